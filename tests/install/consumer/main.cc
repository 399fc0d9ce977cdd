// Uses the installed headers and libraries: the unit physics (settled force of the default unit
// at its prestretch: 0.447 N, docs/sma-units.md) and the population Kalman filter's two-state
// model (one prediction from all off with p_on = 0.3: 60 x 0.3 = 18 units on).
#include <cmath>
#include <cstdio>

#include "estimation/filter_model.h"
#include "estimation/population_kalman_filter.h"
#include "plugin/unit_model.h"

int main() {
  auto unit = recruit::sma::UnitModel::Create(recruit::sma::UnitParams{});
  if (!unit.ok()) return 1;
  const double hot = unit->Tension(0.0, unit->params().prestretch);
  const auto model = recruit::estimation::FilterModel::TwoState(60, 0.5, hot, 0.1);
  auto kf = recruit::estimation::PopulationKalmanFilter::Create(
      model, recruit::estimation::CovarianceMode::kExtended);
  if (!kf.ok()) return 2;
  kf->PredictBroadcast(0.3, 0.0);
  std::printf("hot unit %.4f N, on after one broadcast %.4f\n", hot, kf->estimate()[1]);
  return std::abs(kf->estimate()[1] - 18.0) < 1e-9 && hot > 0.4 && hot < 0.5 ? 0 : 3;
}
