#include <algorithm>
#include <cmath>

#include "control/broadcast.h"

namespace recruit::control {

Broadcast ExpectationLaw(double target_on, double estimated_on, double num_units, double lambda) {
  Broadcast b;
  if (!(num_units > 0) || std::isnan(target_on) || std::isnan(estimated_on) || std::isnan(lambda)) {
    return b;
  }
  const double n = num_units;
  const double target = std::clamp(target_on, 0.0, n);
  const double est = std::clamp(estimated_on, 0.0, n);
  const double gain = std::clamp(lambda, 0.0, 1.0);
  const double error = target - est;
  // With both counts in [0, N], error > 0 implies N - est >= error > 0 and error < 0 implies
  // est >= -error > 0: the divisions below never see a zero ("no off unit" and "no on unit" are
  // exactly the cases where nothing is to be recruited or released), and p <= lambda <= 1.
  if (error > 0) {
    b.p_on = std::min(1.0, gain * error / (n - est));
  } else if (error < 0) {
    b.p_off = std::min(1.0, gain * -error / est);
  }
  return b;
}

Broadcast ExplorationLaw(const Broadcast& law, double on, double off, double p_explore) {
  if (!(on > 0) || !(off > 0) || !(p_explore > law.p_on)) return law;
  Broadcast b;
  b.p_on = std::min(1.0, p_explore);
  b.p_off = std::min(1.0, (on * law.p_off + off * (b.p_on - law.p_on)) / on);
  return b;
}

}  // namespace recruit::control
