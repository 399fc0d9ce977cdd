// The broadcast controller's sampling period dT: one default and one rule for every place that
// takes one (task and sweep files, the command line, RunOptions, the controller, the estimators),
// so that a dT one of them accepts is accepted by all.
#pragma once

#include <cmath>
#include <string>

#include "common/result.h"
#include "common/short_text.h"

namespace recruit::control {

constexpr double kDefaultDT = 2.0;  // s: a task's, and ControllerParams', when none is given
constexpr double kMaxDT = 1000;     // s
// The rule in words, for messages: finite, 0 < dT <= kMaxDT.
inline const char* const kDTAllowed = "seconds, 0 < dT <= 1000";

inline bool ValidDT(double dT) { return std::isfinite(dT) && dT > 0 && dT <= kMaxDT; }

// "<where>: dT = <value> is out of range; allowed: seconds, 0 < dT <= 1000" (bad input).
inline Status CheckDT(double dT, const std::string& where) {
  if (ValidDT(dT)) return Status::Ok();
  return Error{where + ": dT = " + GText(dT) + " is out of range; allowed: " + kDTAllowed};
}

}  // namespace recruit::control
