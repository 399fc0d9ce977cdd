#include "sim/task.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "common/atomic_file.h"
#include "common/json_fields.h"
#include "common/json_file.h"
#include "common/short_text.h"

namespace recruit::sim {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;
using json_fields::CheckKeys;
using json_fields::Number;
using json_fields::String;
using json_fields::Vec3;

std::string Resolve(const std::string& path, const std::string& source) {
  if (path.empty() || fs::path(path).is_absolute() || source.empty()) return path;
  return (fs::path(source).parent_path() / path).lexically_normal().string();
}

// A reference in the unit the file states (N for force tasks; deg, the default, or rad for
// angle tasks), returned in N or rad.
Result<Reference> ReadReference(const json& r, const std::string& where, Tracked tracked) {
  std::string unit = tracked == Tracked::kForce ? "N" : "deg";
  if (r.is_object() && r.contains("unit")) {
    if (!r["unit"].is_string()) return Error{where + ".unit: must be a string"};
    unit = r["unit"];
  }
  double scale = 1;
  if (tracked == Tracked::kForce) {
    if (unit != "N") return Error{where + ".unit: '" + unit + "' for a force task; allowed: N"};
  } else if (unit == "deg") {
    scale = M_PI / 180;
  } else if (unit != "rad") {
    return Error{where + ".unit: '" + unit + "' for an angle task; allowed: deg, rad"};
  }
  json body = r;
  if (body.is_object()) body.erase("unit");
  auto ref = Reference::FromJson(body, where, scale);
  if (!ref.ok()) return Error{ref.error(), ref.code()};
  if (tracked == Tracked::kForce && ref->MinValue() < 0) {
    return Error{where + ": a force reference must be >= 0 N (a bundle can only pull)"};
  }
  return ref;
}

// The several-joint form: "joints": [{"joint", "reference"}, ...] and optional "bundles"; the
// one-joint fields are not allowed beside it.
Status ReadJointsForm(const json& j, const std::string& file, Task& task) {
  if (task.tracked != Tracked::kAngle) {
    return Error{file + ".joints: only angle tasks drive joints (tracked is 'force')"};
  }
  for (const char* key : {"joint", "reference", "agonist", "antagonist"}) {
    if (j.contains(key)) {
      return Error{file + "." + key + ": not with 'joints' (each joint has its own reference)"};
    }
  }
  const json& js = j["joints"];
  if (!js.is_array() || js.empty() || js.size() > 64) {
    return Error{file + ".joints: must be an array of 1 to 64 objects {\"joint\", \"reference\"}"};
  }
  for (size_t i = 0; i < js.size(); ++i) {
    const std::string where = file + ".joints[" + std::to_string(i) + "]";
    if (!js[i].is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(js[i], {"joint", "reference"}, where));
    DrivenJoint d;
    RECRUIT_TRY(String(js[i], "joint", where, &d.joint, true));
    for (const DrivenJoint& other : task.joints) {
      if (other.joint == d.joint) return Error{where + ".joint: '" + d.joint + "' is listed twice"};
    }
    if (!js[i].contains("reference")) return Error{where + ": missing field 'reference'"};
    auto ref = ReadReference(js[i]["reference"], where + ".reference", Tracked::kAngle);
    if (!ref.ok()) return Error{ref.error(), ref.code()};
    d.reference = std::move(ref).value();
    task.joints.push_back(std::move(d));
  }
  task.joint = task.joints[0].joint;
  task.reference = task.joints[0].reference;
  if (j.contains("bundles")) {
    const json& bs = j["bundles"];
    if (!bs.is_array() || bs.empty() || bs.size() > 256) {
      return Error{file + ".bundles: must be an array of 1 to 256 actuator names"};
    }
    for (size_t i = 0; i < bs.size(); ++i) {
      const std::string where = file + ".bundles[" + std::to_string(i) + "]";
      if (!bs[i].is_string() || bs[i].get<std::string>().empty()) {
        return Error{where + ": must be a non-empty string, got " + ShortText(bs[i].dump(), 60)};
      }
      const std::string name = bs[i];
      if (std::find(task.bundles.begin(), task.bundles.end(), name) != task.bundles.end()) {
        return Error{where + ": '" + name + "' is listed twice"};
      }
      task.bundles.push_back(name);
    }
    task.agonist = task.bundles[0];
  }
  return Status::Ok();
}

// A number as the plugin reads it back exactly (%.17g; "%g" for messages).
std::string Digits(double v, const char* format = "%.17g") {
  char buf[40];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// The plugin's failure keys of one bundle, checked against plugin/README.md's ranges:
// {"open_rate", "stuck_rate", "open_per_cycle", "stuck_per_cycle", "schedule": [{"time",
// "count", "mode"}], "fatigue_loss", "fatigue_cycles", "fatigue_stress", "fatigue_exponent"}.
Result<BundleFailures> ReadBundleFailures(const json& f, const std::string& actuator,
                                          const std::string& where) {
  if (!f.is_object()) return Error{where + ": must be an object of failure keys"};
  RECRUIT_TRY(CheckKeys(f,
                        {"open_rate", "stuck_rate", "open_per_cycle", "stuck_per_cycle", "schedule",
                         "fatigue_loss", "fatigue_cycles", "fatigue_stress", "fatigue_exponent"},
                        where));
  BundleFailures b;
  b.actuator = actuator;
  struct Key {
    const char* name;
    double lo, hi;
    bool lo_open;
    const char* allowed;
  };
  static const Key kRates[] = {
      {"open_rate", 0, 3600, false, "per hour heated, 0 <= open_rate <= 3600"},
      {"stuck_rate", 0, 3600, false, "per hour heated, 0 <= stuck_rate <= 3600"},
      {"open_per_cycle", 0, 1, false, "a probability per cycle, 0 <= open_per_cycle <= 1"},
      {"stuck_per_cycle", 0, 1, false, "a probability per cycle, 0 <= stuck_per_cycle <= 1"}};
  static const Key kFatigue[] = {
      {"fatigue_loss", 0, 0.9, false, "a fraction of force, 0 <= fatigue_loss <= 0.9"},
      {"fatigue_cycles", 0, 1e9, true, "reference cycles, 0 < fatigue_cycles <= 1e9"},
      {"fatigue_stress", 0, 2e9, true, "Pa, 0 < fatigue_stress <= 2e9"},
      {"fatigue_exponent", 0, 10, false, "0 <= fatigue_exponent <= 10"}};
  auto add = [&](const Key& k) -> Status {
    if (!f.contains(k.name)) return Status::Ok();
    double v = 0;
    RECRUIT_TRY(Number(f, k.name, where, &v, true, k.lo, k.hi, k.lo_open, k.allowed));
    b.keys.emplace_back(k.name, Digits(v));
    return Status::Ok();
  };
  for (const Key& k : kRates) RECRUIT_TRY(add(k));
  double per_cycle = 0;
  for (const auto& [key, value] : b.keys) {
    if (key == "open_per_cycle" || key == "stuck_per_cycle") per_cycle += std::stod(value);
  }
  if (per_cycle > 1) {
    return Error{where + ": open_per_cycle + stuck_per_cycle = " + Digits(per_cycle, "%g") +
                 "; allowed: at most 1"};
  }
  if (f.contains("schedule")) {
    const json& s = f["schedule"];
    if (!s.is_array() || s.empty() || s.size() > 1000) {
      return Error{where + ".schedule: must be an array of 1 to 1000 {\"time\", \"count\", " +
                   "\"mode\"}, got " + ShortText(s.dump(), 60)};
    }
    std::string text;
    for (size_t i = 0; i < s.size(); ++i) {
      const std::string w = where + ".schedule[" + std::to_string(i) + "]";
      if (!s[i].is_object())
        return Error{w + ": must be an object {\"time\", \"count\", \"mode\"}"};
      RECRUIT_TRY(CheckKeys(s[i], {"time", "count", "mode"}, w));
      double t = 0;
      std::int64_t count = 0;
      std::string mode;
      RECRUIT_TRY(Number(s[i], "time", w, &t, true, 0, 1e9, false, "seconds after reset, 0..1e9"));
      RECRUIT_TRY(json_fields::Integer(s[i], "count", w, &count, true, 0, 1000000,
                                       "a whole number of units, 0..1000000"));
      RECRUIT_TRY(String(s[i], "mode", w, &mode, true));
      if (mode != "open" && mode != "stuck") {
        return Error{w + ".mode: '" + ShortText(mode, 40) + "'; allowed: open, stuck"};
      }
      // 0 units: nothing fails then (a sweep's baseline point of a count axis).
      if (count > 0)
        text += (text.empty() ? "" : ",") + Digits(t) + ":" + std::to_string(count) + ":" + mode;
    }
    if (!text.empty()) b.keys.emplace_back("failures", text);
  }
  for (const Key& k : kFatigue) RECRUIT_TRY(add(k));
  if (f.empty()) return Error{where + ": gives no failure key"};
  return b;  // no keys when every scheduled count is 0: the bundle runs as without failures
}

Status ReadFailures(const json& j, const std::string& file, Task& task) {
  const json& f = j["failures"];
  const std::string where = file + ".failures";
  if (!f.is_object() || f.empty()) {
    return Error{where + ": must be an object {\"ACTUATOR\": {failure keys}, ...}, got " +
                 ShortText(f.dump(), 60)};
  }
  for (auto it = f.begin(); it != f.end(); ++it) {
    auto b = ReadBundleFailures(it.value(), it.key(), where + "." + it.key());
    if (!b.ok()) return Error{b.error(), b.code()};
    if (!b->keys.empty()) task.failures.push_back(std::move(b).value());
  }
  return Status::Ok();
}

}  // namespace

Result<Task> Task::FromFile(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{"task file: " + text.error(), text.code()};
  return FromJsonText(*text, path);
}

Result<Task> Task::FromJsonText(const std::string& text, const std::string& source) {
  const std::string file = source.empty() ? std::string("<task>") : source;
  auto parsed = ParseJsonText(text, file);  // depth, size, 1e999 and BOM checked
  if (!parsed.ok()) return Error{parsed.error(), parsed.code()};
  json j = std::move(parsed).value();
  if (!j.is_object()) return Error{file + ": the task must be a JSON object"};
  RECRUIT_TRY(CheckKeys(j,
                        {"name",        "description", "model",      "tracked",        "agonist",
                         "antagonist",  "joint",       "duration",   "timestep",       "reference",
                         "controller",  "sensor",      "outer_loop", "pushes",         "payloads",
                         "settle_band", "joints",      "bundles",    "co_contraction", "failures"},
                        file));
  Task task;
  task.source = source;
  RECRUIT_TRY(String(j, "name", file, &task.name, true));
  if (j.contains("description"))
    RECRUIT_TRY(String(j, "description", file, &task.description, false));
  RECRUIT_TRY(String(j, "model", file, &task.model_path, true));
  task.model_path = Resolve(task.model_path, source);
  // The error_code form: a path the system refuses (too long, ...) is an error message, not an
  // exception (found by the task fuzzer).
  std::error_code ec;
  if (!fs::exists(task.model_path, ec)) {
    return Error{file + ".model: model file '" + ShortText(task.model_path, 120) +
                     "' does not exist" + (ec ? " (" + ec.message() + ")" : ""),
                 ec ? CodeOf(ec) : ErrorCode::kBadInput};
  }
  std::string tracked;
  RECRUIT_TRY(String(j, "tracked", file, &tracked, true));
  if (tracked == "force") {
    task.tracked = Tracked::kForce;
  } else if (tracked == "angle") {
    task.tracked = Tracked::kAngle;
  } else {
    return Error{file + ".tracked: unknown '" + tracked + "'; allowed: force, angle"};
  }
  if (j.contains("joints")) {
    RECRUIT_TRY(ReadJointsForm(j, file, task));
  } else {
    RECRUIT_TRY(String(j, "agonist", file, &task.agonist, true));
    RECRUIT_TRY(String(j, "antagonist", file, &task.antagonist, false));
    if (task.antagonist == task.agonist) {
      return Error{file + ".antagonist: must differ from 'agonist' ('" + task.agonist + "')"};
    }
    RECRUIT_TRY(String(j, "joint", file, &task.joint, task.tracked == Tracked::kAngle));
    if (j.contains("bundles")) {
      return Error{file + ".bundles: only with 'joints' (this task names 'agonist')"};
    }
  }
  RECRUIT_TRY(Number(j, "duration", file, &task.duration, true, 0, 1e6, true,
                     "seconds, 0 < duration <= 1e6"));
  RECRUIT_TRY(Number(j, "timestep", file, &task.timestep, false, 1e-5, 0.05, false,
                     "seconds, 1e-5 <= timestep <= 0.05"));
  RECRUIT_TRY(Number(j, "settle_band", file, &task.settle_band, false, 0, 1, true,
                     "a fraction of the step size, 0 < settle_band <= 1"));

  if (!j.contains("joints")) {
    if (!j.contains("reference")) return Error{file + ": missing field 'reference'"};
    auto ref = ReadReference(j["reference"], file + ".reference", task.tracked);
    if (!ref.ok()) return Error{ref.error(), ref.code()};
    task.reference = std::move(ref).value();
  }

  if (j.contains("controller")) {
    const json& c = j["controller"];
    const std::string where = file + ".controller";
    if (!c.is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(c,
                          {"estimator", "filter_model", "dT", "lambda", "force_noise_std",
                           "force_scale_variance", "census_period"},
                          where));
    RECRUIT_TRY(String(c, "estimator", where, &task.controller.estimator, false));
    RECRUIT_TRY(String(c, "filter_model", where, &task.controller.filter_model, false));
    task.controller.filter_model = Resolve(task.controller.filter_model, source);
    RECRUIT_TRY(Number(c, "dT", where, &task.controller.dT, false, 0, control::kMaxDT, true,
                       control::kDTAllowed));
    RECRUIT_TRY(
        Number(c, "lambda", where, &task.controller.lambda, false, 0, 1, true, "0 < lambda <= 1"));
    RECRUIT_TRY(Number(c, "force_noise_std", where, &task.controller.force_noise_std, false, 0, 1e6,
                       false, "0 <= force_noise_std <= 1e6 N (0: the estimator's default)"));
    RECRUIT_TRY(Number(c, "force_scale_variance", where, &task.controller.force_scale_variance,
                       false, 0, 1, false,
                       "0 <= force_scale_variance <= 1 per control period (0: the scale fixed)"));
    RECRUIT_TRY(Number(c, "census_period", where, &task.controller.census_period, false, 0, 1e6,
                       false, "0 <= census_period <= 1e6 s (0: no census)"));
  }

  if (j.contains("sensor")) {
    auto sensor = SensorParams::FromJson(j["sensor"], file + ".sensor");
    if (!sensor.ok()) return Error{sensor.error(), sensor.code()};
    task.sensor = *sensor;
  }

  if (j.contains("outer_loop") && j["outer_loop"] == "auto") {
    if (task.tracked != Tracked::kAngle) {
      return Error{file + ".outer_loop: only angle tasks have an outer loop (tracked is 'force')"};
    }
    task.auto_loop = true;
  } else if (j.contains("outer_loop")) {
    if (!task.joints.empty()) {
      return Error{file +
                   ".outer_loop: a task with 'joints' designs its own loop; allowed: \"auto\""};
    }
    const json& o = j["outer_loop"];
    const std::string where = file + ".outer_loop";
    if (task.tracked != Tracked::kAngle) {
      return Error{where + ": only angle tasks have an outer loop (tracked is 'force')"};
    }
    if (!o.is_object()) return Error{where + ": must be an object"};
    RECRUIT_TRY(CheckKeys(o, {"kp", "ki", "kd", "feedforward", "tone", "max_force"}, where));
    OuterLoop loop;
    RECRUIT_TRY(Number(o, "kp", where, &loop.kp, true, 0, 1e6, false, "N/rad, >= 0"));
    RECRUIT_TRY(Number(o, "ki", where, &loop.ki, false, 0, 1e6, false, "N/(rad s), >= 0"));
    RECRUIT_TRY(Number(o, "kd", where, &loop.kd, false, 0, 1e6, false, "N s/rad, >= 0"));
    RECRUIT_TRY(
        Number(o, "feedforward", where, &loop.feedforward, false, -1e6, 1e6, false, "N, finite"));
    RECRUIT_TRY(Number(o, "tone", where, &loop.tone, false, 0, 1e6, false, "N, >= 0"));
    RECRUIT_TRY(Number(o, "max_force", where, &loop.max_force, false, 0, 1e6, true, "N, > 0"));
    if (loop.tone > loop.max_force) {
      return Error{where + ".tone: must not exceed max_force"};
    }
    task.outer = loop;
  } else if (task.tracked == Tracked::kAngle && task.joints.empty()) {
    return Error{file + ": missing field 'outer_loop' (\"auto\", or the PI gains kp, ki)"};
  } else {
    task.auto_loop = task.tracked == Tracked::kAngle;  // the joints form's default
  }
  if (task.auto_loop && task.joints.empty()) {
    // The one-joint form: its joint and reference, served by its agonist and antagonist.
    task.joints.push_back({task.joint, task.reference});
    task.bundles.push_back(task.agonist);
    if (!task.antagonist.empty()) task.bundles.push_back(task.antagonist);
  }
  if (j.contains("co_contraction")) {
    if (!task.auto_loop) {
      return Error{file + ".co_contraction: only with \"outer_loop\": \"auto\""};
    }
    RECRUIT_TRY(Number(j, "co_contraction", file, &task.co_contraction, false, 0, 0.5, false,
                       "a fraction of each bundle's capacity, 0 <= co_contraction <= 0.5"));
  }

  if (j.contains("pushes")) {
    if (!j["pushes"].is_array()) return Error{file + ".pushes: must be an array"};
    for (size_t i = 0; i < j["pushes"].size(); ++i) {
      const json& p = j["pushes"][i];
      const std::string where = file + ".pushes[" + std::to_string(i) + "]";
      if (!p.is_object()) return Error{where + ": must be an object"};
      RECRUIT_TRY(CheckKeys(p, {"body", "start", "duration", "force", "torque"}, where));
      Push push;
      RECRUIT_TRY(String(p, "body", where, &push.body, true));
      RECRUIT_TRY(Number(p, "start", where, &push.start, true, 0, 1e6, false, "seconds, >= 0"));
      RECRUIT_TRY(Number(p, "duration", where, &push.duration, true, 0, 1e6, true, "seconds, > 0"));
      RECRUIT_TRY(Vec3(p, "force", where, &push.force));
      RECRUIT_TRY(Vec3(p, "torque", where, &push.torque));
      task.pushes.push_back(push);
    }
  }
  if (j.contains("payloads")) {
    if (!j["payloads"].is_array()) return Error{file + ".payloads: must be an array"};
    for (size_t i = 0; i < j["payloads"].size(); ++i) {
      const json& p = j["payloads"][i];
      const std::string where = file + ".payloads[" + std::to_string(i) + "]";
      if (!p.is_object()) return Error{where + ": must be an object"};
      RECRUIT_TRY(CheckKeys(p, {"body", "mass", "time"}, where));
      Payload pl;
      RECRUIT_TRY(String(p, "body", where, &pl.body, true));
      RECRUIT_TRY(
          Number(p, "mass", where, &pl.mass, true, 1e-6, 1e3, false, "kg, 1e-6 <= mass <= 1000"));
      RECRUIT_TRY(Number(p, "time", where, &pl.time, false, 0, 1e6, false, "seconds, >= 0"));
      task.payloads.push_back(pl);
    }
  }
  if (j.contains("failures")) RECRUIT_TRY(ReadFailures(j, file, task));
  return task;
}

Result<std::string> SetPluginConfig(const std::string& xml, const std::string& instance,
                                    const std::string& key, const std::string& value) {
  std::vector<std::string> seen;
  size_t pos = 0;
  while ((pos = xml.find("<instance", pos)) != std::string::npos) {
    const size_t tag_end = xml.find('>', pos);
    if (tag_end == std::string::npos) break;
    const std::string tag = xml.substr(pos, tag_end - pos);
    const size_t n = tag.find("name=");
    std::string name;
    if (n != std::string::npos && n + 6 < tag.size()) {
      const char q = tag[n + 5];
      const size_t e = tag.find(q, n + 6);
      if (e != std::string::npos) name = tag.substr(n + 6, e - n - 6);
    }
    if (name != instance) {
      seen.push_back(name);
      pos = tag_end;
      continue;
    }
    if (tag.back() == '/') {  // <instance name="x"/>: no config lines yet
      std::string out = xml.substr(0, pos) + tag.substr(0, tag.size() - 1) + "><config key=\"" +
                        key + "\" value=\"" + value + "\"/></instance" + xml.substr(tag_end);
      return out;
    }
    const size_t close = xml.find("</instance>", tag_end);
    if (close == std::string::npos) return Error{"instance '" + instance + "' is not closed"};
    for (const char q : {'"', '\''}) {
      const std::string needle = std::string("key=") + q + key + q;
      const size_t k = xml.find(needle, tag_end);
      if (k == std::string::npos || k > close) continue;
      const size_t cfg = xml.rfind("<config", k);
      const size_t cfg_end = xml.find('>', k);
      const size_t v = xml.find("value=", cfg);
      if (cfg == std::string::npos || cfg < tag_end || v == std::string::npos || v > cfg_end) {
        return Error{"config key '" + key + "' of instance '" + instance + "' has no value"};
      }
      const char vq = xml[v + 6];
      const size_t ve = xml.find(vq, v + 7);
      return xml.substr(0, v + 7) + value + xml.substr(ve);
    }
    return xml.substr(0, tag_end + 1) + "\n        <config key=\"" + key + "\" value=\"" + value +
           "\"/>" + xml.substr(tag_end + 1);
  }
  std::string list;
  for (const auto& s : seen) list += (list.empty() ? "" : ", ") + s;
  return Error{
      "the model has no plugin instance '" + instance + "'" +
      (list.empty() ? std::string(" (it has no named instances)") : "; instances: " + list)};
}

}  // namespace recruit::sim
