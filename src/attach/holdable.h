// The part of each driven joint's usable range where the attached bundles can hold the limb:
// the pose's static torque (gravity, springs: MuJoCo's inverse dynamics at rest, constraints
// off) met by tensions between the co-contraction floor and every unit on, shared as the
// self-tuned loop shares a demand (control/torque_allocation.h). The starter task steps inside
// it: a pose beyond the bundles never settles (MyoSuite's two-joint elbow, whose shoulder only
// the biceps' and triceps' long heads cross).
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

namespace recruit::attach {

struct BundleReport;  // attach/attach.h

struct HoldableRange {
  std::string joint;
  double lo = 0, hi = 0;            // rad: the usable range given
  double hold_lo = 0, hold_hi = 0;  // rad: the part held, around the middle of [lo, hi]
  bool cut() const { return hold_lo > lo || hold_hi < hi; }
};

// Samples each joint of `ranges` (lo, hi set) over [lo, hi] (kHoldSamples points) with the
// other joints of `ranges` at their middles and the rest at qpos0, and sets hold_lo/hold_hi to
// the run of held samples that contains the middle (the longest run when the middle is not held;
// the whole range when none is). `m` is the written model (the bundles with their designs in
// `bundles`, by actuator name; its constraints are disabled for each inverse dynamics call and
// the flag restored); `co_contraction` the floor as a fraction of capacity.
void FindHoldableRanges(mjModel* m, const std::vector<BundleReport>& bundles, double co_contraction,
                        std::vector<HoldableRange>& ranges);

inline constexpr int kHoldSamples = 41;

}  // namespace recruit::attach
