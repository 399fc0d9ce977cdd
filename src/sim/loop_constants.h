// The self-tuned joint loop's fixed margins, one definition for the loop and for the C package
// that `recruit export` writes of it (export/auto_loop_export.cc).
#pragma once

namespace recruit::sim {

// A limited joint's reference stays this fraction of its range inside the range.
inline constexpr double kLimitMargin = 0.03;

// A holding joint's stiffness row: the bundles may not hold it with less stiffness than this
// fraction of the magnitudes it is made of (sim/holding.h).
inline constexpr double kStiffnessMargin = 0.5;

}  // namespace recruit::sim
