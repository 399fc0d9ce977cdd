// The load a bundle holds in its limb: the largest static torque (gravity and joint springs at
// rest, no actuator) of the joints its tendon crosses over their usable ranges, over the tendon's
// largest moment arm there. Sizing gives a bundle enough units that one unit is a small part of
// that force (SizingLimits::units_per_holding_force): one unit's torque then moves a joint held
// by its own weight a fraction of a degree, not a whole settling band.
#pragma once

#include <mujoco/mujoco.h>

#include <vector>

namespace recruit::attach {

struct HoldingLoad {
  double torque = 0;  // N m: largest |static torque| of a crossed joint
  double arm = 0;     // m: the tendon's largest |moment arm| about that joint
  double force() const { return arm > 0 ? torque / arm : 0; }  // N at the tendon
};

// Each joint of `joints` (ids) swept over [lo, hi] (33 points, the others at qpos0); the joint
// with the largest torque / arm. d is scratch (its state is overwritten).
HoldingLoad SampleHoldingLoad(const mjModel* m, mjData* d, int tendon,
                              const std::vector<int>& joints, const std::vector<double>& lo,
                              const std::vector<double>& hi);

}  // namespace recruit::attach
