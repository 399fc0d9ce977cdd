// The broadcast controller's output and its law (Odhner and Asada 2010, Sec. V).
//
// Every sampling period dT the controller broadcasts two probabilities to every unit of a
// bundle: p_on, the probability that a unit whose heater is off switches it on, and p_off, the
// probability that a unit whose heater is on switches it off. docs/controller.md has the
// equations.
#pragma once

namespace recruit::control {

struct Broadcast {
  double p_on = 0;   // Pr(an "off" unit turns its heater on at this instant)
  double p_off = 0;  // Pr(an "on" unit turns its heater off at this instant)
};

// The expectation law: choose (p_on, p_off) so that the expected number of transitions is
// lambda times the number of units to recruit (target_on > estimated_on) or to release
// (target_on < estimated_on):
//   recruit: p_on  = lambda (target - est) / (N - est),  p_off = 0
//   release: p_off = lambda (est - target) / est,         p_on  = 0
// Guards: target_on and estimated_on are first clamped to [0, N] (an estimate may leave the
// feasible set; a reference may ask for more than N units). Then "no unit off" (est = N) and
// "no unit on" (est = 0) never divide by zero: nothing can be recruited, resp. released, and the
// probability is 0. lambda is clamped to [0, 1], so p_on, p_off are in [0, lambda]. A NaN input
// or N <= 0 broadcasts no transition (p_on = p_off = 0).
Broadcast ExpectationLaw(double target_on, double estimated_on, double num_units, double lambda);

// Exploration: the broadcast `law` with at least `p_explore` of the off units recruited and as
// many more on units released as keeps the expected on count after the instant that of `law`:
//   p_on' = max(p_on, p_explore),  p_off' = (on p_off + off (p_on' - p_on)) / on
// (on, off: the estimated on and off units of those the broadcast reaches). Units switched in
// both directions show units that no longer respond (lost while off) without moving the expected
// force. p_off' is capped at 1; with no on unit to release (on <= 0) `law` is returned as it is.
Broadcast ExplorationLaw(const Broadcast& law, double on, double off, double p_explore);

}  // namespace recruit::control
