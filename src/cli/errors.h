// The error policy of every `recruit` command (docs/reliability.md): a message on stderr that
// starts with "recruit COMMAND: ", names the file / field / option, shortens echoed values to
// ~40 characters and says what is allowed; one exit code per class (common/exit_codes.h).
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>

#include "common/exit_codes.h"
#include "common/short_text.h"
#include "control/sampling_period.h"

namespace recruit::cli {

// Prints "recruit <command>: <message>" and returns `code`.
inline int Fail(const std::string& command, const std::string& message, int code) {
  std::cerr << "recruit " << command << ": " << ShortenLongTokens(message, 200) << "\n";
  return code;
}
// Same, with the exit code of the error's class (common/exit_codes.h).
inline int Fail(const std::string& command, const Error& error) {
  return Fail(command, error.message, exit_code::Of(error));
}

// Numeric option checks with our own messages: CLI11's ranges print their bounds, which for
// one-sided ranges is DBL_MAX. NaN and infinities are refused everywhere.
// Allowed: lo < x (open) or lo <= x (closed), and x <= hi when hi is finite.
inline CLI::Validator NumberIn(double lo, bool lo_open, double hi, const std::string& what) {
  return CLI::Validator(
      [=](std::string& s) -> std::string {
        // strtod, unlike a stream, reads "nan" and "inf", which must be refused here.
        char* end = nullptr;
        const double x = std::strtod(s.c_str(), &end);
        if (s.empty() || end != s.c_str() + s.size()) {
          // Non-numbers are reported by CLI11's conversion; the check only judges numbers.
          return {};
        }
        const bool ok = std::isfinite(x) && (lo_open ? x > lo : x >= lo) && x <= hi;
        if (ok) return {};
        return "value '" + ShortText(s) + "' not allowed: must be " + what;
      },
      what);
}
inline CLI::Validator Positive() {
  return NumberIn(0, true, std::numeric_limits<double>::max(), "a finite number > 0");
}
inline CLI::Validator NonNegative() {
  return NumberIn(0, false, std::numeric_limits<double>::max(), "a finite number >= 0");
}
inline CLI::Validator Fraction() { return NumberIn(0, true, 1, "in (0, 1]"); }
// The controller's sampling period (control/sampling_period.h).
inline CLI::Validator SamplingPeriod() {
  return NumberIn(0, true, control::kMaxDT, "a finite number > 0 and <= 1000 (seconds)");
}

}  // namespace recruit::cli
