// The self-tuned joint loop's fixed margins, one definition for the loop and for the C package
// that `recruit export` writes of it (export/auto_loop_export.cc).
#pragma once

namespace recruit::sim {

// A limited joint's reference stays this fraction of its range inside the range.
inline constexpr double kLimitMargin = 0.03;

// A holding joint's stiffness row: the bundles may not hold it with less stiffness than this
// fraction of the magnitudes it is made of, the limb's and each bundle's (sim/holding.h): with
// less, the errors of the model (force map, moment arms) can make a pose the bundles hold
// unstable. 0.5 settled 7/16, 6/8 and 3/8 steps of the development cases at dT 1 (two-joint
// arm, MyoSuite elbow and finger, seeds 401-402) against 4/16, 4/8 and 2/8 without; 0.25 gave
// 7/16, 4/8, 3/8.
inline constexpr double kStiffnessMargin = 0.5;

}  // namespace recruit::sim
