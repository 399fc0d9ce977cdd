#include "sweep/sweep_file.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include "common/atomic_file.h"
#include "common/json_fields.h"
#include "common/json_file.h"
#include "common/short_text.h"
#include "control/on_count_estimator.h"
#include "control/sampling_period.h"
#include "sweep/sampling.h"

namespace recruit::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
using json_fields::CheckKeys;

std::string Resolve(const std::string& path, const std::string& source) {
  if (path.empty() || fs::path(path).is_absolute() || source.empty()) return path;
  return (fs::path(source).parent_path() / path).lexically_normal().string();
}

// Values of an axis: [v, ...] or {"values": [...]} or {"range": [lo, hi], "steps": k,
// "scale": "lin"|"log"}; `where` names the axis in errors.
struct Values {
  std::vector<double> values;
  double lo = 0, hi = 0;
  bool has_range = false, log = false;
};

Result<Values> ParseValues(const json& j, const std::string& where, bool need_steps) {
  Values v;
  const json* list = nullptr;
  if (j.is_array()) {
    list = &j;
  } else if (j.is_object() && j.contains("values")) {
    list = &j.at("values");
  }
  if (list) {
    if (!list->is_array() || list->empty()) {
      return Error{where + ".values: must be a non-empty array of numbers, got " +
                   ShortText(list->dump())};
    }
    for (const json& x : *list) {
      if (!x.is_number() || !std::isfinite(x.get<double>())) {
        return Error{where + ": value " + ShortText(x.dump()) + " is not a finite number"};
      }
      v.values.push_back(x.get<double>());
    }
    return v;
  }
  if (!j.is_object() || !j.contains("range")) {
    return Error{where + ": give \"values\": [..] or \"range\": [lo, hi] (with \"steps\"), got " +
                 ShortText(j.dump())};
  }
  const json& r = j.at("range");
  if (!r.is_array() || r.size() != 2 || !r[0].is_number() || !r[1].is_number()) {
    return Error{where + ".range: must be [lo, hi], got " + ShortText(r.dump())};
  }
  v.lo = r[0].get<double>();
  v.hi = r[1].get<double>();
  v.has_range = true;
  if (!std::isfinite(v.lo) || !std::isfinite(v.hi) || !(v.lo <= v.hi)) {
    return Error{where + ".range: " + r.dump() + " must be finite with lo <= hi"};
  }
  if (j.contains("scale")) {
    const json& s = j.at("scale");
    if (s == "log") {
      v.log = true;
    } else if (s != "lin") {
      return Error{where + ".scale: " + ShortText(s.dump()) + "; allowed: \"lin\", \"log\""};
    }
  }
  if (v.log && !(v.lo > 0)) return Error{where + ".range: a log scale needs lo > 0"};
  int steps = 0;
  if (j.contains("steps")) {
    const json& s = j.at("steps");
    if (!s.is_number_integer() || s.get<long>() < 1 || s.get<long>() > 100000) {
      return Error{where + ".steps: " + ShortText(s.dump()) +
                   "; allowed: a whole number 1..100000"};
    }
    steps = s.get<int>();
  } else if (need_steps) {
    return Error{where + ": a range on a grid needs \"steps\" (number of values, >= 1)"};
  }
  for (int i = 0; i < steps; ++i) {
    const double f = steps == 1 ? 0.0 : static_cast<double>(i) / (steps - 1);
    v.values.push_back(v.log ? v.lo * std::pow(v.hi / v.lo, f) : v.lo + f * (v.hi - v.lo));
  }
  return v;
}

std::string FormatValue(double v, bool integer) {
  return integer ? fmt::format("{}", static_cast<long long>(std::llround(v)))
                 : fmt::format("{:.17g}", v);
}

}  // namespace

double PlantAxis::FromUnit(double u) const {
  double x;
  if (has_range) {
    x = log ? lo * std::pow(hi / lo, u) : lo + u * (hi - lo);
  } else {
    const size_t i = std::min(values.size() - 1, static_cast<size_t>(u * values.size()));
    x = values[i];
  }
  return integer ? std::round(x) : x;
}

Result<SweepFile> SweepFile::FromFile(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{"sweep file: " + text.error(), text.code()};
  return FromJsonText(*text, path);
}

Result<SweepFile> SweepFile::FromJsonText(const std::string& text, const std::string& source) {
  const std::string file = "sweep file '" + (source.empty() ? "<sweep>" : source) + "'";
  auto parsed = ParseJsonText(text, source.empty() ? "<sweep>" : source);
  if (!parsed.ok()) return Error{parsed.error(), parsed.code()};
  const json j = std::move(parsed).value();
  if (!j.is_object()) return Error{file + ": must be a JSON object"};
  RECRUIT_TRY(
      CheckKeys(j, {"task", "duration", "controller", "plant", "criterion", "comment"}, file));
  SweepFile f;
  f.source = source;
  if (j.contains("task")) {
    if (!j["task"].is_string()) return Error{file + ".task: must be a path (string)"};
    f.task = Resolve(j["task"].get<std::string>(), source);
  }
  if (j.contains("duration")) {
    double d = 0;
    RECRUIT_TRY(json_fields::Number(j, "duration", file, &d, true, 0, 1e6, true,
                                    "seconds, 0 < duration <= 1e6"));
    f.duration = d;
  }
  if (j.contains("controller")) {
    const json& c = j["controller"];
    const std::string where = file + ".controller";
    if (!c.is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(c, {"dT", "lambda", "estimator", "seeds", "base_seed"}, where));
    if (c.contains("dT")) {
      auto v = ParseValues(c["dT"], where + ".dT", true);
      if (!v.ok()) return Error{v.error(), v.code()};
      for (double x : v->values) {
        if (!control::ValidDT(x)) {
          return Error{fmt::format("{}.dT: value {:g} is out of range; allowed: {}", where, x,
                                   control::kDTAllowed)};
        }
      }
      f.dTs = v->values;
    }
    if (c.contains("lambda")) {
      auto v = ParseValues(c["lambda"], where + ".lambda", true);
      if (!v.ok()) return Error{v.error(), v.code()};
      for (double x : v->values) {
        if (!(x > 0 && x <= 1)) {
          return Error{fmt::format(
              "{}.lambda: value {:g} is out of range; allowed: 0 < lambda <= 1", where, x)};
        }
      }
      f.lambdas = v->values;
    }
    if (c.contains("estimator")) {
      const json& e = c["estimator"];
      const json list = e.is_string() ? json::array({e}) : e;
      if (!list.is_array() || list.empty()) {
        return Error{where + ".estimator: must be a name or a non-empty array of names"};
      }
      for (const json& x : list) {
        // The kinds a task's controller takes (control::EstimatorSpec::Parse).
        if (!x.is_string() || !control::EstimatorSpec::Parse(x.get<std::string>()).ok()) {
          return Error{where + ".estimator: " + ShortText(x.dump()) +
                       "; allowed: output, kalman2, kalman-augmented, kalman-failures"};
        }
        f.estimators.push_back(x.get<std::string>());
      }
    }
    if (c.contains("seeds")) {
      std::int64_t seeds = 0;
      RECRUIT_TRY(json_fields::Integer(c, "seeds", where, &seeds, true, 1, 100000, "1..100000"));
      f.seeds = static_cast<int>(seeds);
    }
    if (c.contains("base_seed")) {
      std::uint64_t seed = 0;
      RECRUIT_TRY(json_fields::Unsigned(c, "base_seed", where, &seed, true));
      f.base_seed = seed;
    }
  }
  if (j.contains("criterion")) {
    const json& c = j["criterion"];
    const std::string where = file + ".criterion";
    if (!c.is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(c, {"max_overshoot", "min_settled"}, where));
    sweep::TrackingCriterion crit;
    RECRUIT_TRY(json_fields::Number(c, "max_overshoot", where, &crit.max_overshoot, false, 0,
                                    std::numeric_limits<double>::max(), false, "a number >= 0"));
    RECRUIT_TRY(json_fields::Number(c, "min_settled", where, &crit.min_settled, false, 0, 1, false,
                                    "a number in [0, 1]"));
    f.criterion = crit;
  }
  if (j.contains("plant")) {
    const json& p = j["plant"];
    const std::string where = file + ".plant";
    if (!p.is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(p, {"sampling", "samples", "seed", "axes"}, where));
    if (p.contains("sampling")) {
      const json& s = p["sampling"];
      if (s == "grid") {
        f.sampling = Sampling::kGrid;
      } else if (s == "lhs") {
        f.sampling = Sampling::kLatinHypercube;
      } else if (s == "sobol") {
        f.sampling = Sampling::kSobol;
      } else {
        return Error{where + ".sampling: " + ShortText(s.dump()) +
                     "; allowed: \"grid\", \"lhs\", \"sobol\""};
      }
    }
    if (f.sampling != Sampling::kGrid) {
      std::int64_t samples = 0;
      RECRUIT_TRY(json_fields::Integer(p, "samples", where, &samples, true, 1, 1000000,
                                       "a sample needs a whole number of points, 1..1000000"));
      f.samples = static_cast<int>(samples);
      std::uint64_t seed = f.sample_seed;
      RECRUIT_TRY(json_fields::Unsigned(p, "seed", where, &seed, false));
      f.sample_seed = seed;
    }
    const json axes = p.value("axes", json::array());
    if (!axes.is_array()) return Error{where + ".axes: must be an array of axes"};
    std::set<std::string> names, paths;
    for (size_t i = 0; i < axes.size(); ++i) {
      const json& a = axes[i];
      std::string aw = fmt::format("{}.axes[{}]", where, i);
      if (!a.is_object()) return Error{aw + ": must be an object {name, path, values | range}"};
      RECRUIT_TRY(
          CheckKeys(a, {"name", "path", "values", "range", "steps", "scale", "integer"}, aw));
      PlantAxis ax;
      if (!a.contains("path") || !a["path"].is_string() || a["path"].get<std::string>().empty()) {
        return Error{aw +
                     ".path: missing; a JSON pointer into the task (\"/sensor/noise_std\") "
                     "or \"model:INSTANCE/KEY\""};
      }
      ax.path = a["path"];
      ax.name = a.value("name", ax.path);
      if (!a.value("name", json("")).is_string()) return Error{aw + ".name: must be a string"};
      aw = fmt::format("{} (axis '{}')", aw, ax.name);
      if (ax.path.rfind("model:", 0) == 0) {
        const std::string rest = ax.path.substr(6);
        const auto slash = rest.find('/');
        if (slash == std::string::npos || slash == 0 || slash + 1 == rest.size()) {
          return Error{aw + ".path: '" + ax.path + "' must be model:INSTANCE/KEY"};
        }
        ax.instance = rest.substr(0, slash);
        ax.key = rest.substr(slash + 1);
      } else if (ax.path[0] != '/') {
        return Error{aw + ".path: '" + ShortText(ax.path) +
                     "' is neither a JSON pointer (starts with '/') nor model:INSTANCE/KEY"};
      } else if (ax.path == "/controller/dT" || ax.path == "/controller/lambda" ||
                 ax.path == "/controller/estimator") {
        return Error{aw + ".path: '" + ax.path +
                     "' is a controller axis; set it in \"controller\" (the sweep's own axes)"};
      } else {
        try {
          (void)json::json_pointer(ax.path);
        } catch (const json::exception& e) {
          return Error{aw + ".path: '" + ShortText(ax.path) +
                       "' is not a JSON pointer: " + e.what()};
        }
      }
      if (!names.insert(ax.name).second) return Error{aw + ".name: repeated axis name"};
      if (!paths.insert(ax.path).second) return Error{aw + ".path: repeated path " + ax.path};
      RECRUIT_TRY(json_fields::Boolean(a, "integer", aw, &ax.integer));
      auto v = ParseValues(a, aw, f.sampling == Sampling::kGrid);
      if (!v.ok()) return Error{v.error(), v.code()};
      ax.values = v->values;
      ax.lo = v->lo;
      ax.hi = v->hi;
      ax.has_range = v->has_range;
      ax.log = v->log;
      if (ax.integer) {
        for (double& x : ax.values) x = std::round(x);
      }
      f.axes.push_back(ax);
    }
    if (f.sampling == Sampling::kSobol && static_cast<int>(f.axes.size()) > MaxSobolDims()) {
      return Error{fmt::format("{}.axes: {} axes; a Sobol sample takes at most {} (use \"lhs\")",
                               where, f.axes.size(), MaxSobolDims())};
    }
  }
  return f;
}

Result<std::vector<sweep::PlantPoint>> PlantPoints(const SweepFile& f) {
  std::vector<sweep::PlantPoint> points;
  if (f.axes.empty()) return std::vector<sweep::PlantPoint>{sweep::PlantPoint{}};
  if (f.sampling == Sampling::kGrid) {
    size_t total = 1;
    for (const auto& a : f.axes) {
      total *= a.values.size();
      if (total > 10000000) return Error{"sweep file '" + f.source + "': the grid is too large"};
    }
    for (size_t i = 0; i < total; ++i) {
      sweep::PlantPoint p;
      size_t rem = i;
      std::vector<size_t> idx(f.axes.size());
      for (size_t k = f.axes.size(); k-- > 0;) {  // last axis fastest
        idx[k] = rem % f.axes[k].values.size();
        rem /= f.axes[k].values.size();
      }
      for (size_t k = 0; k < f.axes.size(); ++k) {
        p.values.emplace_back(f.axes[k].name, f.axes[k].values[idx[k]]);
      }
      points.push_back(p);
    }
    return points;
  }
  const int dims = static_cast<int>(f.axes.size());
  UnitPoints u;
  if (f.sampling == Sampling::kLatinHypercube) {
    u = LatinHypercube(f.samples, dims, f.sample_seed);
  } else {
    auto s = Sobol(f.samples, dims, f.sample_seed);
    if (!s.ok()) return Error{"sweep file '" + f.source + "': " + s.error(), s.code()};
    u = std::move(s).value();
  }
  for (const auto& row : u) {
    sweep::PlantPoint p;
    for (int k = 0; k < dims; ++k)
      p.values.emplace_back(f.axes[k].name, f.axes[k].FromUnit(row[k]));
    points.push_back(p);
  }
  return points;
}

Result<PlantInputs> ApplyPlantPoint(const std::string& task_text, const std::string& model_text,
                                    const std::vector<PlantAxis>& axes,
                                    const sweep::PlantPoint& point, const std::string& where) {
  PlantInputs out;
  out.model_text = model_text;
  json doc;
  try {
    doc = json::parse(task_text);
  } catch (const json::exception& e) {
    return Error{where + ": the task is not JSON: " + e.what()};
  }
  for (size_t k = 0; k < axes.size(); ++k) {
    const PlantAxis& a = axes[k];
    const double v = point.values.at(k).second;
    const std::string label = fmt::format("{}: axis '{}' ({}) value {}", where, a.name, a.path,
                                          FormatValue(v, a.integer));
    if (a.is_model()) {
      auto xml = SetPluginConfig(out.model_text, a.instance, a.key, FormatValue(v, a.integer));
      if (!xml.ok()) return Error{label + ": " + xml.error(), xml.code()};
      out.model_text = std::move(xml).value();
      out.model_edited = true;
      continue;
    }
    const json::json_pointer ptr(a.path);
    const json::json_pointer parent = ptr.parent_pointer();
    // A failure key of a bundle the task gives no failures ("/failures/BUNDLE/open_rate"): the
    // objects on the way are made (the task's check then names a bad bundle or key).
    if (a.path.rfind("/failures/", 0) == 0 &&
        ptr.parent_pointer().parent_pointer().to_string() == "/failures") {
      if (!doc.contains(parent)) doc[parent] = json::object();
    }
    if (!doc.contains(parent)) {
      return Error{label + ": the task has no '" + parent.to_string() + "'"};
    }
    json& p = doc.at(parent);
    const std::string last = ptr.back();
    if (p.is_array()) {
      std::size_t i = 0;
      try {
        i = std::stoul(last);
      } catch (...) {
        return Error{label + ": '" + last + "' is not an index of the array " + parent.to_string()};
      }
      if (i >= p.size()) {
        return Error{fmt::format("{}: index {} is past the end of {} ({} elements)", label, i,
                                 parent.to_string(), p.size())};
      }
    } else if (!p.is_object()) {
      return Error{label + ": '" + parent.to_string() + "' is not an object or array"};
    }
    if (doc.contains(ptr) && !doc.at(ptr).is_number()) {
      return Error{label + ": the task's value there is " + ShortText(doc.at(ptr).dump()) +
                   ", not a number"};
    }
    if (a.integer) {
      doc[ptr] = static_cast<long long>(std::llround(v));
    } else {
      doc[ptr] = v;
    }
  }
  out.task_text = doc.dump(1);
  return out;
}

}  // namespace recruit::sweep
