#include "attach/attach.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "attach/holding_load.h"
#include "attach/report.h"
#include "attach/spec_edit.h"
#include "attach/starter_task.h"
#include "common/atomic_file.h"
#include "plugin/sma_plugin.h"
#include "plugin/tendon_range.h"

namespace recruit::attach {
namespace {

namespace fs = std::filesystem;

bool SamePath(const std::string& a, const std::string& b) {
  std::error_code ec;
  return fs::weakly_canonical(fs::absolute(a, ec), ec) ==
         fs::weakly_canonical(fs::absolute(b, ec), ec);
}

Status CheckPaths(const AttachOptions& o) {
  if (o.model.empty()) return Error{"no model given"};
  std::error_code ec;
  if (!fs::is_regular_file(o.model, ec))
    return Error{"cannot open model '" + o.model + "': no such file"};  // bad input (CodeOf)
  if (o.muscles.empty()) return Error{"no muscle given (--muscles NAME[,NAME...] or all)"};
  if (!o.size_only && o.output.empty()) return Error{"no output model given (-o OUT.xml)"};
  for (const std::string* p : {&o.output, &o.task, &o.report}) {
    if (!p->empty() && SamePath(*p, o.model)) {
      return Error{"output '" + *p + "' is the input model: refusing to overwrite an input"};
    }
  }
  return Status::Ok();
}

Result<std::vector<std::string>> SelectActuators(const mjSpec* spec, const AttachOptions& o) {
  std::vector<std::string> names;
  if (o.muscles.size() == 1 && o.muscles[0] == "all") {
    names = TendonMuscleNames(spec);
    if (names.empty()) return Error{"'" + o.model + "' has no muscle on a tendon (--muscles all)"};
    return names;
  }
  for (const std::string& n : o.muscles) {
    auto a = FindTendonActuator(spec, n);
    if (!a.ok()) return Error{"'" + o.model + "': " + a.error(), a.code()};
    if (std::find(names.begin(), names.end(), n) == names.end()) names.push_back(n);
  }
  return names;
}

// The replaced actuator's peak force: MuJoCo's muscle F0 (gainprm[2], or scale / acc0 when it is
// automatic), or the user's.
Result<double> PeakForce(const mjModel* m, int a, const std::string& name, double force,
                         std::string* source) {
  if (std::isfinite(force)) {
    *source = "--force";
    if (force <= 0) return Error{"--force " + std::to_string(force) + " is invalid: must be > 0 N"};
    return force;
  }
  if (m->actuator_gaintype[a] != mjGAIN_MUSCLE) {
    return Error{"actuator '" + name +
                 "' is not a muscle: give the bundle's peak force with --force N"};
  }
  *source = "muscle F0";
  const double* prm = m->actuator_gainprm + mjNGAIN * a;
  if (prm[2] > 0) return prm[2];
  if (m->actuator_acc0[a] > 0) return prm[3] / m->actuator_acc0[a];
  return Error{"actuator '" + name + "': MuJoCo gives no F0 (acc0 = 0): give --force N"};
}

// The first free joint on the way from joint j's body to the world ("" when none): a limb that
// hangs from one falls, or is pushed about, instead of moving on its joints.
std::string FreeJointAbove(const mjModel* m, int j) {
  for (int b = m->jnt_bodyid[j]; b > 0; b = m->body_parentid[b]) {
    for (int k = m->body_jntadr[b]; k >= 0 && k < m->body_jntadr[b] + m->body_jntnum[b]; ++k) {
      if (m->jnt_type[k] == mjJNT_FREE) {
        const char* n = mj_id2name(m, mjOBJ_JOINT, k);
        return n != nullptr ? n : "#" + std::to_string(k);
      }
    }
  }
  return "";
}

// What sizing takes of a probed bundle.
SizingInput InputOf(const BundleReport& b) {
  return {b.name,       b.peak_force,     b.length_max - b.length_min, b.length_min, b.length_max,
          b.ref_length, b.holding.force()};
}

// At qpos0: each bundle's moment arm about the joints it crosses, and the joints the bundles move
// (not locked) with their inertia and damping, the replaced actuators' own left out.
void ProbeArms(const mjModel* m, mjData* d, const std::vector<std::string>& names,
               const std::vector<std::string>& locked, std::vector<BundleReport>& bundles,
               std::vector<DampedJoint>* joints) {
  mju_copy(d->qpos, m->qpos0, m->nq);
  mj_fwdPosition(m, d);
  std::vector<int> replaced;
  for (const std::string& n : names) replaced.push_back(mj_name2id(m, mjOBJ_ACTUATOR, n.c_str()));
  joints->clear();
  for (BundleReport& b : bundles) {
    for (JointUse& u : b.joints) {
      const int j = mj_name2id(m, mjOBJ_JOINT, u.joint.c_str());
      if (j < 0) continue;
      u.arm = sma::TendonArm(m, d, b.tendon_id, m->jnt_dofadr[j]);
      const bool seen = std::any_of(joints->begin(), joints->end(),
                                    [&](const DampedJoint& x) { return x.joint == u.joint; });
      const bool held = std::find(locked.begin(), locked.end(), u.joint) != locked.end();
      if (!seen && !held) joints->push_back(ProbeJoint(m, d, j, replaced));
    }
  }
}

// Every bundle's damper (BundleDesign::damper) for the joints in `joints` (attach/damper.h).
Status DesignBundleDampers(std::vector<BundleReport>& bundles, std::vector<DampedJoint>& joints,
                           const SizingLimits& limits) {
  std::vector<DampedBundle> in;
  for (const BundleReport& b : bundles) {
    const SizingInput s = InputOf(b);
    DampedBundle db;
    db.stiffness = RestStiffness(b.design, s, RestTension(s, limits));
    db.arms.assign(joints.size(), 0.0);
    for (std::size_t j = 0; j < joints.size(); ++j) {
      for (const JointUse& u : b.joints) {
        if (u.joint == joints[j].joint) db.arms[j] = u.arm;
      }
    }
    in.push_back(std::move(db));
  }
  auto c = DesignDampers(joints, in, limits.damping_ratio);
  if (!c.ok()) return Error{"dampers: " + c.error(), c.code()};
  for (std::size_t i = 0; i < bundles.size(); ++i) {
    bundles[i].design.damper = (*c)[i] / (bundles[i].design.gear * bundles[i].design.gear);
  }
  return Status::Ok();
}

// Probes the original model (compiled without lengthrange computation, which a bundle does not
// need) for each bundle's force and tendon range.
// The bundles' tendons, joints and loads, on a copy of the model with the locked joints held.
Result<std::vector<BundleReport>> Probe(const mjSpec* spec, const std::vector<std::string>& names,
                                        const AttachOptions& o, std::vector<JointLock>* locks,
                                        std::vector<DampedJoint>* joints) {
  auto copy = CopySpec(spec);
  if (!copy.ok()) return Error{copy.error(), copy.code()};
  (*copy)->compiler.LRopt.mode = mjLRMODE_NONE;
  auto m = CompileSpec(copy->get());
  if (!m.ok()) return Error{"'" + o.model + "' does not compile: " + m.error(), m.code()};
  if (!o.lock.empty()) {
    auto found = FindLocks(m->get(), o.lock, o.model);
    if (!found.ok()) return found.failure();
    *locks = std::move(found).value();
    Status held = AddLockEqualities(copy->get(), *locks);
    if (!held.ok()) return held.failure();
    m = CompileSpec(copy->get());
    if (!m.ok()) return Error{"'" + o.model + "' with the locks does not compile: " + m.error()};
  }
  DataPtr d(mj_makeData(m->get()));
  if (!d) return Error{"cannot make data for '" + o.model + "'"};
  std::vector<BundleReport> out;
  for (const std::string& name : names) {
    const mjModel* mm = m->get();
    const int a = mj_name2id(mm, mjOBJ_ACTUATOR, name.c_str());
    BundleReport b;
    b.name = name;
    b.tendon_id = mm->actuator_trnid[2 * a];
    const char* tn = mj_id2name(mm, mjOBJ_TENDON, b.tendon_id);
    b.tendon = tn != nullptr ? tn : "#" + std::to_string(b.tendon_id);
    b.replaced = mm->actuator_gaintype[a] == mjGAIN_MUSCLE ? "muscle" : "general";
    auto f = PeakForce(mm, a, name, o.force, &b.force_source);
    if (!f.ok()) return Error{"'" + o.model + "': " + f.error(), f.code()};
    b.peak_force = *f;
    const sma::TendonRange r = sma::SampleTendonRange(mm, d.get(), b.tendon_id);
    for (std::size_t i = 0; i < r.joints.size(); ++i) {
      const int j = r.joints[i];
      const char* jn = mj_id2name(mm, mjOBJ_JOINT, j);
      b.joints.push_back({jn != nullptr ? jn : "#" + std::to_string(j),
                          mm->jnt_type[j] == mjJNT_HINGE, mm->jnt_range[2 * j],
                          mm->jnt_range[2 * j + 1], r.usable_lo[i], r.usable_hi[i]});
    }
    for (const sma::TendonJump& jump : r.jumps) b.jumps.push_back(sma::JumpText(mm, jump));
    for (int j : r.joints) {
      if (b.free_base.empty()) b.free_base = FreeJointAbove(mm, j);
    }
    b.length_min = r.length_min;
    b.length_max = r.length_max;
    b.holding = SampleHoldingLoad(mm, d.get(), b.tendon_id, r.joints, r.usable_lo, r.usable_hi);
    mju_copy(d->qpos, mm->qpos0, mm->nq);
    mj_kinematics(mm, d.get());
    mj_comPos(mm, d.get());
    mj_tendon(mm, d.get());
    b.ref_length = d->ten_length[b.tendon_id];
    out.push_back(std::move(b));
  }
  ProbeArms(m->get(), d.get(), names, o.lock, out, joints);
  return out;
}

Status Size(std::vector<BundleReport>& bundles, const SizingLimits& limits) {
  for (BundleReport& b : bundles) {
    auto design = SizeBundle(InputOf(b), limits);
    if (!design.ok()) return Error{design.error(), design.code()};
    b.design = std::move(design).value();
  }
  return Status::Ok();
}

// Writes `text` to `path` atomically; `check` (may be null) runs on the temporary file first.
Status WriteChecked(const std::string& path, const std::string& text,
                    Status (*check)(const std::string& temp)) {
  AtomicFile file(path);
  if (!file.ok()) return Error{file.error(), file.code()};
  file.stream() << text;
  file.stream().flush();
  if (!file.stream()) return Error{"cannot write '" + path + "'", ErrorCode::kIo};
  if (check != nullptr) {
    Status ok = check(file.temp_path());
    if (!ok.ok()) return ok;
  }
  return file.Commit();
}

// The written model must load with MuJoCo's own loader from its folder (assets, plugin).
Status LoadsFromFile(const std::string& temp) {
  char error[1000] = "";
  ModelPtr m(mj_loadXML(temp.c_str(), nullptr, error, sizeof error));
  if (!m) return Error{std::string("the written model does not load: ") + error};
  return Status::Ok();
}

}  // namespace

Result<AttachReport> Attach(const AttachOptions& o) {
  Status paths = CheckPaths(o);
  if (!paths.ok()) return Error{paths.error(), paths.code()};
  sma::RegisterSmaPlugin();
  auto spec = ParseSpec(o.model);
  if (!spec.ok()) return Error{spec.error(), spec.code()};
  auto names = SelectActuators(spec->get(), o);
  if (!names.ok()) return Error{names.error(), names.code()};
  std::vector<JointLock> locks;
  std::vector<DampedJoint> joints;
  auto bundles = Probe(spec->get(), *names, o, &locks, &joints);
  if (!bundles.ok()) return Error{bundles.error(), bundles.code()};
  Status sized = Size(*bundles, o.limits);
  if (!sized.ok()) return Error{sized.error(), sized.code()};
  Status damped = DesignBundleDampers(*bundles, joints, o.limits);
  if (!damped.ok()) return Error{damped.error(), damped.code()};

  AttachReport report;
  report.model = o.model;
  report.output = o.size_only ? "" : o.output;
  report.bundles = std::move(bundles).value();
  report.locks = locks;
  report.damped_joints = std::move(joints);
  for (const BundleReport& b : report.bundles) {
    for (const std::string& j : b.jumps) {
      report.warnings.push_back("'" + b.name + "': tendon path jumps at " + j +
                                ": sized on the usable range");
    }
    for (const std::string& n : b.design.notes) report.warnings.push_back("'" + b.name + "': " + n);
    if (!b.free_base.empty()) {
      report.warnings.push_back(
          "'" + b.name + "': the joints it moves hang from the free joint '" + b.free_base +
          "': the limb's base is not held, so it falls or is pushed about instead of moving on "
          "those joints (the starter task assumes a fixed base): fix the base (remove its free "
          "joint, or weld the body) before driving it");
    }
  }
  if (!o.size_only) {
    mjSpec* s = spec->get();
    for (BundleReport& b : report.bundles) {
      b.instance = UniqueName(s, mjOBJ_PLUGIN, b.name + "_units");
      b.sensor = UniqueName(s, mjOBJ_SENSOR, b.name + "_truth");
      Status ok = ReplaceWithBundle(s, {b.name, b.instance, b.sensor, b.design.gear,
                                        b.design.damper, b.design.ConfigPairs()});
      if (!ok.ok()) return Error{ok.error(), ok.code()};
    }
    RebaseAssetDirs(s, o.model, o.output);
    // Compiled before the locks: what the fit check says then is not the written model's (which
    // is compiled and checked at the end, warnings and all).
    auto fixes = [&] {
      QuietMujocoWarnings quiet;
      return CheckLengthRanges(s, o.lengthrange_from_joints);
    }();
    if (!fixes.ok()) return Error{"'" + o.model + "': " + fixes.error(), fixes.code()};
    report.lengthranges = std::move(fixes).value();
    if (!report.locks.empty()) {  // the kept muscles' ranges are the free limb's, not the locked
      auto frozen = FreezeLengthRanges(s);
      if (!frozen.ok()) return Error{"'" + o.model + "': " + frozen.error(), frozen.code()};
      report.lengthranges_unlocked = std::move(frozen).value();
    }
    Status locked = AddLockEqualities(s, report.locks);
    if (!locked.ok()) return locked.failure();
    auto compiled = CompileSpec(s);
    if (!compiled.ok())
      return Error{"the edited model does not compile: " + compiled.error(), compiled.code()};
    for (const BundleReport& b : report.bundles) {
      const int a = mj_name2id(compiled->get(), mjOBJ_ACTUATOR, b.name.c_str());
      if (a < 0 || (*compiled)->actuator_trnid[2 * a] != b.tendon_id) {
        return Error{"internal: bundle '" + b.name + "' is not on tendon '" + b.tendon + "'"};
      }
    }
    auto xml = SaveXmlString(s);
    if (!xml.ok()) return Error{xml.error(), xml.code()};
    report.changes = ChangeLines(report, s);
    if (!o.task.empty()) {
      for (const JointUse& j : DrivenJoints(report, o.lock)) {
        report.holdable.push_back({j.joint, j.usable_lo, j.usable_hi});
      }
      FindHoldableRanges(compiled->get(), report.bundles, kStarterCoContraction, report.holdable);
      auto task = StarterTask(report, o.lock, o.task);
      if (!task.ok()) return Error{task.error(), task.code()};
      report.task = o.task;
      Status w = WriteChecked(o.output, *xml, &LoadsFromFile);
      if (!w.ok()) return Error{w.error(), w.code()};
      Status t = WriteFileAtomically(o.task, task->dump(2) + "\n");
      if (!t.ok()) return Error{t.error(), t.code()};
    } else {
      Status w = WriteChecked(o.output, *xml, &LoadsFromFile);
      if (!w.ok()) return Error{w.error(), w.code()};
    }
  }
  if (!o.report.empty()) {
    Status r = WriteFileAtomically(o.report, ReportJson(report).dump(2) + "\n");
    if (!r.ok()) return Error{r.error(), r.code()};
  }
  return report;
}

}  // namespace recruit::attach
