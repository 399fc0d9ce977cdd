// The linear viscous damping a model gives one degree of freedom at a pose: the joint's own
// (dof_damping), each tendon's and each actuator's (MuJoCo's tendon and actuator `damping`,
// c J^2 with J the tendon's or actuator's moment about the dof). Cross terms between dofs are
// not included. Used by `recruit attach` (the bundles' dampers) and the self-tuned loop's design
// model (sim/joint_loop.h).
#pragma once

#include <mujoco/mujoco.h>

#include <vector>

namespace recruit::sma {

// d: positions set and at least the tendon and transmission stages done (mj_tendon,
// mj_transmission). Actuators whose ids are in `skip` are left out.
double JointDamping(const mjModel* m, const mjData* d, int dof, const std::vector<int>& skip = {});

}  // namespace recruit::sma
