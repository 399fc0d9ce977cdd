#include "attach/damper.h"

#include <algorithm>
#include <cmath>

#include "plugin/joint_damping.h"

namespace recruit::attach {
namespace {

bool Finite(double v) { return std::isfinite(v); }

double Ratio(double damping, double stiffness, double inertia) {
  const double critical = 2 * std::sqrt(std::max(stiffness, 0.0) * inertia);
  return critical > 0 ? damping / critical : 0;
}

}  // namespace

double RestTension(const SizingInput& in, const SizingLimits& limits) {
  return std::max(limits.rest_tension_fraction * in.peak_force, in.holding_force);
}

double RestStiffness(const BundleDesign& d, const SizingInput& in, double rest_tension) {
  const double l_mid = 0.5 * (in.length_min + in.length_max);
  const double stretch = d.Stretch(l_mid, in.ref_length);
  return stretch > 0 ? rest_tension * d.gear / stretch : 0;
}

Result<std::vector<double>> DesignDampers(std::vector<DampedJoint>& joints,
                                          const std::vector<DampedBundle>& bundles, double ratio) {
  if (!(Finite(ratio) && ratio >= 0)) {
    return Error{"damping ratio " + std::to_string(ratio) + " is invalid: must be >= 0"};
  }
  const std::size_t nj = joints.size();
  for (const DampedJoint& j : joints) {
    if (!(Finite(j.inertia) && j.inertia > 0 && Finite(j.damping) && j.damping >= 0)) {
      return Error{"joint '" + j.joint + "': inertia " + std::to_string(j.inertia) +
                   " and damping " + std::to_string(j.damping) + " must be > 0 and >= 0"};
    }
  }
  for (const DampedBundle& b : bundles) {
    if (!(Finite(b.stiffness) && b.stiffness >= 0) || b.arms.size() != nj ||
        !std::all_of(b.arms.begin(), b.arms.end(), Finite)) {
      return Error{"a bundle's stiffness or moment arms are invalid"};
    }
  }
  // Per joint: the bundles' stiffness and the extra damping per unit of it (a time, s).
  std::vector<double> per_stiffness(nj, 0.0);
  for (std::size_t j = 0; j < nj; ++j) {
    DampedJoint& joint = joints[j];
    joint.stiffness = 0;
    for (const DampedBundle& b : bundles) joint.stiffness += b.stiffness * b.arms[j] * b.arms[j];
    const double need =
        std::max(0.0, 2 * ratio * std::sqrt(joint.stiffness * joint.inertia) - joint.damping);
    if (joint.stiffness > 0) per_stiffness[j] = need / joint.stiffness;
  }
  std::vector<double> c(bundles.size(), 0.0);
  for (std::size_t i = 0; i < bundles.size(); ++i) {
    double beta = 0;
    for (std::size_t j = 0; j < nj; ++j) {
      if (bundles[i].arms[j] != 0) beta = std::max(beta, per_stiffness[j]);
    }
    c[i] = beta * bundles[i].stiffness;
  }
  for (std::size_t j = 0; j < nj; ++j) {
    DampedJoint& joint = joints[j];
    joint.damping_after = joint.damping;
    for (std::size_t i = 0; i < bundles.size(); ++i) {
      joint.damping_after += c[i] * bundles[i].arms[j] * bundles[i].arms[j];
    }
    joint.ratio_before = Ratio(joint.damping, joint.stiffness, joint.inertia);
    joint.ratio_after = Ratio(joint.damping_after, joint.stiffness, joint.inertia);
  }
  return c;
}

DampedJoint ProbeJoint(const mjModel* m, const mjData* d, int joint, const std::vector<int>& skip) {
  DampedJoint out;
  const char* name = mj_id2name(m, mjOBJ_JOINT, joint);
  out.joint = name != nullptr ? name : "#" + std::to_string(joint);
  const int dof = m->jnt_dofadr[joint];
  std::vector<mjtNum> full(static_cast<std::size_t>(m->nv) * m->nv);
  mj_fullM(m, d, full.data());
  out.inertia = full[static_cast<std::size_t>(dof) * m->nv + dof];
  out.damping = sma::JointDamping(m, d, dof, skip);
  return out;
}

}  // namespace recruit::attach
