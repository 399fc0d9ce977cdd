// The filter objects behind recruit.KalmanFilter, ExactFilter and ParticleFilter: one base that
// checks every input (so the C++ cores get only valid ones) and runs a whole log with the GIL
// released; the derived classes hold the C++ filters.
#pragma once

#include <pybind11/pybind11.h>

#include <Eigen/Dense>
#include <memory>
#include <string>

#include "common/rng.h"
#include "estimation/exact_filter.h"
#include "estimation/filter_model.h"
#include "estimation/particle_filter.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::py_bind {

namespace py = pybind11;

class PyFilter {
 public:
  explicit PyFilter(estimation::FilterModel model) : model_(std::move(model)) {}
  virtual ~PyFilter() = default;

  // Time update with an m x m column-stochastic A.
  void Predict(const py::object& A);
  // Time update with the model's broadcast transition A(p_on, p_off).
  void PredictBroadcast(double p_on, double p_off);
  // Measurement update; None or an all-NaN y is a missing sample (returns false).
  bool Update(const py::object& y);
  // The offline run (docs/formats/filter.md): for k = 0..T-1 predict with input k-1 (k > 0),
  // update with ys[k] unless missing; returns (X, V), the T x m estimates and variances.
  py::tuple Run(const py::object& ys, const py::object& p_on, const py::object& p_off,
                const py::object& As);

  virtual Eigen::VectorXd Mean() const = 0;
  virtual Eigen::MatrixXd Covariance() const = 0;
  const estimation::FilterModel& model() const { return model_; }

 protected:
  // Inputs already checked.
  virtual void DoPredict(const Eigen::MatrixXd& A) = 0;
  virtual void DoPredictBroadcast(double p_on, double p_off) {
    DoPredict(model_.broadcast.Matrix(p_on, p_off));
  }
  virtual void DoUpdate(const Eigen::VectorXd& y) = 0;
  virtual void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const {
    mean = Mean();
    var = Covariance().diagonal();
  }

  estimation::FilterModel model_;
};

// The population Kalman filter of one size: fixed (PopulationKalmanFilterT<M, R>, no heap in
// the steps) or dynamic.
class KalmanCore {
 public:
  virtual ~KalmanCore() = default;
  virtual void Predict(const Eigen::MatrixXd& A) = 0;
  virtual void PredictBroadcast(double p_on, double p_off) = 0;
  virtual void Update(const Eigen::VectorXd& y) = 0;
  virtual void SetOutput(const Eigen::MatrixXd& H, const Eigen::MatrixXd& R) = 0;
  virtual Eigen::VectorXd estimate() const = 0;
  virtual Eigen::MatrixXd covariance() const = 0;
  virtual Eigen::VectorXd innovation() const = 0;
  virtual Eigen::MatrixXd gain() const = 0;
  virtual Eigen::MatrixXd H() const = 0;
  virtual void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const = 0;
  virtual bool fixed_size() const = 0;
};

class PyKalmanFilter : public PyFilter {
 public:
  // fixed_size: use PopulationKalmanFilterT<m, 1> for m = 2, 3, 20 and r = 1 (the sizes
  // `recruit filter` and the controllers use), else the dynamic-size filter.
  PyKalmanFilter(const estimation::FilterModel& model, const std::string& mode,
                 const py::object& x0, const py::object& P0, bool fixed_size);
  void Reset(const py::object& x0, const py::object& P0);
  void SetOutput(const py::object& H, const py::object& R);

  Eigen::VectorXd Mean() const override { return core_->estimate(); }
  Eigen::MatrixXd Covariance() const override { return core_->covariance(); }
  const KalmanCore& core() const { return *core_; }
  estimation::CovarianceMode mode() const { return mode_; }

 protected:
  void DoPredict(const Eigen::MatrixXd& A) override { core_->Predict(A); }
  void DoPredictBroadcast(double p_on, double p_off) override;
  void DoUpdate(const Eigen::VectorXd& y) override { core_->Update(y); }
  void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const override {
    core_->MeanAndVariance(mean, var);
  }

 private:
  estimation::CovarianceMode mode_;
  bool want_fixed_;
  std::unique_ptr<KalmanCore> core_;
};

class PyExactFilter : public PyFilter {
 public:
  PyExactFilter(const estimation::FilterModel& model, uint64_t max_states, uint64_t cache_bytes);
  Eigen::VectorXd Mean() const override { return f_.Mean(); }
  Eigen::MatrixXd Covariance() const override { return f_.Covariance(); }
  const estimation::ExactBayesFilter& filter() const { return f_; }
  estimation::ExactBayesFilter& filter() { return f_; }

 protected:
  void DoPredict(const Eigen::MatrixXd& A) override { f_.Predict(A); }
  void DoUpdate(const Eigen::VectorXd& y) override { f_.Update(y); }

 private:
  estimation::ExactBayesFilter f_;
};

class PyParticleFilter : public PyFilter {
 public:
  // As `recruit filter --estimator particle --seed seed`: one Rng(seed) draws the initial
  // particles, then every step.
  PyParticleFilter(const estimation::FilterModel& model, int particles, double resample_threshold,
                   uint64_t seed);
  Eigen::VectorXd Mean() const override { return f_.Mean(); }
  Eigen::MatrixXd Covariance() const override { return f_.Covariance(); }
  const estimation::ParticleFilter& filter() const { return f_; }

 protected:
  void DoPredict(const Eigen::MatrixXd& A) override { f_.Predict(A, rng_); }
  void DoUpdate(const Eigen::VectorXd& y) override { f_.Update(y, rng_); }

 private:
  Rng rng_;
  estimation::ParticleFilter f_;
};

}  // namespace recruit::py_bind
