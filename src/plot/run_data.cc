#include "plot/run_data.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/atomic_file.h"
#include "common/short_text.h"

namespace recruit::plot {
namespace {

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

// An empty cell is NaN; anything else must parse completely as a number.
bool ParseCell(const std::string& cell, double& out) {
  if (cell.empty()) return out = NAN, true;
  char* end = nullptr;
  out = std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size();
}

Status CheckColumns(const RunCsv& csv) {
  std::vector<std::string> required = {"time", "reference", "measured"};
  for (const auto& b : csv.bundles) {
    for (const char* c : {"force", "force_reference", "true_on", "estimated_on", "p_on", "p_off",
                          "mean_temperature"}) {
      required.push_back(b + "." + c);
    }
  }
  for (const auto& name : required) {
    const auto* col = csv.Find(name);
    if (!col) {
      return Error{
          fmt::format("{}: no column '{}' (docs/formats/task.md lists the columns of "
                      "`recruit simulate`'s CSV)",
                      csv.path, name)};
    }
    if (name.size() > 13 && name.substr(name.size() - 13) == ".estimated_on") continue;
    bool any = false;
    for (double v : *col) any = any || std::isfinite(v);
    if (!any) return Error{fmt::format("{}: column '{}' has no finite value", csv.path, name)};
  }
  return Status::Ok();
}

void FindBundles(RunCsv& csv) {
  const std::string suffix = ".true_on";
  for (const auto& n : csv.names) {
    if (n.size() > suffix.size() &&
        n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0) {
      csv.bundles.push_back(n.substr(0, n.size() - suffix.size()));
    }
  }
}

}  // namespace

const std::vector<double>* RunCsv::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i] == name) return &columns[i];
  }
  return nullptr;
}

const std::vector<double>& RunCsv::At(const std::string& name) const { return *Find(name); }

Result<RunCsv> ParseCsvTable(const std::string& text, const std::string& path) {
  RunCsv csv;
  csv.path = path;
  std::istringstream in(text);
  std::string line;
  if (!std::getline(in, line) || line.find_first_not_of(" \t\r") == std::string::npos) {
    return Error{path + ": empty file (expected a header line and data rows)"};
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  csv.names = SplitCells(line);
  csv.columns.resize(csv.names.size());
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const auto cells = SplitCells(line);
    if (cells.size() != csv.names.size()) {
      return Error{fmt::format("{} line {}: {} cells, the header has {}", path, line_no,
                               cells.size(), csv.names.size())};
    }
    for (size_t c = 0; c < cells.size(); ++c) {
      double v;
      if (!ParseCell(cells[c], v)) {
        return Error{fmt::format("{} line {}, column '{}': '{}' is not a number", path, line_no,
                                 csv.names[c], ShortText(cells[c]))};
      }
      csv.columns[c].push_back(v);
    }
  }
  if (csv.columns.empty() || csv.columns[0].empty()) {
    return Error{path + ": no data rows after the header"};
  }
  return csv;
}

Result<RunCsv> ParseRunCsv(const std::string& text, const std::string& path) {
  auto table = ParseCsvTable(text, path);
  if (!table.ok()) return Error{table.error(), table.code()};
  RunCsv csv = std::move(*table);
  FindBundles(csv);
  if (csv.bundles.empty()) {
    return Error{path + ": no column '<bundle>.true_on' (not a `recruit simulate` CSV?)"};
  }
  for (const auto& b : csv.bundles) {  // a CSV from before the column existed: all NaN
    if (!csv.Find(b + ".estimated_on_std")) {
      csv.names.push_back(b + ".estimated_on_std");
      csv.columns.emplace_back(csv.columns[0].size(), NAN);
    }
  }
  if (Status s = CheckColumns(csv); !s.ok()) return Error{s.error(), s.code()};
  return csv;
}

Result<RunCsv> ReadCsvTable(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{text.error(), text.code()};
  return ParseCsvTable(*text, path);
}

Result<RunCsv> ReadRunCsv(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{text.error(), text.code()};
  return ParseRunCsv(*text, path);
}

namespace {

template <class T>
Status Field(const nlohmann::json& j, const char* key, const std::string& path, T& out,
             const char* allowed) {
  if (!j.contains(key) || j[key].is_null()) return Status::Ok();
  const auto& v = j[key];
  const bool ok =
      std::is_same_v<typename T::value_type, std::string> ? v.is_string() : v.is_number();
  if (!ok) {
    return Error{
        fmt::format("{}: field '{}' is {} ({} allowed)", path, key, ShortText(v.dump()), allowed)};
  }
  out = v.get<typename T::value_type>();
  return Status::Ok();
}

}  // namespace

Result<RunInfo> ReadRunSummary(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{text.error(), text.code()};
  nlohmann::json j = nlohmann::json::parse(*text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) {
    return Error{path + ": not a JSON object (expected `recruit simulate`'s summary)"};
  }
  RunInfo info;
  std::optional<std::string> task, estimator, unit;
  for (Status s : {Field(j, "task", path, task, "a string"),
                   Field(j, "estimator", path, estimator, "a string"),
                   Field(j, "unit", path, unit, "\"N\" or \"rad\""),
                   Field(j, "dT", path, info.dT, "a number, s"),
                   Field(j, "lambda", path, info.lambda, "a number"),
                   Field(j, "seed", path, info.seed, "an integer")}) {
    if (!s.ok()) return Error{s.error(), s.code()};
  }
  info.task = task.value_or(""), info.estimator = estimator.value_or("");
  info.unit = unit.value_or("");
  if (!info.unit.empty() && info.unit != "N" && info.unit != "rad") {
    return Error{fmt::format("{}: field 'unit' is '{}' (\"N\" or \"rad\" allowed)", path,
                             ShortText(info.unit))};
  }
  return info;
}

std::string TitleOf(const RunInfo& info) {
  std::vector<std::string> parts;
  if (!info.task.empty()) parts.push_back("task " + info.task);
  if (!info.estimator.empty()) parts.push_back("estimator " + info.estimator);
  if (info.dT) parts.push_back(fmt::format("dT = {:g} s", *info.dT));
  if (info.lambda) parts.push_back(fmt::format("lambda = {:g}", *info.lambda));
  if (info.seed) parts.push_back(fmt::format("seed {}", *info.seed));
  std::string out;
  for (const auto& p : parts) out += (out.empty() ? "" : ", ") + p;
  return out;
}

}  // namespace recruit::plot
