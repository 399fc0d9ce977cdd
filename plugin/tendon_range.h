// A tendon's length range over the ranges of the joints that move it, aware of path jumps: a
// spatial tendon that wraps a cylinder can switch sides at some joint angle and its length then
// jumps (MuJoCo's arm26 EE tendon at 114 deg elbow). A jump is not excursion: the range is taken
// over the usable joint range, the part of each joint's range on qpos0's side of its nearest
// jumps. Used by the plugin's fit check (sma_instance.cc) and by `recruit attach`.
#pragma once

#include <mujoco/mujoco.h>

#include <string>
#include <vector>

namespace recruit::sma {

struct TendonJump {
  int joint = -1;     // joint id
  double at = 0;      // joint value (rad or m) where the length jumps (to 1e-9 of the range)
  double before = 0;  // tendon length just below `at` (m)
  double after = 0;   // just above (m)
};

struct TendonRange {
  std::vector<int> joints;  // limited hinge/slide joints that move the tendon
  // Usable range of each of `joints` (same order): its limits, cut at the nearest jump on each
  // side of qpos0 (each joint swept with the others at qpos0).
  std::vector<double> usable_lo, usable_hi;
  std::vector<TendonJump> jumps;          // every jump found, in joint order then by position
  double length_min = 0, length_max = 0;  // tendon length range over the usable ranges (m)
  // The values of `joints` (same order) where length_min and length_max were found.
  std::vector<double> q_shortest, q_longest;
  double excursion() const { return length_max - length_min; }
};

// Limited hinge and slide joints whose motion changes tendon t's length (probed at both limits
// and the middle, every other joint at qpos0). A joint that an active one-joint equality holds
// (MuJoCo's <equality><joint joint1=.../>, as `recruit attach --lock` writes) does not move: it
// is left out, and every sweep holds it where the equality does. d is scratch.
std::vector<int> TendonJoints(const mjModel* m, mjData* d, int t);

// Tendon t's range over the usable ranges of TendonJoints(m, d, t). Jumps are found on a
// 65-point sweep of each joint (others at qpos0) by bisecting every interval whose length change
// exceeds 4x the sweep's median change until the interval is 1e-9 of the range: a change that
// stays above 1e-5 m there is a jump. The range: one joint, 33 points plus golden-section
// refinement of interior extremes; two to six, a grid of about 4096 points; more, 4096 seeded
// random points and the two corners. d is scratch (its qpos is overwritten).
TendonRange SampleTendonRange(const mjModel* m, mjData* d, int t);

// "elbow 0..120 deg, shoulder -30..90 deg" for the given joints and ranges (lo/hi in model units).
std::string JointRangeText(const mjModel* m, const std::vector<int>& joints,
                           const std::vector<double>& lo, const std::vector<double>& hi);
// "elbow at 114 deg (376.0 -> 211.0 mm)".
std::string JumpText(const mjModel* m, const TendonJump& jump);

// Tendon t's moment arm about degree of freedom `dof`, d(length)/d(qvel[dof]), from MuJoCo's
// sparse tendon Jacobian in d (mj_tendon done); 0 when the tendon does not cross it.
double TendonArm(const mjModel* m, const mjData* d, int t, int dof);

}  // namespace recruit::sma
