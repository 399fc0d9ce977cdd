// Cost of one control instant (UpdateWithMeasurement + law + Broadcasted) per estimator, and of the
// mean propagation the identification repeats. Run from the source tree (the identified model
// files).
#include <benchmark/benchmark.h>

#include <string>

#include "control/recruitment_controller.h"
#include "identification/transient_chain.h"

namespace recruit::control {
namespace {

void ControllerStep(benchmark::State& state, const std::string& kind,
                    const std::string& covariance) {
  ControllerParams p;
  p.num_units = 60;
  p.unit_force = 0.4532;
  p.dT = 0.5;
  p.lambda = 0.5;
  auto spec = EstimatorSpec::Parse(kind, covariance,
                                   kind == "kalman-augmented" ? RECRUIT_SOURCE_DIR
                                       "/models/identified/bench_n60_dt0.5_m20.json"
                                                              : "");
  auto c = RecruitmentController::Create(p, *spec);
  if (!c.ok()) {
    state.SkipWithError(c.error().c_str());
    return;
  }
  // A force that wanders around the reference, so the law alternates recruit and release.
  double t = 0;
  for (auto _ : state) {
    t += 0.37;
    const double y = 15.0 + 2.0 * ((static_cast<long>(t) % 7) - 3);
    benchmark::DoNotOptimize(c->Step(15.0, y));
  }
}
BENCHMARK_CAPTURE(ControllerStep, output, std::string("output"), std::string("extended"));
BENCHMARK_CAPTURE(ControllerStep, kalman2_extended, std::string("kalman2"),
                  std::string("extended"));
BENCHMARK_CAPTURE(ControllerStep, augmented20_extended, std::string("kalman-augmented"),
                  std::string("extended"));
BENCHMARK_CAPTURE(ControllerStep, augmented20_conservative, std::string("kalman-augmented"),
                  std::string("conservative"));

void ChainPropagateMean(benchmark::State& state) {
  identification::TransientChain c = identification::TransientChain::Uniform(20, 0.7);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(20);
  x[0] = 60;
  for (auto _ : state) {
    c.PropagateMean(0.2, 0.1, x);
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(ChainPropagateMean);

void ChainDenseMatrixTimesX(benchmark::State& state) {
  identification::TransientChain c = identification::TransientChain::Uniform(20, 0.7);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(20);
  x[0] = 60;
  for (auto _ : state) {
    x = c.Matrix(0.2, 0.1) * x;
    benchmark::DoNotOptimize(x.data());
  }
}
BENCHMARK(ChainDenseMatrixTimesX);

}  // namespace
}  // namespace recruit::control
