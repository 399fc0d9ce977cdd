// MuJoCo computes a muscle's lengthrange by simulation when the model compiles, and that can fail
// ("Lengthrange computation did not converge in actuator N": MuJoCo's arm26 in 4.0.0). This finds
// every muscle that fails, and can set their ranges from the joint ranges instead (the tendon's
// length range over the usable joint ranges, plugin/tendon_range.h) so that the model loads.
#pragma once

#include <string>
#include <vector>

#include "attach/spec_edit.h"
#include "common/result.h"

namespace recruit::attach {

struct LengthRangeFix {
  std::string actuator;
  double lo = 0, hi = 0;  // actuator length range set (m)
};

// Compiles copies of `spec` until it compiles, collecting the actuators whose lengthrange
// computation fails. With `apply`, their ranges are set in `spec` from the joint ranges and
// returned; without, an error names them all and the option that fixes them. Other compile
// errors are returned as they are.
Result<std::vector<LengthRangeFix>> CheckLengthRanges(mjSpec* spec, bool apply);

// Writes into `spec` the lengthrange MuJoCo computes for each actuator that has none set (the
// muscles), from a compiled copy of `spec` as it is, and returns them. Called before joints
// are locked: MuJoCo would otherwise compute them on the locked limb at every load (a kept
// muscle's range a fraction of a millimetre wide, its passive force kilonewtons at a small
// drift, and wrong once the lock is removed).
Result<std::vector<LengthRangeFix>> FreezeLengthRanges(mjSpec* spec);

}  // namespace recruit::attach
