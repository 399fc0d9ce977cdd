#include "control/actuator_response.h"

#include <algorithm>
#include <cmath>

#include "control/broadcast.h"

namespace recruit::control {
namespace {

// One sampling period of the expected chain: the law's broadcast for `target` (a fraction of the
// units on), then the chain's transition.
void Advance(const estimation::BroadcastTransitionModel& chain, double target_on, double lambda,
             Eigen::VectorXd& x) {
  double on = 0;
  for (int i = 0; i < chain.num_states(); ++i) on += chain.is_on[i] ? x[i] : 0.0;
  const Broadcast b = ExpectationLaw(target_on, on, 1.0, lambda);
  x = chain.Matrix(b.p_on, b.p_off) * x;
}

// Advances x under the law towards `target` until its force h'x changes by less than
// `tolerance` in a period (or `max_periods` have passed).
void Settle(const estimation::BroadcastTransitionModel& chain, double target, double lambda,
            const Eigen::Ref<const Eigen::VectorXd>& h, double tolerance, int max_periods,
            Eigen::VectorXd& x) {
  double before = 0;
  for (int k = 0; k < max_periods; ++k) {
    Advance(chain, target, lambda, x);
    const double y = h.dot(x);
    if (k > 10 && std::abs(y - before) < tolerance) return;
    before = y;
  }
}

}  // namespace

double ActuatorResponse::TimeTo(double fraction) const {
  for (size_t i = 1; i < s.size(); ++i) {
    if (s[i] >= fraction) {
      const double f = (fraction - s[i - 1]) / (s[i] - s[i - 1]);
      return (i - 1 + f) * dT;
    }
  }
  return s.size() * dT;
}

ActuatorResponse ActuatorResponse::Released() const {
  ActuatorResponse r;
  r.dT = dT;
  r.s = release.empty() ? s : release;
  return r;
}

ActuatorResponse ActuatorResponse::Reversed() const {
  ActuatorResponse r;
  r.dT = dT;
  r.s = release.empty() ? s : release;
  if (!release.empty()) r.release = s;
  return r;
}

Result<ActuatorResponse> PredictActuatorResponse(const estimation::BroadcastTransitionModel& chain,
                                                 const std::vector<double>& force, double lambda,
                                                 double from, double to, int max_samples) {
  const int m = chain.num_states();
  if (static_cast<int>(force.size()) != m) {
    return Error{"actuator response: the force row has " + std::to_string(force.size()) +
                 " entries for a chain of " + std::to_string(m) + " states"};
  }
  if (!(chain.dt > 0) || !(lambda > 0 && lambda <= 1) || !(from > 0 && from < 1) ||
      !(to > 0 && to < 1) || from == to) {
    return Error{"actuator response: needs dt > 0, 0 < lambda <= 1 and two distinct fractions"};
  }
  // The settled force of a unit held on: the largest state force (the settled on state).
  const double unit_force = *std::max_element(force.begin(), force.end());
  if (!(unit_force > 0)) return Error{"actuator response: no state of the chain pulls"};
  const Eigen::Map<const Eigen::VectorXd> h(force.data(), m);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  x[0] = 1;
  // Settle at `from` (the law's count target is the force target over one settled unit's).
  Settle(chain, from, lambda, h, 1e-12 * unit_force, 20 * max_samples, x);
  const double y0 = h.dot(x);
  ActuatorResponse r;
  r.dT = chain.dt;
  r.s.push_back(0);
  // The force the step ends at, from the same chain settled at `to` (not assumed linear).
  Eigen::VectorXd settled = x;
  Settle(chain, to, lambda, h, 1e-12 * unit_force, 20 * max_samples, settled);
  const double y1 = h.dot(settled);
  if (std::abs(y1 - y0) < 1e-9 * unit_force) {
    return Error{"actuator response: the chain's force does not follow its on-count"};
  }
  for (int k = 1; k <= max_samples; ++k) {
    Advance(chain, to, lambda, x);
    r.s.push_back((h.dot(x) - y0) / (y1 - y0));
    if (k > 2 && std::abs(1 - r.s.back()) < 1e-4 && std::abs(1 - r.s[k - 1]) < 1e-4) break;
  }
  return r;
}

Result<ActuatorResponse> PredictBundleResponse(const estimation::BroadcastTransitionModel& chain,
                                               const std::vector<double>& force, double lambda) {
  auto rise = PredictActuatorResponse(chain, force, lambda, 0.25, 0.5);
  if (!rise) return rise;
  auto release = PredictActuatorResponse(chain, force, lambda, 0.5, 0.25);
  if (!release) return release.failure();
  rise->release = std::move(release->s);
  return rise;
}

ActuatorResponse FirstOrderActuatorResponse(double dT, double lambda, double tau, int max_samples) {
  ActuatorResponse r;
  r.dT = dT;
  r.s.push_back(0);
  const double decay = tau > 0 ? std::exp(-dT / tau) : 0.0;
  double count = 0, force = 0;
  for (int k = 1; k <= max_samples; ++k) {
    count += lambda * (1 - count);  // the broadcast at instant k - 1, held until k
    force = count + (force - count) * decay;
    r.s.push_back(force);
    if (1 - force < 1e-4) break;
  }
  return r;
}

}  // namespace recruit::control
