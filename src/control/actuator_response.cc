#include "control/actuator_response.h"

#include <algorithm>
#include <cmath>

#include "control/broadcast.h"

namespace recruit::control {
namespace {

// One sampling period of the expected chain: the law's broadcast for `target` (a fraction of the
// units on), then the chain's transition. The matrix and the product go to thread-local space
// (the same arithmetic as x = chain.Matrix(..) * x, without its two allocations per period).
void Advance(const estimation::BroadcastTransitionModel& chain, double target_on, double lambda,
             Eigen::VectorXd& x) {
  const int m = chain.num_states();
  double on = 0;
  for (int i = 0; i < m; ++i) on += chain.is_on[i] ? x[i] : 0.0;
  const Broadcast b = ExpectationLaw(target_on, on, 1.0, lambda);
  thread_local Eigen::MatrixXd a;
  thread_local Eigen::VectorXd next;
  a.resize(m, m);
  next.resize(m);
  chain.FillMatrix(b.p_on, b.p_off, a);
  next.noalias() = a * x;
  x.swap(next);
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

namespace {

// The two settled states of a step and the response from the first: `x` settled at `from`
// (from all units off), `settled` at `to` (from `x`; the force the step ends at is the chain's
// own there, not assumed linear), then the response from `x` towards `to`.
struct Settled {
  Eigen::VectorXd x, settled;
  double y0 = 0, y1 = 0;
};

Status CheckChain(const estimation::BroadcastTransitionModel& chain,
                  const std::vector<double>& force, double lambda, double from, double to,
                  double& unit_force) {
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
  unit_force = *std::max_element(force.begin(), force.end());
  if (!(unit_force > 0)) return Error{"actuator response: no state of the chain pulls"};
  return Status::Ok();
}

Result<Settled> SettleBoth(const estimation::BroadcastTransitionModel& chain,
                           const Eigen::Ref<const Eigen::VectorXd>& h, double unit_force,
                           double lambda, double from, double to, int max_samples) {
  Settled st;
  st.x = Eigen::VectorXd::Zero(chain.num_states());
  st.x[0] = 1;
  // Settle at `from` (the law's count target is the force target over one settled unit's).
  Settle(chain, from, lambda, h, 1e-12 * unit_force, 20 * max_samples, st.x);
  st.y0 = h.dot(st.x);
  st.settled = st.x;
  Settle(chain, to, lambda, h, 1e-12 * unit_force, 20 * max_samples, st.settled);
  st.y1 = h.dot(st.settled);
  if (std::abs(st.y1 - st.y0) < 1e-9 * unit_force) {
    return Error{"actuator response: the chain's force does not follow its on-count"};
  }
  return st;
}

// The response from x (force y0) to a reference of `to` (settled force y1), normalised.
ActuatorResponse StepFrom(const estimation::BroadcastTransitionModel& chain,
                          const Eigen::Ref<const Eigen::VectorXd>& h, double lambda, double to,
                          Eigen::VectorXd x, double y0, double y1, int max_samples) {
  ActuatorResponse r;
  r.dT = chain.dt;
  r.s.push_back(0);
  for (int k = 1; k <= max_samples; ++k) {
    Advance(chain, to, lambda, x);
    r.s.push_back((h.dot(x) - y0) / (y1 - y0));
    if (k > 2 && std::abs(1 - r.s.back()) < 1e-4 && std::abs(1 - r.s[k - 1]) < 1e-4) break;
  }
  return r;
}

}  // namespace

Result<ActuatorResponse> PredictActuatorResponse(const estimation::BroadcastTransitionModel& chain,
                                                 const std::vector<double>& force, double lambda,
                                                 double from, double to, int max_samples) {
  double unit_force = 0;
  RECRUIT_TRY(CheckChain(chain, force, lambda, from, to, unit_force));
  const Eigen::Map<const Eigen::VectorXd> h(force.data(), chain.num_states());
  auto st = SettleBoth(chain, h, unit_force, lambda, from, to, max_samples);
  if (!st) return st.failure();
  return StepFrom(chain, h, lambda, to, std::move(st->x), st->y0, st->y1, max_samples);
}

Result<ActuatorResponse> PredictBundleResponse(const estimation::BroadcastTransitionModel& chain,
                                               const std::vector<double>& force, double lambda) {
  constexpr double kLow = 0.25, kHigh = 0.5;
  constexpr int kMaxSamples = 1000;
  double unit_force = 0;
  RECRUIT_TRY(CheckChain(chain, force, lambda, kLow, kHigh, unit_force));
  const Eigen::Map<const Eigen::VectorXd> h(force.data(), chain.num_states());
  // The two settled states once: the rise starts at the low one, the release at the high one.
  auto st = SettleBoth(chain, h, unit_force, lambda, kLow, kHigh, kMaxSamples);
  if (!st) return st.failure();
  ActuatorResponse r = StepFrom(chain, h, lambda, kHigh, st->x, st->y0, st->y1, kMaxSamples);
  r.release = StepFrom(chain, h, lambda, kLow, st->settled, st->y1, st->y0, kMaxSamples).s;
  return r;
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
