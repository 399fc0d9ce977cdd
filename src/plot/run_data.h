// The inputs of `recruit plot`: a run's per-step CSV (docs/formats/task.md, "Outputs of recruit
// simulate") and, optionally, its JSON summary. Both are validated here, with messages naming
// the file, the line or column and the value.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::plot {

struct RunCsv {
  std::string path;
  std::vector<std::string> names;            // header, in file order
  std::vector<std::vector<double>> columns;  // one per name; empty cells are NaN
  std::vector<std::string> bundles;          // actuator names (from `<name>.true_on` columns)
  // The column, or nullptr.
  const std::vector<double>* Find(const std::string& name) const;
  // The column, which validation guarantees for required columns.
  const std::vector<double>& At(const std::string& name) const;
};

// Parses and validates `text` (read from `path`, used in messages): a header and >= 1 data row,
// every row as many cells as the header, every cell empty or a number; the columns time,
// reference, measured and, per bundle, force, force_reference, true_on, estimated_on, p_on,
// p_off, mean_temperature
// must exist, and all but estimated_on must hold at least one finite value.
// `<bundle>.estimated_on_std` is optional (older CSVs lack it): absent = all NaN.
Result<RunCsv> ParseRunCsv(const std::string& text, const std::string& path);
// Any numeric CSV table: a header and >= 1 data row, equal cell counts, cells empty (NaN) or
// numbers; no required columns (`recruit plot --panel`).
Result<RunCsv> ParseCsvTable(const std::string& text, const std::string& path);
Result<RunCsv> ReadCsvTable(const std::string& path);
Result<RunCsv> ReadRunCsv(const std::string& path);

// What the title line shows, from the summary JSON (all fields optional).
struct RunInfo {
  std::string task, estimator, unit;  // unit: "N" (force task) or "rad" (angle task)
  std::optional<double> dT, lambda;
  std::optional<unsigned long long> seed;
};

Result<RunInfo> ReadRunSummary(const std::string& path);

// "task isometric_paper, estimator output, dT = 0.5 s, lambda = 0.2, seed 1" (the parts known).
std::string TitleOf(const RunInfo& info);

}  // namespace recruit::plot
