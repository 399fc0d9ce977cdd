#include "attach/spec_edit.h"

#include <filesystem>

namespace recruit::attach {
namespace {

namespace fs = std::filesystem;

std::string Str(const mjString* s) {
  const char* c = s != nullptr ? mjs_getString(s) : nullptr;
  return c != nullptr ? c : "";
}

std::string ElementName(mjsElement* e) { return Str(mjs_getName(e)); }

bool HasAssetFiles(const mjSpec* spec) {
  for (mjtObj type : {mjOBJ_MESH, mjOBJ_TEXTURE, mjOBJ_HFIELD, mjOBJ_SKIN}) {
    if (mjs_firstElement(const_cast<mjSpec*>(spec), type) != nullptr) return true;
  }
  return false;
}

// dir (relative to the input model's folder, or absolute) as seen from the output's folder.
std::string Rebase(const std::string& dir, const fs::path& in_dir, const fs::path& out_dir) {
  const fs::path target = fs::path(dir).is_absolute() ? fs::path(dir) : in_dir / dir;
  std::error_code ec;
  fs::path rel = fs::relative(fs::weakly_canonical(target, ec), out_dir, ec);
  if (ec || rel.empty()) rel = fs::absolute(target, ec);
  std::string s = rel.lexically_normal().string();
  if (s.empty() || s == ".") s = "./";
  if (s.back() != '/') s += '/';
  return s;
}

// Sets a plugin instance's config. mjs_setPluginAttributes takes a std::map of MuJoCo's own C++
// library, which the wheel links statically (libc++): a map built here (libstdc++) would not be
// one. So MuJoCo's parser builds it, in a donor spec holding only the instance, and the donor's
// map is moved into `p` (mjs_setPluginAttributes moves from it).
Status SetConfig(mjsPlugin* p, const std::vector<std::pair<std::string, std::string>>& config) {
  std::string xml = "<mujoco><extension><plugin plugin=\"recruit.sma\"><instance name=\"donor\">";
  for (const auto& [key, value] : config) {
    xml += "<config key=\"" + key + "\" value=\"" + value + "\"/>";
  }
  xml += "</instance></plugin></extension></mujoco>";
  char error[500] = "";
  SpecPtr donor(mj_parseXMLString(xml.c_str(), nullptr, error, sizeof error));
  if (!donor) return Error{std::string("cannot build the plugin config: ") + error};
  mjsElement* e = mjs_firstElement(donor.get(), mjOBJ_PLUGIN);
  if (e == nullptr) return Error{"cannot build the plugin config: no instance parsed"};
  mjs_setPluginAttributes(p, const_cast<void*>(mjs_getPluginAttributes(mjs_asPlugin(e))));
  return Status::Ok();
}

}  // namespace

Result<SpecPtr> ParseSpec(const std::string& path) {
  char error[1000] = "";
  SpecPtr spec(mj_parseXML(path.c_str(), nullptr, error, sizeof error));
  if (!spec) return Error{"cannot parse '" + path + "': " + error};
  return spec;
}

Result<SpecPtr> CopySpec(const mjSpec* spec) {
  SpecPtr copy(mj_copySpec(spec));
  if (!copy) return Error{"cannot copy the model specification"};
  return copy;
}

Result<ModelPtr> CompileSpec(mjSpec* spec) {
  ModelPtr m(mj_compile(spec, nullptr));
  if (!m) return Error{mjs_getError(spec)};
  return m;
}

std::vector<std::string> ActuatorNames(const mjSpec* spec) {
  std::vector<std::string> names;
  mjSpec* s = const_cast<mjSpec*>(spec);
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_ACTUATOR); e; e = mjs_nextElement(s, e)) {
    names.push_back(ElementName(e));
  }
  return names;
}

std::vector<std::string> TendonMuscleNames(const mjSpec* spec) {
  std::vector<std::string> names;
  mjSpec* s = const_cast<mjSpec*>(spec);
  for (mjsElement* e = mjs_firstElement(s, mjOBJ_ACTUATOR); e; e = mjs_nextElement(s, e)) {
    const mjsActuator* a = mjs_asActuator(e);
    if (a->trntype == mjTRN_TENDON && a->gaintype == mjGAIN_MUSCLE) {
      names.push_back(ElementName(e));
    }
  }
  return names;
}

mjsActuator* FindActuator(const mjSpec* spec, const std::string& name) {
  mjsElement* e = mjs_findElement(const_cast<mjSpec*>(spec), mjOBJ_ACTUATOR, name.c_str());
  return e != nullptr ? mjs_asActuator(e) : nullptr;
}

Result<mjsActuator*> FindTendonActuator(const mjSpec* spec, const std::string& name) {
  mjsActuator* a = FindActuator(spec, name);
  if (a == nullptr) {
    std::string names;
    for (const std::string& n : ActuatorNames(spec)) {
      if (names.size() > 200) {
        names += ", ...";
        break;
      }
      names += (names.empty() ? "" : ", ") + n;
    }
    return Error{"actuator '" + name.substr(0, 60) +
                 "' does not exist: the model's actuators are " +
                 (names.empty() ? "(none)" : names)};
  }
  if (a->trntype != mjTRN_TENDON) {
    return Error{"actuator '" + name +
                 "' does not act on a tendon: a bundle pulls a tendon (only "
                 "actuators with tendon=\"...\" can be replaced)"};
  }
  return a;
}

std::string UniqueName(const mjSpec* spec, mjtObj type, const std::string& base) {
  mjSpec* s = const_cast<mjSpec*>(spec);
  std::string name = base;
  for (int i = 2; mjs_findElement(s, type, name.c_str()) != nullptr; ++i) {
    name = base + "_" + std::to_string(i);
  }
  return name;
}

// The bundles' class: a child of the main class reset to MuJoCo's built-in actuator defaults, so
// that a <default><muscle/> (or any dyntype/gain/bias) in the main class does not reach them.
static mjsDefault* BundleClass(mjSpec* spec) {
  if (mjsDefault* d = mjs_findDefault(spec, kBundleClass)) return d;
  mjsDefault* d = mjs_addDefault(spec, kBundleClass, mjs_getSpecDefault(spec));
  if (d != nullptr) mjs_defaultActuator(d->actuator);
  return d;
}

Status ReplaceWithBundle(mjSpec* spec, const BundleEdit& edit) {
  auto found = FindTendonActuator(spec, edit.actuator);
  if (!found.ok()) return Error{found.error(), found.code()};
  mjsActuator* a = *found;
  if (mjs_activatePlugin(spec, "recruit.sma") != 0) {
    return Error{"the recruit.sma plugin is not registered in this process"};
  }
  mjsPlugin* p = mjs_addPlugin(spec);
  mjs_setString(p->plugin_name, "recruit.sma");
  mjs_setString(p->name, edit.instance.c_str());
  p->active = true;
  Status configured = SetConfig(p, edit.config);
  if (!configured.ok()) return configured;

  mjsDefault* cls = BundleClass(spec);
  if (cls == nullptr) return Error{"cannot add the default class " + std::string(kBundleClass)};
  // Keep what the user set that a bundle keeps: name, tendon, group, forcerange.
  const std::string tendon = Str(a->target);
  const int group = a->group;
  const mjtLimited forcelimited = a->forcelimited;
  const double forcerange[2] = {a->forcerange[0], a->forcerange[1]};
  mjs_setDefault(a->element, cls);
  // Every field to the class's (MuJoCo's built-in) values, then the bundle's own.
  mjsElement* element = a->element;
  mjString* target = a->target;
  mjString* refsite = a->refsite;
  mjString* slidersite = a->slidersite;
  mjDoubleVec* userdata = a->userdata;
  mjString* info = a->info;
  mjsPlugin plugin = a->plugin;
  *a = *cls->actuator;
  a->element = element;
  a->target = target;
  a->refsite = refsite;
  a->slidersite = slidersite;
  a->userdata = userdata;
  a->info = info;
  a->plugin = plugin;
  mjs_setString(a->target, tendon.c_str());
  a->type = mjACTUATOR_GENERAL;
  a->trntype = mjTRN_TENDON;
  a->dyntype = mjDYN_NONE;
  a->gaintype = mjGAIN_FIXED;
  a->biastype = mjBIAS_NONE;
  a->actdim = 0;
  a->gear[0] = edit.gear;
  for (int i = 1; i < 6; ++i) a->gear[i] = 0;
  a->damping[0] = edit.damping;
  for (int i = 1; i <= mjNPOLY; ++i) a->damping[i] = 0;
  a->lengthrange[0] = a->lengthrange[1] = 0;  // a bundle needs none
  a->ctrllimited = mjLIMITED_TRUE;
  a->ctrlrange[0] = -1;
  a->ctrlrange[1] = 1;
  a->group = group;
  a->forcelimited = forcelimited;
  a->forcerange[0] = forcerange[0];
  a->forcerange[1] = forcerange[1];
  mjs_setString(a->plugin.plugin_name, "recruit.sma");
  mjs_setString(a->plugin.name, edit.instance.c_str());
  a->plugin.active = true;

  mjsSensor* s = mjs_addSensor(spec);
  if (s == nullptr) return Error{"cannot add sensor '" + edit.sensor + "'"};
  mjs_setName(s->element, edit.sensor.c_str());
  s->type = mjSENS_PLUGIN;
  mjs_setString(s->plugin.plugin_name, "recruit.sma");
  mjs_setString(s->plugin.name, edit.instance.c_str());
  s->plugin.active = true;
  return Status::Ok();
}

void RebaseAssetDirs(mjSpec* spec, const std::string& input_path, const std::string& output_path) {
  if (!HasAssetFiles(spec)) return;
  std::error_code ec;
  const fs::path in_dir = fs::absolute(fs::path(input_path), ec).parent_path();
  const fs::path out_dir =
      fs::weakly_canonical(fs::absolute(fs::path(output_path), ec), ec).parent_path();
  mjs_setString(spec->compiler.meshdir,
                Rebase(Str(spec->compiler.meshdir), in_dir, out_dir).c_str());
  mjs_setString(spec->compiler.texturedir,
                Rebase(Str(spec->compiler.texturedir), in_dir, out_dir).c_str());
  // The spec now compiles as the written file will load: from the output's folder.
  mjs_setString(spec->modelfiledir, (out_dir.string() + "/").c_str());
}

Result<std::string> SaveXmlString(const mjSpec* spec) {
  char error[1000] = "";
  std::string xml(1 << 16, '\0');
  int need = mj_saveXMLString(spec, xml.data(), static_cast<int>(xml.size()), error, sizeof error);
  if (need > 0) {
    xml.assign(need + 1, '\0');
    need = mj_saveXMLString(spec, xml.data(), static_cast<int>(xml.size()), error, sizeof error);
  }
  if (need != 0) return Error{std::string("cannot write the model: ") + error, ErrorCode::kIo};
  xml.resize(std::char_traits<char>::length(xml.c_str()));
  return xml;
}

}  // namespace recruit::attach
