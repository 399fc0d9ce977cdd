#include "attach/lengthrange.h"

#include <cstdlib>
#include <cstring>

#include "plugin/tendon_range.h"

namespace recruit::attach {
namespace {

// The actuator index MuJoCo names in a lengthrange failure, or -1.
int FailingActuator(const std::string& error) {
  static const char kText[] = "Lengthrange computation did not converge in actuator ";
  const std::size_t at = error.find(kText);
  if (at == std::string::npos) return -1;
  return std::atoi(error.c_str() + at + std::strlen(kText));
}

// The actuator's length range over the usable joint ranges of its tendon, on a model compiled
// without lengthrange computation.
Result<LengthRangeFix> FromJoints(const mjModel* m, int a, const std::string& name) {
  if (m->actuator_trntype[a] != mjTRN_TENDON) {
    return Error{"actuator '" + name +
                 "' fails MuJoCo's lengthrange computation and acts on no tendon: give it a "
                 "lengthrange=\"lo hi\" in the model"};
  }
  DataPtr d(mj_makeData(m));
  if (!d) return Error{"cannot make data for the lengthrange of '" + name + "'"};
  const sma::TendonRange r = sma::SampleTendonRange(m, d.get(), m->actuator_trnid[2 * a]);
  const double gear = m->actuator_gear[6 * a];
  LengthRangeFix fix{name, gear * r.length_min, gear * r.length_max};
  if (fix.lo > fix.hi) std::swap(fix.lo, fix.hi);
  if (!(fix.hi > fix.lo)) {
    return Error{"actuator '" + name +
                 "': its tendon does not move over the joint ranges, so no "
                 "lengthrange can be taken from them"};
  }
  return fix;
}

}  // namespace

Result<std::vector<LengthRangeFix>> CheckLengthRanges(mjSpec* spec, bool apply) {
  const std::vector<std::string> names = ActuatorNames(spec);
  std::vector<LengthRangeFix> fixes;
  ModelPtr plain;  // compiled without lengthrange computation, for the joint sampling
  while (true) {
    auto trial = CopySpec(spec);
    if (!trial.ok()) return Error{trial.error(), trial.code()};
    for (const LengthRangeFix& f : fixes) {
      mjsActuator* a = FindActuator(trial->get(), f.actuator);
      a->lengthrange[0] = f.lo;
      a->lengthrange[1] = f.hi;
    }
    auto m = CompileSpec(trial->get());
    if (m.ok()) break;
    const int k = FailingActuator(m.error());
    if (k < 0 || k >= static_cast<int>(names.size()) || fixes.size() >= names.size()) {
      return Error{m.error(), m.code()};
    }
    if (!plain) {
      auto copy = CopySpec(spec);
      if (!copy.ok()) return Error{copy.error(), copy.code()};
      (*copy)->compiler.LRopt.mode = mjLRMODE_NONE;
      auto p = CompileSpec(copy->get());
      if (!p.ok()) return Error{p.error(), p.code()};
      plain = std::move(p).value();
    }
    auto fix = FromJoints(plain.get(), k, names[k]);
    if (!fix.ok()) return Error{fix.error(), fix.code()};
    fixes.push_back(*fix);
  }
  if (fixes.empty()) return fixes;
  if (!apply) {
    std::string list;
    for (const LengthRangeFix& f : fixes) list += (list.empty() ? "" : ", ") + f.actuator;
    return Error{"muscle(s) " + list +
                 " (not replaced) fail MuJoCo's lengthrange computation (\"did not converge\"), "
                 "so the model does not compile: rerun with --lengthrange-from-joints to set "
                 "their lengthrange from the joint ranges, or give them lengthrange=\"lo hi\""};
  }
  for (const LengthRangeFix& f : fixes) {
    mjsActuator* a = FindActuator(spec, f.actuator);
    a->lengthrange[0] = f.lo;
    a->lengthrange[1] = f.hi;
  }
  return fixes;
}

Result<std::vector<LengthRangeFix>> FreezeLengthRanges(mjSpec* spec) {
  auto copy = CopySpec(spec);
  if (!copy.ok()) return Error{copy.error(), copy.code()};
  // Without the locks the bundles' fit check (plugin) warns of the joints they will hold.
  QuietMujocoWarnings quiet;
  auto m = CompileSpec(copy->get());
  if (!m.ok()) return Error{m.error(), m.code()};
  const std::vector<std::string> names = ActuatorNames(spec);
  std::vector<LengthRangeFix> frozen;
  for (int a = 0; a < static_cast<int>(names.size()); ++a) {
    mjsActuator* act = FindActuator(spec, names[a]);
    const double lo = (*m)->actuator_lengthrange[2 * a], hi = (*m)->actuator_lengthrange[2 * a + 1];
    if (act == nullptr || act->lengthrange[0] < act->lengthrange[1] || !(hi > lo)) continue;
    act->lengthrange[0] = lo;
    act->lengthrange[1] = hi;
    frozen.push_back({names[a], lo, hi});
  }
  return frozen;
}

}  // namespace recruit::attach
