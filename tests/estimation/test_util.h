// Helpers shared by the estimation tests: simulated runs of the population chain with a noisy
// sensor, and chi-square quantiles for the statistical bands.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "common/rng.h"
#include "estimation/filter_model.h"
#include "estimation/population_chain.h"

namespace recruit::testing_util {

// Standard normal draw from the project's Rng (Box-Muller; no std::normal_distribution, whose
// algorithm differs between standard libraries).
inline double Gaussian(Rng& rng) {
  const double u1 = 1.0 - rng.Uniform(), u2 = rng.Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

// y = H x + v, v ~ N(0, R).
inline Eigen::VectorXd Measure(const estimation::FilterModel& f, const Eigen::VectorXd& x,
                               Rng& rng) {
  const Eigen::MatrixXd L = Eigen::LLT<Eigen::MatrixXd>(f.R).matrixL();
  Eigen::VectorXd g(f.num_outputs());
  for (int i = 0; i < g.size(); ++i) g(i) = Gaussian(rng);
  return f.H * x + L * g;
}

// Quantile of the chi-square distribution with k degrees of freedom (Wilson-Hilferty; relative
// error < 1e-3 for k >= 10, which is where the tests use it), z the standard normal quantile.
inline double ChiSquareQuantile(double k, double z) {
  const double a = 2.0 / (9.0 * k);
  const double c = 1.0 - a + z * std::sqrt(a);
  return k * c * c * c;
}

// The three-state unit used by several tests: off, warming (heater on, partial force), on.
// A broadcast moves off units to warming with p_on and heated units to off with p_off; a
// warming unit that is not switched off settles to "on" with probability 0.6 per step.
inline estimation::FilterModel ThreeStateModel(int64_t N, double noise_std) {
  estimation::FilterModel f;
  f.state_names = {"off", "warming", "on"};
  f.N = N;
  f.H = Eigen::RowVector3d(0.0, 0.2, 0.45);
  f.R = Eigen::MatrixXd::Constant(1, 1, noise_std * noise_std);
  f.G = Eigen::MatrixXd::Zero(3, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = estimation::TransitionSource::kBroadcast;
  estimation::BroadcastTransitionModel& b = f.broadcast;
  b.state_names = f.state_names;
  b.is_on = {false, true, true};
  b.interior = Eigen::Matrix3d{{1, 0, 0}, {0, 0.4, 0}, {0, 0.6, 1}};
  b.on_target = {1, -1, -1};
  b.off_target = {-1, 0, 0};
  b.dt = 0.5;
  f.x0 = Eigen::Vector3d(static_cast<double>(N), 0, 0);
  f.P0 = Eigen::Matrix3d::Zero();
  return f;
}

}  // namespace recruit::testing_util
