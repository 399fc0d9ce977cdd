// The bench log (docs/formats/bench_log.md): what a rig records at its control instants, in the
// form `recruit filter`, `recruit identify --log` and `recruit replay` all read. One CSV header,
// then rows; the columns it names (others are ignored, so `recruit simulate`'s per-step CSV is a
// bench log):
//   time                      s, uniformly spaced over the control instants
//   control_instant           optional: 1 on a control instant's row, 0 elsewhere (skipped);
//                             without it every row is a control instant
//   <bundle>.p_on, .p_off     the broadcast made at that instant
//   <bundle>.sensed_force     the load cell's reading at that instant (before the broadcast), N
//   angle, <joint>.angle      optional: joint angles, rad
// MuJoCo-free.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "common/result.h"

namespace recruit::estimation {

// Where a bench log's columns are (indices into the header; -1 = absent).
struct BenchLogColumns {
  struct Bundle {
    std::string name;
    int p_on = -1, p_off = -1, sensed_force = -1;
  };
  struct Angle {
    std::string name;  // "angle" or the joint's name
    int col = -1;
  };
  int time = -1;
  int control_instant = -1;
  std::vector<Bundle> bundles;  // in the order of their sensed_force columns
  std::vector<Angle> angles;    // "angle" first, then <joint>.angle in header order
};

// True if the header names `time` and at least one `<bundle>.sensed_force` column: the file is
// a bench log (the readers of the older formats check this first).
bool IsBenchLogHeader(const std::vector<std::string_view>& header);
bool IsBenchLogHeader(const std::vector<std::string>& header);

// The columns of a bench log's header. Errors (naming `where`, the file): no time column, a
// bundle's sensed_force without its p_on and p_off, a duplicate column name.
Result<BenchLogColumns> FindBenchLogColumns(const std::vector<std::string>& header,
                                            const std::string& where);

// The index in c.bundles of the bundle named `name`; an empty name picks the only bundle. Errors
// list the bundles the log has.
Result<int> SelectBenchBundle(const BenchLogColumns& c, const std::string& name,
                              const std::string& where);

// Reads the cell of a control_instant column: 1 -> true, 0 -> false; else an error naming
// `where` (file:line) and the value.
Result<bool> ParseControlInstant(std::string_view cell, const std::string& where);

// The largest relative deviation of one control-instant period from the log's mean period that
// the readers accept (a rig's timing jitter; `recruit simulate` prints its times to 6 digits).
constexpr double kBenchLogPeriodTolerance = 0.01;

// A whole bench log in memory, its control instants only.
struct BenchLog {
  std::string path;
  double dT = 0;             // mean period of the control instants, s
  std::vector<double> time;  // of each control instant's row, s
  std::vector<int> line;     // its line in the file
  struct Bundle {
    std::string name;
    std::vector<double> p_on, p_off, sensed_force;
  };
  std::vector<Bundle> bundles;
  struct Angle {
    std::string name;  // "angle" or the joint's name
    std::vector<double> value;
  };
  std::vector<Angle> angles;
  int size() const { return static_cast<int>(time.size()); }
};

// Reads and checks a bench log: at least 2 control instants, times increasing and uniformly
// spaced (kBenchLogPeriodTolerance), broadcasts in [0, 1], every cell it uses a finite number.
// Errors name the file, the line, the column and the value (shortened).
Result<BenchLog> ReadBenchLog(const std::string& path);
// The same from text (`path` only names it in messages).
Result<BenchLog> ParseBenchLog(const std::string& text, const std::string& path);

}  // namespace recruit::estimation
