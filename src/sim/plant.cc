#include "sim/plant.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/compiled_model_cache.h"
#include "plugin/joint_damping.h"

namespace recruit::sim {
namespace {

// The elements of `type` in `spec`, collected first so that a caller may delete them.
std::vector<mjsElement*> Elements(mjSpec* spec, mjtObj type) {
  std::vector<mjsElement*> all;
  for (mjsElement* e = mjs_firstElement(spec, type); e != nullptr; e = mjs_nextElement(spec, e)) {
    all.push_back(e);
  }
  return all;
}

// True if a custom tuple of `spec` lists an object of `type`: deleting an object drops the
// tuples that name it. (The wheel's C++ library is not this one; a vector of ints has the same
// layout in both.)
bool TupleLists(mjSpec* spec, mjtObj type) {
  for (mjsElement* e : Elements(spec, mjOBJ_TUPLE)) {
    for (int t : *mjs_asTuple(e)->objtype) {
      if (t == type) return true;
    }
  }
  return false;
}

// True if a sensor (a frame sensor on a camera, a camera projection) or a custom tuple of `spec`
// names an object of `type`: that object must stay, for the model to compile (a sensor) or to
// keep its tuple.
bool SomethingNames(mjSpec* spec, mjtObj type) {
  for (mjsElement* e : Elements(spec, mjOBJ_SENSOR)) {
    const mjsSensor* s = mjs_asSensor(e);
    if (s->objtype == type || s->reftype == type) return true;
  }
  return TupleLists(spec, type);
}

// Every name another element refers to, whatever its type: tendon wraps and their side sites,
// contact pairs, sensors, actuator transmissions, equality constraints (custom tuples: see
// TupleLists).
std::set<std::string> NamesReferredTo(mjSpec* spec) {
  std::set<std::string> names;
  // Through mjs_getString: MuJoCo's wheel is built with another C++ library, whose strings
  // this one cannot read.
  auto add = [&names](const mjString* s) {
    const char* c = s != nullptr ? mjs_getString(s) : nullptr;
    if (c != nullptr && *c != 0) names.insert(c);
  };
  for (mjsElement* e : Elements(spec, mjOBJ_TENDON)) {
    const mjsTendon* t = mjs_asTendon(e);
    for (int i = 0; i < mjs_getWrapNum(t); ++i) {
      const mjsWrap* w = mjs_getWrap(t, i);
      if (mjsElement* target = mjs_getWrapTarget(w)) add(mjs_getName(target));
      if (mjsSite* side = mjs_getWrapSideSite(w)) add(mjs_getName(side->element));
    }
  }
  for (mjsElement* e : Elements(spec, mjOBJ_PAIR)) {
    add(mjs_asPair(e)->geomname1);
    add(mjs_asPair(e)->geomname2);
  }
  for (mjsElement* e : Elements(spec, mjOBJ_SENSOR)) {
    add(mjs_asSensor(e)->objname);
    add(mjs_asSensor(e)->refname);
  }
  for (mjsElement* e : Elements(spec, mjOBJ_ACTUATOR)) {
    const mjsActuator* a = mjs_asActuator(e);
    add(a->target);
    add(a->refsite);
    add(a->slidersite);
  }
  for (mjsElement* e : Elements(spec, mjOBJ_EQUALITY)) {
    add(mjs_asEquality(e)->name1);
    add(mjs_asEquality(e)->name2);
  }
  return names;
}

// The world's geoms that no contact can reach and the sites, wherever they are, that nothing
// names: MuJoCo places each at every step (3 of the arm's 16 frames, ~1 % of its step), for
// renders only. A world geom has no mass that moves and a site none at all, so the dynamics are
// the same to the bit (test PlantSkipsStagesTheModelHasNothingForAndStepsTheSame).
void LeaveOutStaticDecor(mjSpec* spec) {
  const std::set<std::string> named = NamesReferredTo(spec);
  auto unnamed = [&named](mjsElement* e) {
    return named.count(mjs_getString(mjs_getName(e))) == 0;
  };
  const bool no_contact = (spec->option.disableflags & mjDSBL_CONTACT) != 0;
  const mjsBody* world = mjs_findBody(spec, "world");
  std::vector<mjsElement*> decor;
  for (mjsElement* e : Elements(spec, mjOBJ_GEOM)) {
    const mjsGeom* g = mjs_asGeom(e);
    const bool collides = !no_contact && (g->contype != 0 || g->conaffinity != 0);
    if (!collides && mjs_getParent(e) == world && unnamed(e)) decor.push_back(e);
  }
  for (mjsElement* e : Elements(spec, mjOBJ_SITE)) {
    if (unnamed(e)) decor.push_back(e);
  }
  // A tuple's elements are kept by type (TupleLists); sensors are among the names above.
  const bool geoms_listed = TupleLists(spec, mjOBJ_GEOM),
             sites_listed = TupleLists(spec, mjOBJ_SITE);
  for (mjsElement* e : decor) {
    const bool listed = e->elemtype == mjOBJ_GEOM ? geoms_listed : sites_listed;
    if (!listed) mjs_delete(spec, e);
  }
}

// Builtin textures at 1 x 1 pixel; no camera and no light, unless something names one.
void LeaveOutWhatOnlyRendersRead(mjSpec* spec) {
  for (mjsElement* e : Elements(spec, mjOBJ_TEXTURE)) {
    mjsTexture* t = mjs_asTexture(e);
    if (t->builtin != mjBUILTIN_NONE) t->width = t->height = 1;
  }
  for (mjtObj type : {mjOBJ_CAMERA, mjOBJ_LIGHT}) {
    if (SomethingNames(spec, type)) continue;
    for (mjsElement* e : Elements(spec, type)) mjs_delete(spec, e);
  }
  LeaveOutStaticDecor(spec);
}

// The model at `path`; without `drawn` (a run that draws nothing), every builtin texture (a
// sky, a floor grid) compiled at 1 x 1 pixel, and no camera or light. Texture pixels only colour
// renders, yet generating them (and the plugin hashing them with the rest of the model) was ~4 %
// of a 60 s arm run's instructions (34 of 792 M); MuJoCo places every camera and light at each
// step (~1 %), which only a renderer reads.
mjModel* CompilePlantModel(const std::string& path, bool drawn, char* error, int error_size) {
  mjSpec* spec = mj_parseXML(path.c_str(), nullptr, error, error_size);
  if (spec == nullptr) return nullptr;
  // The compiler's thread pool only speeds up mesh processing; without meshes, starting and
  // joining its threads is all it does.
  if (mjs_firstElement(spec, mjOBJ_MESH) == nullptr) spec->compiler.usethread = false;
  if (!drawn) LeaveOutWhatOnlyRendersRead(spec);
  mjModel* m = mj_compile(spec, nullptr);
  if (m == nullptr) std::snprintf(error, error_size, "%s", mjs_getError(spec));
  mj_deleteSpec(spec);
  // A model that fails to compile without what only renders read (a reference this file does
  // not know of) is loaded whole: its error, if any, is then the model's own.
  if (m == nullptr && !drawn) return CompilePlantModel(path, true, error, error_size);
  return m;
}

// CompilePlantModel's model, from the cache of compiled models when the file reads no other
// (common/compiled_model_cache.h): a short run's parse, spec edits and compile were ~6 of its
// 16.5 M instructions.
mjModel* LoadPlantModel(const std::string& path, bool drawn, char* error, int error_size) {
  return compiled_cache::Load(
      path, drawn ? "plant drawn" : "plant undrawn",
      [&](char* e, int n) { return CompilePlantModel(path, drawn, e, n); }, error, error_size);
}

// True if any joint or tendon has dry friction (a frictionloss constraint row).
bool HasFrictionLoss(const mjModel* m) {
  for (int i = 0; i < m->nv; ++i) {
    if (m->dof_frictionloss[i] > 0) return true;
  }
  for (int i = 0; i < m->ntendon; ++i) {
    if (m->tendon_frictionloss[i] > 0) return true;
  }
  return false;
}

// True if a contact can be made: contacts are on and a pair is listed, a flex exists, or some
// geom's contype meets some geom's conaffinity (MuJoCo's filter, at its widest).
bool CanContact(const mjModel* m) {
  if (m->opt.disableflags & mjDSBL_CONTACT) return false;
  int contype = 0, conaffinity = 0;
  for (int i = 0; i < m->ngeom; ++i) {
    contype |= m->geom_contype[i];
    conaffinity |= m->geom_conaffinity[i];
  }
  return m->npair > 0 || m->nflex > 0 || (contype & conaffinity) != 0;
}

// The limited joints whose limits are the only constraint rows MuJoCo can make in `m`, or
// nullopt if another kind can be made (contacts, equalities, dry friction, tendon or ball
// limits) or the integrator evaluates more than the step's starting state (RK4). A step that
// starts with all of them clear of their limits then makes no row; sleeping and the discrete
// integrator are left alone.
std::optional<std::vector<int>> LimitsThatAloneConstrain(const mjModel* m) {
  const int off = m->opt.disableflags;
  const bool one_pass = m->opt.integrator == mjINT_EULER || m->opt.integrator == mjINT_IMPLICIT ||
                        m->opt.integrator == mjINT_IMPLICITFAST;
  if ((off & mjDSBL_CONSTRAINT) || !one_pass || (m->opt.enableflags & mjENBL_SLEEP) ||
      CanContact(m) || (!(off & mjDSBL_EQUALITY) && m->neq > 0) ||
      (!(off & mjDSBL_FRICTIONLOSS) && HasFrictionLoss(m))) {
    return std::nullopt;
  }
  std::vector<int> joints;
  if (off & mjDSBL_LIMIT) return joints;
  for (int i = 0; i < m->ntendon; ++i) {
    if (m->tendon_limited[i]) return std::nullopt;
  }
  for (int j = 0; j < m->njnt; ++j) {
    if (!m->jnt_limited[j]) continue;
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) return std::nullopt;
    joints.push_back(j);
  }
  return joints;
}

// True if a joint of `joints` at `qpos` is at or past a limit (within its margin), by MuJoCo's
// own test (mj_instantiateLimit); a NaN counts as reached.
bool AnyLimitReached(const mjModel* m, const std::vector<int>& joints, const mjtNum* qpos) {
  for (int j : joints) {
    const mjtNum value = qpos[m->jnt_qposadr[j]];
    for (int side = -1; side <= 1; side += 2) {
      const mjtNum dist = side * (m->jnt_range[2 * j + (side + 1) / 2] - value);
      if (!(dist >= m->jnt_margin[j])) return true;
    }
  }
  return false;
}

// MuJoCo's constraint stage switched off (when `off`) until the end of the scope: the model's
// stage switches are restored as they were (plant.h says where the plant changes its model).
class DisableForOneCall {
 public:
  DisableForOneCall(mjModel* m, bool off) : m_(m), flags_(m->opt.disableflags) {
    if (off) m_->opt.disableflags |= mjDSBL_CONSTRAINT;
  }
  ~DisableForOneCall() { m_->opt.disableflags = flags_; }
  DisableForOneCall(const DisableForOneCall&) = delete;
  DisableForOneCall& operator=(const DisableForOneCall&) = delete;

 private:
  mjModel* m_;
  const int flags_;
};

}  // namespace

Result<std::unique_ptr<Plant>> Plant::Create(const Task& task, bool drawn) {
  const std::string where = task.source.empty() ? task.name : task.source;
  std::unique_ptr<Plant> p(new Plant());
  p->task_ = &task;
  char load_error[1000] = "";
  p->model_.reset(LoadPlantModel(task.model_path, drawn, load_error, sizeof load_error));
  if (!p->model_) {
    return Error{where + ".model: cannot load '" + task.model_path + "': " + load_error};
  }
  mjModel* m = p->model_.get();
  if (task.timestep > 0) m->opt.timestep = task.timestep;
  // The run reads each bundle through SmaHost and the joint from qpos, never sensordata: MuJoCo's
  // sensor stage (the plugin's ground-truth sums over every cohort, and the model's own sensors)
  // would be evaluated every step for nothing. Sensors never act on the dynamics.
  m->opt.disableflags |= mjDSBL_SENSOR;
  // Constraint kinds the model has none of: MuJoCo still visits them every step (~1 % of an arm
  // step). Disabling them changes nothing else: no such row would ever be made. Likewise island
  // discovery in a model of one kinematic tree, whose constraints all fall in one island (the
  // project's arm and bench give cmp-identical runs either way).
  if (!HasFrictionLoss(m)) m->opt.disableflags |= mjDSBL_FRICTIONLOSS;
  if (m->neq == 0) m->opt.disableflags |= mjDSBL_EQUALITY;
  if (m->ntree <= 1 && !(m->opt.enableflags & mjENBL_SLEEP)) {  // sleeping works on islands
    m->opt.disableflags |= mjDSBL_ISLAND;
  }
  // A bad state makes mj_step reset to qpos0 and go on from there: the gate holds only if
  // qpos0 is clear of the limits too.
  p->gate_ = LimitsThatAloneConstrain(m);
  if (p->gate_ && AnyLimitReached(m, *p->gate_, m->qpos0)) p->gate_.reset();
  auto host = sma::SmaHost::Create(m);
  if (!host.ok()) return Error{where + ".model: " + host.error(), host.code()};
  p->host_ = std::move(host).value();

  if (Status st = p->FindBundles(task, where); !st.ok()) return Error{st.error(), st.code()};
  if (Status st = p->FindJoints(task, where); !st.ok()) return Error{st.error(), st.code()};
  if (!task.joint.empty()) {
    const int joint = mj_name2id(m, mjOBJ_JOINT, task.joint.c_str());
    if (joint < 0) {
      return Error{where + ".joint: no joint '" + task.joint + "' in '" + task.model_path + "'"};
    }
    if (m->jnt_type[joint] != mjJNT_HINGE) {
      return Error{where + ".joint: '" + task.joint + "' must be a hinge"};
    }
    p->qadr_ = m->jnt_qposadr[joint];
    p->dadr_ = m->jnt_dofadr[joint];
  }
  for (size_t i = 0; i < task.pushes.size(); ++i) {
    const int id = mj_name2id(m, mjOBJ_BODY, task.pushes[i].body.c_str());
    if (id < 0) {
      return Error{where + ".pushes[" + std::to_string(i) + "].body: no body '" +
                   task.pushes[i].body + "' in '" + task.model_path + "'"};
    }
    p->push_body_.push_back(id);
  }
  for (size_t i = 0; i < task.payloads.size(); ++i) {
    const int id = mj_name2id(m, mjOBJ_BODY, task.payloads[i].body.c_str());
    if (id <= 0) {
      return Error{where + ".payloads[" + std::to_string(i) + "].body: no body '" +
                   task.payloads[i].body + "' in '" + task.model_path + "'"};
    }
    p->payload_body_.push_back(id);
  }
  p->body_mass0_.assign(m->body_mass, m->body_mass + m->nbody);
  p->body_inertia0_.assign(m->body_inertia, m->body_inertia + 3 * m->nbody);
  p->data_.reset(mj_makeData(m));
  if (!p->joints_.empty()) p->scratch_.reset(mj_makeData(m));
  p->telemetry_.resize(p->bundles_.size());
  p->ForgetTelemetry();
  return p;
}

Status Plant::FindBundles(const Task& task, const std::string& where) {
  std::string have;
  for (int i = 0; i < host_->num_bundles(); ++i) have += (i ? ", " : "") + host_->bundle_name(i);
  auto find = [&](const std::string& name, const std::string& field) -> Status {
    const int b = host_->BundleIndex(name);
    if (b < 0) {
      return Error{where + "." + field + ": '" + name + "' is not an SMA bundle of '" +
                   task.model_path + "'; bundles: " + (have.empty() ? "none" : have)};
    }
    bundles_.push_back(b);
    return Status::Ok();
  };
  if (!task.auto_loop) {
    for (const std::string* name : {&task.agonist, &task.antagonist}) {
      if (name->empty()) continue;
      if (Status st = find(*name, name == &task.agonist ? "agonist" : "antagonist"); !st.ok()) {
        return st;
      }
    }
    return Status::Ok();
  }
  if (task.bundles.empty()) {  // every bundle of the model
    for (int b = 0; b < host_->num_bundles(); ++b) bundles_.push_back(b);
    if (bundles_.empty())
      return Error{where + ".model: '" + task.model_path + "' has no SMA bundle"};
    return Status::Ok();
  }
  for (size_t i = 0; i < task.bundles.size(); ++i) {
    if (Status st = find(task.bundles[i], "bundles[" + std::to_string(i) + "]"); !st.ok()) {
      return st;
    }
  }
  return Status::Ok();
}

Status Plant::FindJoints(const Task& task, const std::string& where) {
  const mjModel* m = model_.get();
  auto hinge = [&](const std::string& name, const std::string& field) -> Result<int> {
    const int joint = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    if (joint < 0) {
      return Error{where + "." + field + ": no joint '" + name + "' in '" + task.model_path + "'"};
    }
    if (m->jnt_type[joint] != mjJNT_HINGE) {
      return Error{where + "." + field + ": '" + name + "' must be a hinge"};
    }
    return joint;
  };
  if (!task.joint.empty()) {
    auto joint = hinge(task.joint, task.auto_loop ? "joints[0].joint" : "joint");
    if (!joint.ok()) return Error{joint.error(), joint.code()};
    qadr_ = m->jnt_qposadr[*joint];
    dadr_ = m->jnt_dofadr[*joint];
  }
  if (!task.auto_loop) return Status::Ok();
  for (size_t j = 0; j < task.joints.size(); ++j) {
    auto joint = hinge(task.joints[j].joint, "joints[" + std::to_string(j) + "].joint");
    if (!joint.ok()) return Error{joint.error(), joint.code()};
    joints_.push_back(*joint);
  }
  return Status::Ok();
}

Eigen::MatrixXd Plant::MomentArms() const { return MomentArmsOf(data_.get()); }

void Plant::PoseTransmission(const Eigen::VectorXd& q) const {
  // The stages the tendons and actuator moments need, not collision or the mass matrix.
  const mjModel* m = model_.get();
  mjData* s = scratch_.get();
  PoseScratch(q);
  mj_kinematics(m, s);
  mj_comPos(m, s);
  mj_tendon(m, s);
  mj_transmission(m, s);
}

Eigen::MatrixXd Plant::MomentArmsAt(const Eigen::VectorXd& q) const {
  PoseTransmission(q);
  return MomentArmsOf(scratch_.get());
}

Eigen::VectorXd Plant::UnitLengthsAt(const Eigen::VectorXd& q) const {
  PoseTransmission(q);
  Eigen::VectorXd lengths(num_bundles());
  for (int i = 0; i < num_bundles(); ++i) {
    lengths[i] = host_->UnitLength(scratch_.get(), bundles_[i]);
  }
  return lengths;
}

Eigen::MatrixXd Plant::MomentArmsOf(const mjData* d) const {
  const mjModel* m = model_.get();
  Eigen::MatrixXd arms = Eigen::MatrixXd::Zero(num_joints(), num_bundles());
  for (int i = 0; i < num_bundles(); ++i) {
    const int out = m->actuator_outadr[host_->actuator_id(bundles_[i])];
    for (int k = 0; k < d->moment_rownnz[out]; ++k) {
      const int adr = d->moment_rowadr[out] + k;
      for (int j = 0; j < num_joints(); ++j) {
        if (d->moment_colind[adr] == m->jnt_dofadr[joints_[j]]) {
          arms(j, i) = -d->actuator_moment[adr];
        }
      }
    }
  }
  return arms;
}

void Plant::PoseScratch(const Eigen::VectorXd& q) const {
  const mjModel* m = model_.get();
  mjData* s = scratch_.get();
  std::copy(data_->qpos, data_->qpos + m->nq, s->qpos);
  for (int j = 0; j < num_joints(); ++j) s->qpos[m->jnt_qposadr[joints_[j]]] = q[j];
  std::fill(s->qvel, s->qvel + m->nv, 0.0);
  std::fill(s->qacc, s->qacc + m->nv, 0.0);
  std::fill(s->qfrc_applied, s->qfrc_applied + m->nv, 0.0);
  std::fill(s->xfrc_applied, s->xfrc_applied + 6 * m->nbody, 0.0);
}

Eigen::VectorXd Plant::StaticTorque(const Eigen::VectorXd& q) const {
  mjModel* m = model_.get();
  PoseScratch(q);
  {
    // Without constraint rows: a limit the pose touches would otherwise take part of the load.
    DisableForOneCall off(m, true);
    mj_inverse(m, scratch_.get());
  }
  Eigen::VectorXd tau(num_joints());
  for (int j = 0; j < num_joints(); ++j) {
    tau[j] = scratch_->qfrc_inverse[m->jnt_dofadr[joints_[j]]];
  }
  return tau;
}

double Plant::JointInertia(int j, const Eigen::VectorXd& q) const {
  const mjModel* m = model_.get();
  PoseScratch(q);
  mj_fwdPosition(m, scratch_.get());
  std::vector<mjtNum> full(static_cast<size_t>(m->nv) * m->nv);
  mj_fullM(m, scratch_.get(), full.data());
  const int dof = m->jnt_dofadr[joints_[j]];
  return full[static_cast<size_t>(dof) * m->nv + dof];
}

double Plant::JointDamping(int j, const Eigen::VectorXd& q) const {
  PoseTransmission(q);
  return sma::JointDamping(model_.get(), scratch_.get(), model_->jnt_dofadr[joints_[j]]);
}

void Plant::Reset(std::uint64_t seed) {
  mjModel* m = model_.get();
  std::copy(body_mass0_.begin(), body_mass0_.end(), m->body_mass);
  std::copy(body_inertia0_.begin(), body_inertia0_.end(), m->body_inertia);
  payload_done_.assign(task_->payloads.size(), false);
  payloads_pending_ = task_->payloads.size();
  mj_resetData(m, data_.get());
  pushed_ = false;  // xfrc_applied zeroed
  ApplyPayloads();
  host_->Reset(data_.get(), seed);
  // TrackPeaks reads every bundle's telemetry after every step: each step keeps it from the
  // units' update (bit for bit the values a separate pass gives).
  for (int b : bundles_) host_->ObserveEachStep(data_.get(), b);
  mj_forward(m, data_.get());
  peak_temperature_.assign(bundles_.size(), -std::numeric_limits<double>::infinity());
  peak_stress_.assign(bundles_.size(), 0.0);
  TrackPeaks();
}

void Plant::Step() {
  // Tested here, not in the calls: most tasks have no payload change left and no push, and a
  // call that found nothing was ~20 instructions a step.
  if (payloads_pending_ > 0) ApplyPayloads();
  if (!task_->pushes.empty()) ApplyPushes();
  mjModel* m = model_.get();
  // Joint limits the only rows there can be, and none reached: MuJoCo's constraint stage would
  // make no row and leave qacc = qacc_smooth, as it does disabled. Visiting it anyway was 5 % of
  // an arm step (docs/benchmarks.md).
  const bool skip = gate_ && !AnyLimitReached(m, *gate_, data_->qpos);
  if (skip) ++skipped_;
  {
    DisableForOneCall off(m, skip);
    mj_step(m, data_.get());
  }
  TrackPeaks();
}

const sma::SmaBundle::Telemetry& Plant::ReadBundleTelemetry(int i) const {
  telemetry_[i] = host_->ReadTelemetry(data_.get(), bundles_[i]);
  telemetry_valid_[i] = true;
  return telemetry_[i];
}

void Plant::ApplyPayloads() {
  mjModel* m = model_.get();
  const double t = data_->time, h = m->opt.timestep;
  for (size_t i = 0; i < task_->payloads.size(); ++i) {
    if (payload_done_[i] || t + 0.5 * h < task_->payloads[i].time) continue;
    const int id = payload_body_[i];
    // Scale the inertia with the mass: the payload keeps its shape.
    const double ratio = task_->payloads[i].mass / m->body_mass[id];
    m->body_mass[id] = task_->payloads[i].mass;
    for (int k = 0; k < 3; ++k) m->body_inertia[3 * id + k] *= ratio;
    payload_done_[i] = true;
    --payloads_pending_;
  }
}

void Plant::ApplyPushes() {
  // Pushes act through xfrc_applied while active; several may share a body, so clear all first
  // and then add the active ones. With none active now or at the last step the pushed bodies'
  // entries are already 0 (only this writes them; mj_resetData zeroes them): nothing to do.
  // (Step calls it only for a task with pushes.)
  const double t = data_->time, h = model_->opt.timestep;
  auto active = [&](const Push& p) {
    return !(t + 0.5 * h < p.start || t + 0.5 * h >= p.start + p.duration);
  };
  const bool any = std::any_of(task_->pushes.begin(), task_->pushes.end(), active);
  if (!any && !pushed_) return;
  pushed_ = any;
  for (size_t i = 0; i < task_->pushes.size(); ++i) {
    for (int k = 0; k < 6; ++k) data_->xfrc_applied[6 * push_body_[i] + k] = 0;
  }
  for (size_t i = 0; i < task_->pushes.size(); ++i) {
    const Push& p = task_->pushes[i];
    if (!active(p)) continue;
    double* x = data_->xfrc_applied + 6 * push_body_[i];
    for (int k = 0; k < 3; ++k) {
      x[k] += p.force[k];
      x[3 + k] += p.torque[k];
    }
  }
}

void Plant::TrackPeaks() {
  for (int i = 0; i < num_bundles(); ++i) {
    // The units just changed. ReadBundleTelemetry's read, here without a call (once a step).
    const sma::SmaBundle::Telemetry& now = telemetry_[i] =
        host_->ReadTelemetry(data_.get(), bundles_[i]);
    telemetry_valid_[i] = true;
    peak_temperature_[i] = std::max(peak_temperature_[i], now.max_temperature);
    peak_stress_[i] = std::max(peak_stress_[i], now.max_wire_stress);
  }
}

Status Plant::Diverged() const {
  return Error{"the simulation diverged at t = " + std::to_string(data_->time) +
               " s (NaN in qpos); try a smaller timestep"};
}

}  // namespace recruit::sim
