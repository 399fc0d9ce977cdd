#include "plugin/tendon_range.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <tuple>
#include <utility>

#include "common/rng.h"

namespace recruit::sma {
namespace {

std::string RangeFmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

double TendonLengthNow(const mjModel* m, mjData* d, int t) {
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_tendon(m, d);
  return d->ten_length[t];
}

// The joint a one-joint equality holds (MuJoCo's joint equality without joint2, active at
// start: q = qpos0 + data[0]), or -1.
int HeldJoint(const mjModel* m, int e) {
  if (m->eq_type[e] != mjEQ_JOINT || !m->eq_active0[e] || m->eq_obj2id[e] >= 0) return -1;
  return m->eq_obj1id[e];
}

// The rest pose the sweeps start from: qpos0, with the joints equalities hold where they hold
// them (`recruit attach --lock`).
void RestPose(const mjModel* m, mjData* d) {
  mju_copy(d->qpos, m->qpos0, m->nq);
  for (int e = 0; e < m->neq; ++e) {
    const int j = HeldJoint(m, e);
    if (j >= 0) d->qpos[m->jnt_qposadr[j]] += m->eq_data[e * mjNEQDATA];
  }
}

bool Held(const mjModel* m, int j) {
  for (int e = 0; e < m->neq; ++e) {
    if (HeldJoint(m, e) == j) return true;
  }
  return false;
}

// Tendon length with joint j at q, every other joint at the rest pose.
double LengthAt(const mjModel* m, mjData* d, int t, int j, double q) {
  RestPose(m, d);
  d->qpos[m->jnt_qposadr[j]] = q;
  return TendonLengthNow(m, d, t);
}

// Jumps of tendon t's length over joint j's [lo, hi] (others at qpos0). Each jump is returned
// with the bracketing joint values a < b (b - a < 1e-9 of the range) in *brackets.
std::vector<TendonJump> FindJumps(const mjModel* m, mjData* d, int t, int j, double lo, double hi,
                                  std::vector<std::pair<double, double>>* brackets) {
  constexpr int kPoints = 65;
  constexpr double kJump = 1e-5;  // m: a change this large across 1e-9 of the range is a jump
  std::vector<double> q(kPoints), len(kPoints), change(kPoints - 1);
  for (int i = 0; i < kPoints; ++i) {
    q[i] = lo + (hi - lo) * i / (kPoints - 1);
    len[i] = LengthAt(m, d, t, j, q[i]);
  }
  for (int i = 0; i + 1 < kPoints; ++i) change[i] = std::abs(len[i + 1] - len[i]);
  std::vector<double> sorted = change;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double threshold = std::max(4 * sorted[sorted.size() / 2], kJump);
  std::vector<TendonJump> jumps;
  for (int i = 0; i + 1 < kPoints; ++i) {
    if (change[i] <= threshold) continue;
    double a = q[i], b = q[i + 1], la = len[i], lb = len[i + 1];
    while (b - a > 1e-9 * (hi - lo)) {
      const double c = 0.5 * (a + b), lc = LengthAt(m, d, t, j, c);
      if (std::abs(lc - la) >= std::abs(lb - lc)) {
        b = c, lb = lc;
      } else {
        a = c, la = lc;
      }
    }
    if (std::abs(lb - la) > kJump) {
      jumps.push_back({j, 0.5 * (a + b), la, lb});
      brackets->push_back({a, b});
    }
  }
  return jumps;
}

// The extremes of a smooth length(x) over x in [0, 1]: 33 points (the ends and the middle among
// them), then each interior grid extreme refined by golden-section search between its
// neighbours to 1e-6 of the range. Most tendons are monotone in one joint.
template <typename LengthFn>
std::pair<double, double> LengthRangeOverOneJoint(LengthFn length) {
  constexpr int kPoints = 33;
  double v[kPoints];
  for (int i = 0; i < kPoints; ++i) v[i] = length(i / double(kPoints - 1));
  double lo = *std::min_element(v, v + kPoints), hi = *std::max_element(v, v + kPoints);
  const double h = 1.0 / (kPoints - 1), g = 0.5 * (std::sqrt(5.0) - 1);
  for (int i = 1; i + 1 < kPoints; ++i) {
    for (double sign : {1.0, -1.0}) {  // +1: a minimum, -1: a maximum
      // Strict on the left: a plateau is refined once, not at each of its points.
      if (!(sign * v[i] < sign * v[i - 1] && sign * v[i] <= sign * v[i + 1])) continue;
      double a = (i - 1) * h, b = (i + 1) * h;
      double c = b - g * (b - a), e = a + g * (b - a);
      double fc = sign * length(c), fe = sign * length(e);
      while (b - a > 1e-6) {
        if (fc < fe) {
          b = e, e = c, fe = fc, c = b - g * (b - a), fc = sign * length(c);
        } else {
          a = c, c = e, fc = fe, e = a + g * (b - a), fe = sign * length(e);
        }
      }
      if (sign > 0) {
        lo = std::min({lo, fc, fe});
      } else {
        hi = std::max({hi, -fc, -fe});
      }
    }
  }
  return {lo, hi};
}

// Tendon t's length range with joints[i] over [lo[i], hi[i]]. One joint: LengthRangeOverOneJoint.
// More: a grid with an odd number of points per joint (so the limits and the middle are on it),
// 65 x 65 for two, up to ~4096 in all; beyond 6 joints 4096 seeded random points plus the all-low
// and all-high corners.
// Fills r.length_min/max and the joint values where they were found (r.q_shortest/longest).
void LengthRange(const mjModel* m, mjData* d, int t, TendonRange& r) {
  const std::vector<int>& joints = r.joints;
  const std::vector<double>&jlo = r.usable_lo, &jhi = r.usable_hi;
  const int n = static_cast<int>(joints.size());
  double lo = INFINITY, hi = -INFINITY;
  std::vector<double> q(n);
  auto sample = [&](const std::vector<double>& f) {
    RestPose(m, d);
    for (int i = 0; i < n; ++i) {
      q[i] = jlo[i] + f[i] * (jhi[i] - jlo[i]);
      d->qpos[m->jnt_qposadr[joints[i]]] = q[i];
    }
    const double l = TendonLengthNow(m, d, t);
    if (l < lo) lo = l, r.q_shortest = q;
    if (l > hi) hi = l, r.q_longest = q;
    return l;
  };
  std::vector<double> f(n, 0.0);
  if (n == 1) {
    LengthRangeOverOneJoint([&](double x) {  // its extremes are among the samples
      f[0] = x;
      return sample(f);
    });
  } else if (n <= 6) {
    const int points = std::clamp(static_cast<int>(std::pow(4096.0, 1.0 / n)) | 1, 3, 257);
    std::vector<int> idx(n, 0);
    while (true) {
      for (int i = 0; i < n; ++i) f[i] = idx[i] / double(points - 1);
      sample(f);
      int i = 0;
      while (i < n && ++idx[i] == points) idx[i++] = 0;
      if (i == n) break;
    }
  } else {
    Rng rng(1);
    for (int s = 0; s < 4096; ++s) {
      for (int i = 0; i < n; ++i) f[i] = s < 2 ? double(s) : rng.Uniform();
      sample(f);
    }
  }
  r.length_min = lo;
  r.length_max = hi;
}

}  // namespace

std::vector<int> TendonJoints(const mjModel* m, mjData* d, int t) {
  RestPose(m, d);
  const double l0 = TendonLengthNow(m, d, t);
  std::vector<int> joints;
  for (int j = 0; j < m->njnt; ++j) {
    const int type = m->jnt_type[j];
    if ((type != mjJNT_HINGE && type != mjJNT_SLIDE) || !m->jnt_limited[j] || Held(m, j)) continue;
    const int q = m->jnt_qposadr[j];
    const double rest = d->qpos[q];
    bool moves = false;
    for (double f : {0.0, 0.5, 1.0}) {
      d->qpos[q] = m->jnt_range[2 * j] + f * (m->jnt_range[2 * j + 1] - m->jnt_range[2 * j]);
      moves = moves || std::abs(TendonLengthNow(m, d, t) - l0) > 1e-9;
    }
    d->qpos[q] = rest;
    if (moves) joints.push_back(j);
  }
  return joints;
}

TendonRange SampleTendonRange(const mjModel* m, mjData* d, int t) {
  TendonRange r;
  r.joints = TendonJoints(m, d, t);
  for (int j : r.joints) {
    const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
    const double q0 = std::clamp(m->qpos0[m->jnt_qposadr[j]], lo, hi);
    std::vector<std::pair<double, double>> brackets;
    std::vector<TendonJump> jumps = FindJumps(m, d, t, j, lo, hi, &brackets);
    double ulo = lo, uhi = hi;
    for (std::size_t k = 0; k < jumps.size(); ++k) {
      if (brackets[k].second <= q0) ulo = std::max(ulo, brackets[k].second);
      if (brackets[k].first >= q0) uhi = std::min(uhi, brackets[k].first);
    }
    r.usable_lo.push_back(ulo);
    r.usable_hi.push_back(uhi);
    r.jumps.insert(r.jumps.end(), jumps.begin(), jumps.end());
  }
  if (!r.joints.empty()) {
    LengthRange(m, d, t, r);
  } else {
    RestPose(m, d);
    r.length_min = r.length_max = TendonLengthNow(m, d, t);
  }
  return r;
}

std::string JointRangeText(const mjModel* m, const std::vector<int>& joints,
                           const std::vector<double>& lo, const std::vector<double>& hi) {
  std::string s;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const int j = joints[i];
    const bool hinge = m->jnt_type[j] == mjJNT_HINGE;
    const double k = hinge ? 180 / mjPI : 1000;
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    s += (s.empty() ? "" : ", ") + std::string(name != nullptr ? name : "#" + std::to_string(j)) +
         " " + RangeFmt("%.4g", k * lo[i]) + ".." + RangeFmt("%.4g", k * hi[i]) +
         (hinge ? " deg" : " mm");
  }
  return s;
}

std::string JumpText(const mjModel* m, const TendonJump& jump) {
  const bool hinge = m->jnt_type[jump.joint] == mjJNT_HINGE;
  const char* name = mj_id2name(m, mjOBJ_JOINT, jump.joint);
  return std::string(name != nullptr ? name : "#" + std::to_string(jump.joint)) + " at " +
         RangeFmt("%.4g", (hinge ? 180 / mjPI : 1000) * jump.at) + (hinge ? " deg" : " mm") + " (" +
         RangeFmt("%.1f", 1000 * jump.before) + " -> " + RangeFmt("%.1f", 1000 * jump.after) +
         " mm)";
}

double TendonArm(const mjModel* m, const mjData* d, int t, int dof) {
  const int adr = m->ten_J_rowadr[t];
  for (int k = 0; k < m->ten_J_rownnz[t]; ++k) {
    if (m->ten_J_colind[adr + k] == dof) return d->ten_J[adr + k];
  }
  return 0;
}

}  // namespace recruit::sma
