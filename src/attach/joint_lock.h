// `recruit attach --lock`: joints held fixed by a MuJoCo joint equality (joint1 only: the joint
// stays at its reference value qpos0, kept inside its range), in the written model and in the
// copy the bundles are sized on; the tendon sweeps (plugin/tendon_range.h) leave held joints
// out, so a tendon's excursion, usable range and load are those of the joints that still move.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::attach {

struct JointLock {
  std::string joint;
  double value = 0;  // rad or m: where it is held
  double ref = 0;    // the joint's qpos0 (the equality's origin)
};

// The locks of the named joints (hinges or slides of the compiled model `m`); an error names a
// joint that is missing or of another type. `model` names the file in messages.
Result<std::vector<JointLock>> FindLocks(const mjModel* m, const std::vector<std::string>& names,
                                         const std::string& model);

// One joint equality per lock, named "lock_JOINT" (made unique).
Status AddLockEqualities(mjSpec* spec, const std::vector<JointLock>& locks);

}  // namespace recruit::attach
