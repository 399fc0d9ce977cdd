// Latency theory of the output-only loop, for the bound drawn over the sweep's margin map. The
// output-only estimator counts a unit as on only once its force shows, so the loop acts like a
// gain K = lambda / dT (the expectation law closes a fraction lambda of the error per period)
// around a pure delay tau (the unit's force latency): y'(t) = K (r - y(t - tau)). Its step response
// overshoots by at most `max_overshoot` iff K tau <= c(max_overshoot), with c(0) = 1/e (the
// classical non-oscillation threshold) and c -> pi/2 at the loss of stability. So the shortest
// dT that meets the overshoot criterion is about dT_bound = lambda tau / c.
#pragma once

#include "common/result.h"
#include "sim/task.h"

namespace recruit::sweep {

// The overshoot of the normalised delay loop y' = a (1 - y(t - 1)), y = 0 for t <= 0 (Euler,
// step 1e-3, over 80 delays); a in (0, pi/2).
double DelayLoopOvershoot(double a);
// c: the a in (0, pi/2) at which DelayLoopOvershoot(a) = overshoot (bisection), overshoot >= 0.
double DelayLoopGainForOvershoot(double overshoot);

// The force latency of the task's agonist bundle: from rest, every unit switched on (ctrl = 1
// held), the time at which the tendon force first reaches half its value after 30 s. Loads the
// task's model (with the task's timestep).
Result<double> ForceLatency(const sim::Task& task);

}  // namespace recruit::sweep
