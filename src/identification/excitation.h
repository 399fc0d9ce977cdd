// The switching pattern `recruit identify` applies to the bench: broadcast probabilities per
// control instant that excite the whole transient model (docs/identification.md):
//   1. population steps: all on (p_on = 1) and hold to settle, then all off and hold;
//   2. on-pulses of 1, 2, ... periods from cold and off-pulses of 1, 2, ... periods from hot
//      (switching back mid-transient exercises the jumps between the chains);
//   3. partial steps (p = 0.25, 0.5) that leave part of the bundle on;
//   4. random switching until the end: blocks of 1 .. settle/2 periods with p_on, p_off drawn
//      uniformly in [0, 0.5] (either may be zero).
#pragma once

#include <cstdint>
#include <vector>

namespace recruit::identification {

struct Excitation {
  std::vector<double> p_on, p_off;
  int size() const { return static_cast<int>(p_on.size()); }
};

// settle: periods to hold for a unit to settle (e.g. 8 s / dT); total: number of instants.
Excitation MakeExcitation(int settle, int total, std::uint64_t seed);

}  // namespace recruit::identification
