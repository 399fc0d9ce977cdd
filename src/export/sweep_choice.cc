#include "export/sweep_choice.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/json_file.h"
#include "sweep/recommend.h"
#include "sweep/sweep_file.h"
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

// The cells of table.csv (plant point when the sweep has plant axes, dT, lambda, estimator,
// seeds, meets_criterion, margin); `has_plant`: the table has a plant column.
Result<std::vector<sweep::CellStats>> ReadCells(const std::string& path, bool* has_plant) {
  auto text = ReadFile(path);
  if (!text) return text.failure();
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
  const int c_p = column("plant");
  *has_plant = c_p >= 0;
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
      if (!*r) return r->failure();
    }
    if (c_p >= 0) {
      auto pl = Number(f[c_p], where + ", plant");
      if (!pl) return pl.failure();
      c.plant = static_cast<int>(*pl);
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

// The task of plant point `k` of the sweep in `dir`: its sweep file (sweep.json names it) gives
// the axes and points; the point's values are applied to the task's and its model's texts as the
// sweep applies them (sweep::ApplyPlantPoint). An edited model is the one the sweep wrote under
// DIR/models (named by its content), else written to the temporary folder.
Result<sim::Task> PlantTask(const std::string& dir, const sim::Task& task, int k,
                            std::vector<std::pair<std::string, double>>& values) {
  namespace fs = std::filesystem;
  const std::string id_path = (fs::path(dir) / "sweep.json").string();
  auto id = LoadJsonFile(id_path);
  if (!id) return id.failure();
  if (!id->contains("sweep") || !(*id)["sweep"].is_string()) {
    return Error{id_path + ": names no sweep file (\"sweep\"), so its plant points are unknown"};
  }
  const std::string sweep_path = (*id)["sweep"].get<std::string>();
  auto file = sweep::SweepFile::FromFile(sweep_path);
  if (!file) return file.failure();
  auto points = sweep::PlantPoints(*file);
  if (!points) return points.failure();
  const int n = static_cast<int>(points->size());
  if (k < 0 || k >= n) {
    return Error{"--plant-point " + std::to_string(k) + ": the sweep has " + std::to_string(n) +
                 " plant points (0.." + std::to_string(n - 1) + ", table.md's plant column)"};
  }
  auto task_text = ReadFile(task.source);
  if (!task_text) return task_text.failure();
  auto model_text = ReadFile(task.model_path);
  if (!model_text) return model_text.failure();
  auto in = sweep::ApplyPlantPoint(*task_text, *model_text, file->axes, (*points)[k],
                                   "sweep file '" + sweep_path + "'");
  if (!in) return in.failure();
  values = (*points)[k].values;
  std::string text = in->task_text;
  if (in->model_edited) {
    ContentHash h;
    h.Add(in->model_text);
    const std::string name = fs::path(task.model_path).stem().string() + "_" + h.Hex() + ".xml";
    fs::path model = fs::absolute(fs::path(dir) / "models" / name);
    std::error_code ec;
    if (!fs::exists(model, ec)) {
      model = fs::temp_directory_path() / ("recruit_export_" + name);
      RECRUIT_TRY(WriteFileAtomically(model.string(), in->model_text));
    }
    nlohmann::json doc = nlohmann::json::parse(text);
    doc["model"] = model.string();
    text = doc.dump(1);
  }
  return sim::Task::FromJsonText(text, task.source);
}

}  // namespace

Result<SweepSettings> SweepChoice(const std::string& dir, const sim::Task& task,
                                  const std::string& estimator, int plant_point) {
  namespace fs = std::filesystem;
  const std::string md = (fs::path(dir) / "table.md").string();
  auto title = ReadFile(md);
  if (!title) return Error{title.error() + " (not a `recruit sweep` output folder?)", title.code()};
  const std::string first = title->substr(0, title->find('\n'));
  if (first != "# Sweep: " + task.name) {
    return Error{md + ": the sweep is of another task (\"" + first.substr(0, 60) +
                 "\"), not of \"" + task.name + "\""};
  }
  bool has_plant = false;
  const std::string csv = (fs::path(dir) / "table.csv").string();
  auto cells = ReadCells(csv, &has_plant);
  if (!cells) return cells.failure();
  if (has_plant && plant_point < 0) {
    int points = 0;
    for (const sweep::CellStats& c : *cells) points = std::max(points, c.plant + 1);
    return Error{csv + ": the sweep varies the plant (" + std::to_string(points) +
                 " plant points): its recommendations are per plant point; pass --plant-point K "
                 "(table.md's plant column) to export for the sweep's plant at point K"};
  }
  if (!has_plant && plant_point >= 0) {
    return Error{"--plant-point: the sweep in '" + dir + "' has no plant axes"};
  }
  SweepSettings out;
  if (has_plant) {
    auto t = PlantTask(dir, task, plant_point, out.plant_values);
    if (!t) return Error{t.error(), t.code()};
    out.plant_task = std::move(t).value();
    out.plant_point = plant_point;
  }
  const sweep::Recommendation* best = nullptr;
  const std::vector<sweep::Recommendation> recs = sweep::Recommend(*cells);
  for (const sweep::Recommendation& r : recs) {
    if (r.estimator != estimator || !r.found || (has_plant && r.plant != plant_point)) continue;
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
                 (has_plant ? " at plant point " + std::to_string(plant_point) : std::string()) +
                 " meets the sweep's tracking criterion (nothing to recommend)"};
  }
  char why[160];
  std::snprintf(why, sizeof why, "the shortest dT meeting the criterion, margin %+.3f, %d seeds",
                best->margin, best->seeds);
  out.dT = best->dT;
  out.lambda = best->lambda;
  out.why = why;
  return out;
}

}  // namespace recruit::exporter
