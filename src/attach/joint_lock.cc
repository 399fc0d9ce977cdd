#include "attach/joint_lock.h"

#include <algorithm>

#include "attach/spec_edit.h"

namespace recruit::attach {

Result<std::vector<JointLock>> FindLocks(const mjModel* m, const std::vector<std::string>& names,
                                         const std::string& model) {
  std::vector<JointLock> out;
  for (const std::string& name : names) {
    const int j = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    if (j < 0) return Error{"--lock " + name + ": '" + model + "' has no joint of that name"};
    if (m->jnt_type[j] != mjJNT_HINGE && m->jnt_type[j] != mjJNT_SLIDE) {
      return Error{"--lock " + name + ": not a hinge or slide joint (allowed: hinge, slide)"};
    }
    JointLock lock{name, m->qpos0[m->jnt_qposadr[j]], m->qpos0[m->jnt_qposadr[j]]};
    if (m->jnt_limited[j]) {
      lock.value = std::clamp(lock.value, m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
    }
    if (std::none_of(out.begin(), out.end(), [&](const JointLock& l) { return l.joint == name; })) {
      out.push_back(lock);
    }
  }
  return out;
}

Status AddLockEqualities(mjSpec* spec, const std::vector<JointLock>& locks) {
  for (const JointLock& l : locks) {
    mjsEquality* eq = mjs_addEquality(spec, nullptr);
    if (eq == nullptr) return Error{"cannot add the equality locking joint '" + l.joint + "'"};
    const std::string name = UniqueName(spec, mjOBJ_EQUALITY, "lock_" + l.joint);
    mjs_setName(eq->element, name.c_str());
    eq->type = mjEQ_JOINT;
    eq->objtype = mjOBJ_JOINT;
    mjs_setString(eq->name1, l.joint.c_str());
    std::fill(std::begin(eq->data), std::end(eq->data), 0.0);
    eq->data[0] = l.value - l.ref;  // joint1 only: q1 - q1_ref = data[0]
    eq->active = 1;
  }
  return Status::Ok();
}

}  // namespace recruit::attach
