#include "estimation/count_filter.h"

#include "common/rng.h"
#include "estimation/exact_filter.h"
#include "estimation/particle_filter.h"
#include "estimation/population_kalman_filter.h"

namespace recruit {
namespace {

class KalmanAdapter final : public CountFilter {
 public:
  explicit KalmanAdapter(PopulationKalmanFilter f) : f_(std::move(f)) {}
  void Predict(const Eigen::MatrixXd& A) override { f_.Predict(A); }
  void Update(const Eigen::VectorXd& y) override { f_.Update(y); }
  Eigen::VectorXd Mean() const override { return f_.estimate(); }
  Eigen::MatrixXd Covariance() const override { return f_.covariance(); }

 private:
  PopulationKalmanFilter f_;
};

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
    auto f = PopulationKalmanFilter::Create(model, *mode);
    if (!f.ok()) return Error{f.error()};
    return std::unique_ptr<CountFilter>(new KalmanAdapter(std::move(*f)));
  }
  if (e == "exact") {
    ExactFilterOptions o;
    o.max_states = options.max_states;
    auto f = ExactBayesFilter::Create(model, o);
    if (!f.ok()) return Error{f.error()};
    return std::unique_ptr<CountFilter>(new ExactAdapter(std::move(*f)));
  }
  if (e == "particle") {
    Rng rng(options.seed);
    ParticleFilterOptions o;
    o.num_particles = options.particles;
    auto f = ParticleFilter::Create(model, o, rng);
    if (!f.ok()) return Error{f.error()};
    return std::unique_ptr<CountFilter>(new ParticleAdapter(std::move(*f), rng));
  }
  return Error{"estimator '" + e + "' is not one of " + kEstimatorNames};
}

}  // namespace recruit
