#include "export/sweep_choice.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "sweep/recommend.h"
#include "sweep/table.h"

namespace recruit::exporter {
namespace {

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  for (std::string f; std::getline(s, f, ',');) out.push_back(f);
  return out;
}

Result<double> Number(const std::string& text, const std::string& where) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) {
    return Error{where + ": \"" + text.substr(0, 40) + "\" is not a number"};
  }
  return v;
}

// The cells of table.csv (dT, lambda, estimator, seeds, meets_criterion, margin).
Result<std::vector<sweep::CellStats>> ReadCells(const std::string& path) {
  auto text = ReadFile(path);
  if (!text) return Error{text.error()};
  std::stringstream in(*text);
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> head = SplitCsv(line);
  auto column = [&](const std::string& name) -> int {
    for (size_t i = 0; i < head.size(); ++i) {
      if (head[i] == name) return static_cast<int>(i);
    }
    return -1;
  };
  if (column("plant") >= 0) {
    return Error{path +
                 ": the sweep varies the plant (plant axes): its recommendations are per "
                 "plant point; export with the --dT and --lambda of its report for this plant"};
  }
  const int c_dt = column("dT"), c_l = column("lambda"), c_e = column("estimator");
  const int c_s = column("seeds"), c_m = column("meets_criterion"), c_g = column("margin");
  if (c_dt < 0 || c_l < 0 || c_e < 0 || c_s < 0 || c_m < 0 || c_g < 0) {
    return Error{path +
                 ": not a sweep table (needs the columns dT, lambda, estimator, seeds, "
                 "meets_criterion, margin)"};
  }
  std::vector<sweep::CellStats> cells;
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.empty()) continue;
    const std::vector<std::string> f = SplitCsv(line);
    const std::string where = path + ": row " + std::to_string(row);
    if (f.size() != head.size())
      return Error{where + ": " + std::to_string(f.size()) + " fields, the header has " +
                   std::to_string(head.size())};
    sweep::CellStats c;
    auto dt = Number(f[c_dt], where + ", dT");
    auto l = Number(f[c_l], where + ", lambda");
    auto s = Number(f[c_s], where + ", seeds");
    auto g = Number(f[c_g], where + ", margin");
    for (const Result<double>* r : {&dt, &l, &s, &g}) {
      if (!*r) return Error{r->error()};
    }
    c.dT = *dt;
    c.lambda = *l;
    c.estimator = f[c_e];
    c.seeds = static_cast<int>(*s);
    c.margin = *g;
    c.meets = f[c_m] == "1";
    cells.push_back(std::move(c));
  }
  return cells;
}

}  // namespace

Result<SweepSettings> SweepChoice(const std::string& dir, const sim::Task& task,
                                  const std::string& estimator) {
  namespace fs = std::filesystem;
  const std::string md = (fs::path(dir) / "table.md").string();
  auto title = ReadFile(md);
  if (!title) return Error{title.error() + " (not a `recruit sweep` output folder?)"};
  const std::string first = title->substr(0, title->find('\n'));
  if (first != "# Sweep: " + task.name) {
    return Error{md + ": the sweep is of another task (\"" + first.substr(0, 60) +
                 "\"), not of \"" + task.name + "\""};
  }
  auto cells = ReadCells((fs::path(dir) / "table.csv").string());
  if (!cells) return Error{cells.error()};
  const sweep::Recommendation* best = nullptr;
  const std::vector<sweep::Recommendation> recs = sweep::Recommend(*cells);
  for (const sweep::Recommendation& r : recs) {
    if (r.estimator != estimator || !r.found) continue;
    if (best == nullptr || r.dT < best->dT || (r.dT == best->dT && r.margin > best->margin)) {
      best = &r;
    }
  }
  if (best == nullptr) {
    std::string swept;
    for (const sweep::Recommendation& r : recs) {
      if (swept.find(r.estimator) == std::string::npos)
        swept += (swept.empty() ? "" : ", ") + r.estimator;
    }
    if (swept.find(estimator) == std::string::npos) {
      return Error{dir + ": the sweep has no cell of estimator " + estimator + " (it swept " +
                   swept + "; pass --estimator)"};
    }
    return Error{dir + ": no cell of estimator " + estimator +
                 " meets the sweep's tracking criterion (nothing to recommend)"};
  }
  char why[160];
  std::snprintf(why, sizeof why, "the shortest dT meeting the criterion, margin %+.3f, %d seeds",
                best->margin, best->seeds);
  return SweepSettings{best->dT, best->lambda, why};
}

}  // namespace recruit::exporter
