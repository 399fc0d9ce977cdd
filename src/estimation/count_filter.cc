#include "estimation/count_filter.h"

#include "common/rng.h"
#include "common/short_text.h"
#include "estimation/exact_filter.h"
#include "estimation/json_matrix.h"
#include "estimation/particle_filter.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::estimation {
namespace {

// F: PopulationKalmanFilterT<M, R>; fixed sizes for the common models (no heap, unrolled).
template <class F>
class KalmanAdapter final : public CountFilter {
 public:
  explicit KalmanAdapter(F f) : f_(std::move(f)) {}
  void Predict(const Eigen::MatrixXd& A) override {
    if constexpr (F::Mat::RowsAtCompileTime == Eigen::Dynamic) {
      f_.Predict(A);
    } else {
      f_.Predict(typename F::Mat(A));  // fixed size: a stack copy
    }
  }
  void Update(const Eigen::VectorXd& y) override {
    y_ = y;  // fixed size: a copy, no allocation
    f_.Update(y_);
  }
  Eigen::VectorXd Mean() const override { return f_.estimate(); }
  Eigen::MatrixXd Covariance() const override { return f_.covariance(); }
  void PredictBroadcast(const BroadcastTransitionModel& b, double p_on, double p_off) override {
    if (f_.has_broadcast()) {
      f_.PredictBroadcast(p_on, p_off);
    } else {
      CountFilter::PredictBroadcast(b, p_on, p_off);
    }
  }
  void MeanAndVariance(Eigen::VectorXd& mean, Eigen::VectorXd& var) const override {
    mean = f_.estimate();
    var = f_.covariance().diagonal();
  }

 private:
  F f_;
  typename F::OutVec y_;
};

template <int M, int R>
Result<std::unique_ptr<CountFilter>> MakeKalman(const FilterModel& model, CovarianceMode mode) {
  auto f = PopulationKalmanFilterT<M, R>::Create(model, mode);
  if (!f.ok()) return Error{f.error(), f.code()};
  return std::unique_ptr<CountFilter>(
      new KalmanAdapter<PopulationKalmanFilterT<M, R>>(std::move(*f)));
}

class ExactAdapter final : public CountFilter {
 public:
  explicit ExactAdapter(ExactBayesFilter f) : f_(std::move(f)) {}
  void Predict(const Eigen::MatrixXd& A) override { f_.Predict(A); }
  void Update(const Eigen::VectorXd& y) override { f_.Update(y); }
  Eigen::VectorXd Mean() const override { return f_.Mean(); }
  Eigen::MatrixXd Covariance() const override { return f_.Covariance(); }

 private:
  ExactBayesFilter f_;
};

class ParticleAdapter final : public CountFilter {
 public:
  ParticleAdapter(ParticleFilter f, Rng rng) : f_(std::move(f)), rng_(rng) {}
  void Predict(const Eigen::MatrixXd& A) override { f_.Predict(A, rng_); }
  void Update(const Eigen::VectorXd& y) override { f_.Update(y, rng_); }
  Eigen::VectorXd Mean() const override { return f_.Mean(); }
  Eigen::MatrixXd Covariance() const override { return f_.Covariance(); }

 private:
  ParticleFilter f_;
  Rng rng_;
};

}  // namespace

Result<std::unique_ptr<CountFilter>> MakeCountFilter(const FilterModel& model,
                                                     const CountFilterOptions& options) {
  const std::string& e = options.estimator;
  if (e == "extended" || e == "conservative" || e == "plain") {
    auto mode = ParseCovarianceMode(e);
    if (model.num_outputs() == 1) {
      switch (model.num_states()) {
        case 2:
          return MakeKalman<2, 1>(model, *mode);
        case 3:
          return MakeKalman<3, 1>(model, *mode);
        case 20:
          return MakeKalman<20, 1>(model, *mode);
      }
    }
    return MakeKalman<Eigen::Dynamic, Eigen::Dynamic>(model, *mode);
  }
  if (e == "exact") {
    ExactFilterOptions o;
    o.max_states = options.max_states;
    auto f = ExactBayesFilter::Create(model, o);
    if (!f.ok()) return Error{f.error(), f.code()};
    return std::unique_ptr<CountFilter>(new ExactAdapter(std::move(*f)));
  }
  if (e == "particle") {
    Rng rng(options.seed);
    ParticleFilterOptions o;
    o.num_particles = options.particles;
    auto f = ParticleFilter::Create(model, o, rng);
    if (!f.ok()) return Error{f.error(), f.code()};
    return std::unique_ptr<CountFilter>(new ParticleAdapter(std::move(*f), rng));
  }
  return Error{"estimator '" + ShortText(e) + "' is not one of " + kEstimatorNames};
}

}  // namespace recruit::estimation
