// Dampers beside the bundles. A muscle damps its joint (its force falls as it shortens faster: the
// force-velocity relation); an SMA wire does not, and its force changes in seconds, too slowly to
// damp a limb's swing through the loop. A joint the bundles hold as a spring then rings: arm26's
// shoulder (inertia 1.55 kg m^2, the bundles' stiffness at rest 3.2 N m/rad, joint damping 0.1
// N m s/rad) at a damping ratio of 0.02. Each bundle gets a viscous damper (a dashpot in parallel
// with its units, behind the same lever: MuJoCo's actuator `damping`) so that every joint the
// bundles move has at least the damping ratio asked for at the stiffness the bundles hold it with
// at rest (docs/sma-units.md, "Dampers").
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "attach/sizing.h"
#include "common/result.h"

namespace recruit::attach {

// A joint the bundles move, about the model's reference pose.
struct DampedJoint {
  std::string joint;
  double inertia = 0;  // kg m^2 (mass-matrix diagonal, armature included), > 0
  double damping = 0;  // N m s/rad the limb has without the bundles' dampers, >= 0
  // Filled by DesignDampers:
  double stiffness = 0;      // N m/rad: the bundles' at rest, sum_b k_b A_jb^2
  double damping_after = 0;  // N m s/rad with the dampers
  double ratio_before = 0;   // damping / (2 sqrt(stiffness inertia))
  double ratio_after = 0;
};

struct DampedBundle {
  double stiffness = 0;      // N/m at the tendon at rest (RestStiffness), >= 0
  std::vector<double> arms;  // m, per joint of the problem: dL/dq at the reference pose (0: none)
};

// A bundle's stiffness at its tendon when it pulls its rest tension (N) with the units it has
// on: a hot unit's tension is its stiffness times its stretch, so dF/dL = F g / s, with s the
// units' stretch at mid-range (prestretch + g (L_mid - L_ref)).
double RestStiffness(const BundleDesign& d, const SizingInput& in, double rest_tension);

// The rest tension the stiffness is taken at: the co-contraction the self-tuned loop holds a
// bundle with at least (rest_tension_fraction of its peak force), or the force that holds the
// limb's weight when that is larger.
double RestTension(const SizingInput& in, const SizingLimits& limits);

// Per bundle, the damping (N s/m at the tendon) that brings every joint to at least `ratio`:
// joint j needs b_j = max(0, 2 ratio sqrt(K_j I_j) - damping_j) more, which the bundles crossing
// it share in proportion to their stiffness (c_b = k_b b_j / K_j: stiffness-proportional, as a
// muscle's damping grows with its force); a bundle on several joints takes the largest share
// any of them asks. Fills the joints' figures. Error on a non-finite or negative input.
Result<std::vector<double>> DesignDampers(std::vector<DampedJoint>& joints,
                                          const std::vector<DampedBundle>& bundles, double ratio);

// Joint j's inertia and damping at the pose in d (positions set, mj_fwdPosition done): the
// mass-matrix diagonal, and sma::JointDamping with the actuators in `skip` left out (the ones
// being replaced).
DampedJoint ProbeJoint(const mjModel* m, const mjData* d, int joint, const std::vector<int>& skip);

}  // namespace recruit::attach
