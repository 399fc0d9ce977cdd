#include "export/auto_loop_export.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "control/actuator_response.h"
#include "sim/bundle_models.h"
#include "sim/joint_loop.h"
#include "sim/loop_constants.h"
#include "sim/plant.h"

namespace recruit::exporter {
namespace {

std::vector<sim::UnitForce> UnitForces(const std::vector<sim::BundleController>& controllers) {
  std::vector<sim::UnitForce> out;
  for (const sim::BundleController& c : controllers) {
    out.push_back([&c](double L) { return c.controller.OnUnitForce(L); });
  }
  return out;
}

FrozenJointSetting Setting(const sim::JointDesignRecord* rec, int nb) {
  FrozenJointSetting s;
  if (rec == nullptr || rec->holding.coef.size() != nb) return s;
  s.kp = rec->design.gains.kp;
  s.ki = rec->design.gains.ki;
  s.kd = rec->design.gains.kd;
  s.holds = true;
  s.coef.assign(rec->holding.coef.data(), rec->holding.coef.data() + nb);
  s.limb_stiffness = rec->holding.limb_stiffness;
  return s;
}

}  // namespace

Result<FrozenAutoLoop> FreezeAutoLoop(const sim::Task& task, const sim::RunOptions& options,
                                      const std::vector<sim::BundleController>& controllers) {
  const std::string where = task.source.empty() ? task.name : task.source;
  const sim::ControllerSettings settings = sim::EffectiveSettings(task, options);
  auto plant_or = sim::Plant::Create(task, /*drawn=*/false);
  if (!plant_or.ok()) return Error{plant_or.error(), plant_or.code()};
  sim::Plant& plant = **plant_or;
  plant.Reset(options.seed);
  const int nj = plant.num_joints(), nb = plant.num_bundles();
  if (static_cast<int>(controllers.size()) != nb) {
    return Error{where + ": one controller per bundle is needed"};
  }
  // As RunTask designs the loop (sim/bundle_models.h); its warnings are the run's, not the C's.
  double identify_s = 0;
  std::vector<std::string> warnings;
  auto responses =
      sim::ActuatorResponses(task, settings, plant, controllers, options, identify_s, warnings);
  if (!responses) return Error{where + ".outer_loop: " + responses.error(), responses.code()};
  std::vector<control::ActuatorResponse> resp = *responses;
  auto loops =
      sim::JointLoops::Create(task, plant, std::move(resp), UnitForces(controllers), settings.dT);
  if (!loops) return Error{where + ".outer_loop: " + loops.error(), loops.code()};

  FrozenAutoLoop out;
  out.dT = settings.dT;
  out.co_contraction = task.co_contraction;
  const Eigen::VectorXd& price = loops->prices();  // the allocation's (sim::BundlePrices)
  for (int i = 0; i < nb; ++i) {
    out.price.push_back(price[i]);
    out.held_only.push_back(loops->held_only()[i] ? 1 : 0);
    out.units.push_back(plant.num_units(i));
  }
  for (int j = 0; j < nj; ++j) {
    out.joints.push_back(plant.joint_name(j));
    double lo = 0, hi = 0;
    const bool limited = plant.JointRange(j, &lo, &hi);
    const double margin = sim::kLimitMargin * (hi - lo);
    out.limited.push_back(limited ? 1 : 0);
    out.lo.push_back(limited ? lo + margin : 0.0);
    out.hi.push_back(limited ? hi - margin : 0.0);
  }

  // The run's control instants (RunTask: the plant's clock advances by its timestep; an instant
  // is due when t + h/2 reaches the next multiple of dT), and at each the designs JointLoops::Step
  // makes: one per joint and new reference value, stepping from the last one (from the limb at
  // rest at the first instant).
  const double duration = options.duration ? *options.duration : task.duration;
  const double h = plant.timestep();
  const long num_steps = std::lround(duration / h);
  std::vector<std::map<double, std::unique_ptr<sim::JointDesignRecord>>> designs(nj);
  std::vector<double> last(nj, std::nan(""));
  std::map<std::vector<double>, int> pose_index;
  double t = 0, next_control = 0;
  long instants = 0;
  for (long step = 0; step < num_steps; ++step, t += h) {
    if (!(t + 0.5 * h >= next_control)) continue;
    ++instants;
    next_control = instants * settings.dT;
    const Eigen::VectorXd r = loops->LoopReference(plant, t);
    for (int j = 0; j < nj; ++j) {
      const double raw = task.joints[j].reference(t);
      const double clamped = out.limited[j] ? std::clamp(raw, out.lo[j], out.hi[j]) : raw;
      if (clamped != r[j]) {
        return Error{where + ": joint '" + out.joints[j] +
                     "': the exported reference clamp differs from the loop's (kLimitMargin)"};
      }
      const double from = std::isnan(last[j]) ? plant.JointAngle(j) : last[j];
      last[j] = r[j];
      if (designs[j].count(r[j]) != 0) continue;
      auto rec = loops->Design(plant, j, r, r[j] - from);
      designs[j][r[j]] =
          rec ? std::make_unique<sim::JointDesignRecord>(std::move(rec).value()) : nullptr;
    }
    const std::vector<double> key(r.data(), r.data() + nj);
    if (pose_index.count(key) != 0) continue;
    pose_index[key] = static_cast<int>(out.poses.size());
    FrozenPose p;
    p.first_time = t;
    p.reference = key;
    const Eigen::VectorXd ff = plant.StaticTorque(r);
    const Eigen::MatrixXd arms = plant.MomentArmsAt(r);
    const Eigen::VectorXd lengths = plant.UnitLengthsAt(r);
    for (int j = 0; j < nj; ++j) {
      p.feedforward.push_back(ff[j]);
      for (int i = 0; i < nb; ++i) p.arms.push_back(arms(j, i));
      p.joint.push_back(Setting(designs[j][r[j]].get(), nb));
    }
    for (int i = 0; i < nb; ++i) {
      p.unit_force.push_back(controllers[i].controller.OnUnitForce(lengths[i]));
    }
    out.poses.push_back(std::move(p));
  }

  // What the table assumes of the limb beyond the driven joints.
  const mjModel* m = plant.model();
  if (m->nv > nj) {
    out.notes.push_back(
        "the model has " + std::to_string(m->nv - nj) +
        " degree(s) of freedom the task does not drive: the static torques and moment arms are "
        "taken with them where the plant's reset puts them");
  }
  for (const sim::Payload& pl : task.payloads) {
    if (pl.time > 0) {
      out.notes.push_back("payload '" + pl.body + "' changes at " + std::to_string(pl.time) +
                          " s: the feedforward is the model's with the payloads of t = 0");
      break;
    }
  }
  return out;
}

namespace {

// The loop's C, after the constants: JointLoops::Step with control::AllocateTensions,
// sim::AllocateHolding and control::RoundToUnits, operation for operation. Sums run in the
// order of the C++ build's: Eigen's matrix-vector products and strided reductions add in index
// order (seq), its contiguous dot products in 2-wide packets (lanesum; the same as index order
// for up to three terms); the Cholesky solve is Eigen's unblocked LLT with its triangular
// solves (panels of 8: exact for up to 8 bundles).
const char* const kAutoLoopC = R"RECRUIT_C(
#define NJ RECRUIT_NUM_JOINTS
#define NB RECRUIT_NUM_BUNDLES
#define ROWS (2 * NJ) /* a joint's demand, and a stiffness row per holding joint */
#define EPS 1e-8  /* the allocation's sharing weight */
enum { FREE, LOWER, UPPER };

static double clampd(double v, double lo, double hi) { return v < lo ? lo : (hi < v ? hi : v); }

/* lanesum (above) in double. */
RECRUIT_LANESUM(lanesum_d, double)

typedef struct {
  int rows;
  double arms[ROWS][NB]; /* N m per N of tension */
  double torque[ROWS];   /* N m (a stiffness row: N m/rad) */
  double floor[NB], cap[NB], price[NB];
} alloc_problem;

/* 1 / s_j^2, s_j = sum_b |arms_jb| cap_b (0 for a row no bundle moves). */
static void joint_weights(const alloc_problem *p, double *w) {
  int j, b;
  for (j = 0; j < p->rows; ++j) {
    double span = fabs(p->arms[j][0]) * p->cap[0];
    for (b = 1; b < NB; ++b) span += fabs(p->arms[j][b]) * p->cap[b];
    w[j] = span > 0 ? 1.0 / (span * span) : 0.0;
  }
}

/* Q_FF y = c_F - Q_FB x_B for the free variables (Cholesky, Eigen's LLT); out = x elsewhere. */
static void free_minimum(const double Q[NB][NB], const double *c, const int *state,
                         const double *x, double *out) {
  double L[NB][NB], y[NB], t[NB];
  int f[NB], nf = 0, a, b, i, k, l;
  for (i = 0; i < NB; ++i) {
    out[i] = x[i];
    if (state[i] == FREE) f[nf++] = i;
  }
  if (nf == 0) return;
  for (a = 0; a < nf; ++a) {
    y[a] = c[f[a]];
    for (i = 0; i < NB; ++i) {
      if (state[i] != FREE) y[a] -= Q[f[a]][i] * x[i];
    }
    for (b = 0; b < nf; ++b) L[a][b] = Q[f[a]][f[b]];
  }
  for (k = 0; k < nf; ++k) { /* L L^T, lower triangle */
    double d = L[k][k];
    if (k > 0) {
      double sq = L[k][0] * L[k][0];
      for (l = 1; l < k; ++l) sq += L[k][l] * L[k][l];
      d -= sq;
    }
    L[k][k] = d = sqrt(d);
    for (i = k + 1; i < nf; ++i) {
      if (k > 0) {
        double s = L[i][0] * L[k][0];
        for (l = 1; l < k; ++l) s += L[i][l] * L[k][l];
        L[i][k] -= s;
      }
      L[i][k] /= d;
    }
  }
  for (i = 0; i < nf; ++i) { /* L z = y */
    if (y[i] == 0.0) continue;
    y[i] /= L[i][i];
    for (k = i + 1; k < nf; ++k) y[k] -= y[i] * L[k][i];
  }
  for (i = nf - 1; i >= 0; --i) { /* L^T out = z */
    const int n = nf - 1 - i;
    if (n > 0) {
      for (l = 0; l < n; ++l) t[l] = L[i + 1 + l][i] * y[i + 1 + l];
      y[i] -= lanesum_d(t, n);
    }
    if (y[i] != 0.0) y[i] /= L[i][i];
  }
  for (a = 0; a < nf; ++a) out[f[a]] = y[a];
}

/* control::AllocateTensions: min sum_j (((arms T - torque)_j) / s_j)^2 + eps sum_b
 * (price_b T_b / cap_b)^2 over floor <= T <= cap, by the same primal active-set steps. */
static void allocate_tensions(const alloc_problem *p, double *x) {
  double w[ROWS], Q[NB][NB], c[NB], t[ROWS], target[NB], grad[NB];
  int state[NB], a, b, i, j, iter;
  joint_weights(p, w);
  for (a = 0; a < NB; ++a) {
    for (b = 0; b < NB; ++b) {
      for (j = 0; j < p->rows; ++j) t[j] = (p->arms[j][a] * w[j]) * p->arms[j][b];
      Q[a][b] = lanesum_d(t, p->rows);
    }
  }
  for (b = 0; b < NB; ++b) Q[b][b] += EPS * p->price[b] * p->price[b] / (p->cap[b] * p->cap[b]);
  for (a = 0; a < NB; ++a) {
    for (j = 0; j < p->rows; ++j) t[j] = (p->arms[j][a] * w[j]) * p->torque[j];
    c[a] = lanesum_d(t, p->rows);
  }
  for (i = 0; i < NB; ++i) {
    x[i] = p->floor[i];
    state[i] = LOWER;
  }
  for (iter = 0; iter < 50 * (NB + 1); ++iter) {
    double alpha = 1.0, best = 0.0;
    int blocking = -1, release = -1;
    free_minimum((const double(*)[NB])Q, c, state, x, target);
    for (i = 0; i < NB; ++i) { /* the longest step inside the box */
      double lim, s;
      if (state[i] != FREE || target[i] == x[i]) continue;
      lim = target[i] < x[i] ? p->floor[i] : p->cap[i];
      s = (lim - x[i]) / (target[i] - x[i]);
      if (s < alpha) alpha = s, blocking = i;
    }
    for (i = 0; i < NB; ++i) x[i] += alpha * (target[i] - x[i]);
    if (blocking >= 0) {
      x[blocking] = target[blocking] < x[blocking] ? p->floor[blocking] : p->cap[blocking];
      state[blocking] = x[blocking] == p->floor[blocking] ? LOWER : UPPER;
      continue;
    }
    for (i = 0; i < NB; ++i) { /* Q x - c */
      double g = Q[i][0] * x[0];
      for (b = 1; b < NB; ++b) g += Q[i][b] * x[b];
      grad[i] = g - c[i];
    }
    for (i = 0; i < NB; ++i) { /* release the held one pointing most into the box */
      double into;
      if (!(p->floor[i] < p->cap[i])) continue; /* held at floor == cap: never released */
      into = state[i] == LOWER ? -grad[i] : state[i] == UPPER ? grad[i] : 0.0;
      if (into > best * (1.0 + 1e-12) && into > 1e-14 * fabs(c[i]) + 1e-300) {
        best = into, release = i;
      }
    }
    if (release < 0) break;
    state[release] = FREE;
  }
  for (i = 0; i < NB; ++i) x[i] = clampd(x[i], p->floor[i], p->cap[i]);
}

/* sim::AllocateHolding: again with a stiffness row for each holding joint that the tensions
 * would hold with less than STIFFNESS_MARGIN of the stiffness they are made of. */
static void allocate_holding(const alloc_problem *p, const recruit_pose *pose, double *x) {
  alloc_problem q = *p;
  double t[NB];
  int j, b;
  allocate_tensions(p, x);
  for (j = 0; j < NJ; ++j) {
    double least, held;
    if (!pose->holds[j]) continue;
    for (b = 0; b < NB; ++b) t[b] = fabs(pose->coef[j][b]) * x[b];
    least = STIFFNESS_MARGIN * (fabs(pose->limb_stiffness[j]) + lanesum_d(t, NB));
    for (b = 0; b < NB; ++b) t[b] = pose->coef[j][b] * x[b];
    held = pose->limb_stiffness[j] + lanesum_d(t, NB);
    if (held >= least) continue;
    for (b = 0; b < NB; ++b) q.arms[q.rows][b] = pose->coef[j][b];
    q.torque[q.rows++] = least - pose->limb_stiffness[j];
  }
  if (q.rows > p->rows) allocate_tensions(&q, x);
}

/* control::AllocationCost. */
static double allocation_cost(const alloc_problem *p, const double *w,
                                    const double *x) {
  double r[ROWS], share = 0.0;
  int j, b;
  for (j = 0; j < p->rows; ++j) {
    double a = p->arms[j][0] * x[0];
    for (b = 1; b < NB; ++b) a += p->arms[j][b] * x[b];
    r[j] = a - p->torque[j];
    r[j] = (r[j] * r[j]) * w[j];
  }
  for (b = 0; b < NB; ++b) {
    const double s = p->price[b] * x[b] / p->cap[b];
    share += s * s;
  }
  return lanesum_d(r, p->rows) + EPS * share;
}

/* control::RoundToUnits: whole on-units, the combination of counts near each bundle's with
 * the least cost (one below the floor to one above the ceiling for up to four bundles). */
static void round_to_units(const alloc_problem *p, const double *tension,
                           const double *unit_force, double *best) {
  const int reach = NB <= 4 ? 1 : 0;
  double choice[NB][4], x[NB], w[ROWS], best_cost = (double)HUGE_VAL;
  int count[NB], pick[NB], b, k;
  joint_weights(p, w);
  for (b = 0; b < NB; ++b) {
    count[b] = 0;
    pick[b] = 0;
    best[b] = tension[b];
    if (unit_force[b] > 0) {
      const double n = tension[b] / unit_force[b];
      int lo = (int)floor(n) - reach, hi = (int)ceil(n) + reach;
      if (lo < 0) lo = 0;
      if (hi > recruit_units[b]) hi = recruit_units[b];
      for (k = lo; k <= hi; ++k) choice[b][count[b]++] = (double)k * unit_force[b];
    }
    if (count[b] == 0) choice[b][count[b]++] = tension[b];
  }
  for (;;) {
    double cost;
    for (b = 0; b < NB; ++b) x[b] = choice[b][pick[b]];
    cost = allocation_cost(p, w, x);
    if (cost < best_cost) {
      best_cost = cost;
      for (b = 0; b < NB; ++b) best[b] = x[b];
    }
    for (b = 0; b < NB && ++pick[b] == count[b]; ++b) pick[b] = 0;
    if (b == NB) break;
  }
}

/* The pose nearest the (clamped) references (max norm); *exact: they are its references (to
 * POSE_TOLERANCE), which then replace them. */
static int find_pose(double *r, int *exact) {
  int k, j, best = 0;
  double best_d = 0.0;
  for (k = 0; k < RECRUIT_NUM_POSES; ++k) {
    double d = 0.0;
    for (j = 0; j < NJ; ++j) {
      const double e = fabs(r[j] - recruit_poses[k].reference[j]);
      if (e > d) d = e;
    }
    if (k == 0 || d < best_d) best = k, best_d = d;
  }
  *exact = 1;
  for (j = 0; j < NJ; ++j) {
    const double ref = recruit_poses[best].reference[j];
    *exact &= fabs(r[j] - ref) <= POSE_TOLERANCE * fabs(ref);
  }
  if (*exact) {
    for (j = 0; j < NJ; ++j) r[j] = recruit_poses[best].reference[j];
  }
  return best;
}

/* JointLoops::Step: each joint's demand (the pose's static torque plus the PID, integrating
 * while the bundles can deliver), shared by the bundles at the pose, its transient share
 * delivered where the limb is, as whole units there; the force reference is that count at the
 * bundle's present length. */
static void force_references(recruit_controller *c, const recruit_input *in, recruit_real *fr) {
  double r[NJ], trial[NJ], tension[NB], whole[NB], held[NB], present[NB], achieved;
  const recruit_pose *pose;
  alloc_problem p, held_problem;
  int j, b, any_held_only = 0;
  for (b = 0; b < NB; ++b) any_held_only |= recruit_held_only[b];
  for (j = 0; j < NJ; ++j) {
    r[j] = (double)in->reference[j];
    if (recruit_joint_limited[j]) r[j] = clampd(r[j], recruit_joint_lo[j], recruit_joint_hi[j]);
  }
  c->pose = find_pose(r, &c->pose_exact);
  pose = &recruit_poses[c->pose];
  p.rows = NJ;
  for (j = 0; j < NJ; ++j) {
    const double e = r[j] - (double)in->angle[j];
    trial[j] = c->integral[j] + pose->ki[j] * e * dT;
    p.torque[j] = pose->feedforward[j] + pose->kp[j] * e + trial[j] -
                  pose->kd[j] * (double)in->angular_velocity[j];
    for (b = 0; b < NB; ++b) p.arms[j][b] = pose->arms[j][b];
  }
  for (b = 0; b < NB; ++b) {
    const double cap = (double)recruit_units[b] * pose->unit_force[b];
    p.cap[b] = cap > 1e-9 ? cap : 1e-9;
    p.floor[b] = co_contraction * p.cap[b];
    p.price[b] = recruit_price[b];
  }
  allocate_holding(&p, pose, tension);
  for (j = 0; j < NJ; ++j) { /* anti-windup */
    const double e = r[j] - (double)in->angle[j];
    double span = fabs(p.arms[j][0]) * p.cap[0], short_by;
    achieved = p.arms[j][0] * tension[0];
    for (b = 1; b < NB; ++b) {
      achieved += p.arms[j][b] * tension[b];
      span += fabs(p.arms[j][b]) * p.cap[b];
    }
    short_by = p.torque[j] - achieved;
    if (!(fabs(short_by) > 1e-3 * span && short_by * e > 0)) c->integral[j] = trial[j];
  }
  /* sim::DeliveredAtPresentPose: the transient share (tension - held) scaled by the pose's unit
   * force over the present one where the present one is larger. */
  for (b = 0; b < NB; ++b) present[b] = (double)on_unit_force(recruit_bundles[b], in->length[b]);
  held_problem = p;
  for (j = 0; j < NJ; ++j) held_problem.torque[j] = pose->feedforward[j] + trial[j];
  allocate_holding(&held_problem, pose, held);
  if (any_held_only) { /* sim::AllocateTransient: those bundles keep their held tension */
    alloc_problem q = p;
    for (b = 0; b < NB; ++b) {
      if (recruit_held_only[b]) q.floor[b] = q.cap[b] = held[b] > 1e-9 ? held[b] : 1e-9;
    }
    allocate_holding(&q, pose, tension);
  }
  for (b = 0; b < NB; ++b) {
    const double u = pose->unit_force[b];
    if (present[b] > u && u > 0) tension[b] = held[b] + (tension[b] - held[b]) * u / present[b];
  }
  for (j = 0; j < NJ; ++j) {
    p.torque[j] = p.arms[j][0] * tension[0];
    for (b = 1; b < NB; ++b) p.torque[j] += p.arms[j][b] * tension[b];
  }
  round_to_units(&p, tension, pose->unit_force, whole);
  for (b = 0; b < NB; ++b) {
    const double count = pose->unit_force[b] > 0 ? whole[b] / pose->unit_force[b] : 0.0;
    fr[b] = (recruit_real)(count * present[b]);
  }
}
)RECRUIT_C";

std::string Ints(const std::vector<int>& v) {
  std::string s = "{";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + "}";
}

std::string PoseInit(const FrozenPose& p, int nb, const Writer& w) {
  const int nj = static_cast<int>(p.reference.size());
  std::vector<double> kp, ki, kd, limb;
  std::vector<int> holds;
  std::string arms = "{", coef = "{";
  for (int j = 0; j < nj; ++j) {
    const FrozenJointSetting& s = p.joint[j];
    kp.push_back(s.kp);
    ki.push_back(s.ki);
    kd.push_back(s.kd);
    limb.push_back(s.limb_stiffness);
    holds.push_back(s.holds ? 1 : 0);
    arms += (j ? ", " : "") +
            w.List(std::vector<double>(p.arms.begin() + j * nb, p.arms.begin() + (j + 1) * nb));
    coef += (j ? ", " : "") + w.List(s.holds ? s.coef : std::vector<double>(nb, 0.0));
  }
  return "    {" + w.List(p.reference) + ",\n     " + w.List(p.feedforward) + ",\n     " + arms +
         "},\n     " + w.List(p.unit_force) + ",\n     " + w.List(kp) + ", " + w.List(ki) + ", " +
         w.List(kd) + ",\n     " + Ints(holds) + ", " + coef + "},\n     " + w.List(limb) + "}";
}

}  // namespace

LoopCode AutoLoopCode(const FrozenAutoLoop& loop, const Writer& package) {
  // The loop runs in double in either package: its allocation weighs the bundles' shares by
  // 1e-8 of the joints' errors, below a float's resolution (a float Q is singular).
  const Writer w(Precision::kDouble);
  const int nj = static_cast<int>(loop.joints.size());
  const int nb = static_cast<int>(loop.price.size());
  const int np = static_cast<int>(loop.poses.size());
  LoopCode code;
  code.defines =
      "#define RECRUIT_AUTO_LOOP 1 /* the self-tuned joint loops */\n"
      "#define RECRUIT_NUM_JOINTS " +
      std::to_string(nj) + " /* driven joints:";
  for (const std::string& j : loop.joints) code.defines += " " + j;
  code.defines += " */\n#define RECRUIT_NUM_POSES " + std::to_string(np) +
                  " /* reference poses of the task's schedule */\n";
  code.state =
      "  double integral[RECRUIT_NUM_JOINTS]; /* N m, per driven joint: the sum of ki e dT */\n"
      "  int pose;       /* the reference pose of the last step (index into the .c's table) */\n"
      "  int pose_exact; /* 1: the references were that pose's; 0: the nearest pose was used */";
  code.input =
      "  recruit_real reference[RECRUIT_NUM_JOINTS]; /* rad, each driven joint's reference */\n"
      "  recruit_real angle[RECRUIT_NUM_JOINTS];     /* rad, each driven joint's encoder */\n"
      "  recruit_real angular_velocity[RECRUIT_NUM_JOINTS]; /* rad/s */";
  code.init =
      "  for (i = 0; i < RECRUIT_NUM_JOINTS; ++i) c->integral[i] = 0.0;\n"
      "  c->pose = 0;\n  c->pose_exact = 0;";
  std::string s =
      "/* The force references: the self-tuned joint loops of src/sim/joint_loop.cc, with what "
      "they compute from\n * the model frozen per reference pose of the task's schedule "
      "(docs/export.md, \"Self-tuned loops\"). */\n";
  s +=
      "/* A reference within this of a pose's (relative) is that pose's: 0 in a double package, a\n"
      " * float's rounding in a float one. */\n";
  s += std::string("#define POSE_TOLERANCE ") + (package.is_float() ? "1.2e-7" : "0.0") + "\n";
  s += "#define STIFFNESS_MARGIN " + w.Num(sim::kStiffnessMargin) +
       " /* sim/loop_constants.h, kStiffnessMargin */\n";
  s += "typedef struct {\n"
       "  double reference[RECRUIT_NUM_JOINTS];   /* rad, after the limits' margin */\n"
       "  double feedforward[RECRUIT_NUM_JOINTS]; /* N m, the pose's static torque */\n"
       "  double arms[RECRUIT_NUM_JOINTS][RECRUIT_NUM_BUNDLES]; /* N m per N */\n"
       "  double unit_force[RECRUIT_NUM_BUNDLES]; /* N, an on unit's at the pose */\n"
       "  double kp[RECRUIT_NUM_JOINTS], ki[RECRUIT_NUM_JOINTS], kd[RECRUIT_NUM_JOINTS];\n"
       "  int holds[RECRUIT_NUM_JOINTS]; /* 0: no design (feedforward only, no stiffness row) */\n"
       "  double coef[RECRUIT_NUM_JOINTS][RECRUIT_NUM_BUNDLES]; /* N m/rad per N */\n"
       "  double limb_stiffness[RECRUIT_NUM_JOINTS]; /* N m/rad */\n"
       "} recruit_pose;\n";
  s += "static const recruit_pose recruit_poses[RECRUIT_NUM_POSES] = {\n";
  for (int k = 0; k < np; ++k) {
    char c[96];
    std::snprintf(c, sizeof c, "    /* %d: first at t = %g s */\n", k, loop.poses[k].first_time);
    s += c + PoseInit(loop.poses[k], nb, w) + (k + 1 < np ? ",\n" : "\n");
  }
  s += "};\n";
  s += "static const int recruit_joint_limited[RECRUIT_NUM_JOINTS] = " + Ints(loop.limited) + ";\n";
  s += "static const double recruit_joint_lo[RECRUIT_NUM_JOINTS] = " + w.List(loop.lo) + ";\n";
  s += "static const double recruit_joint_hi[RECRUIT_NUM_JOINTS] = " + w.List(loop.hi) + ";\n";
  s += "static const double recruit_price[RECRUIT_NUM_BUNDLES] = " + w.List(loop.price) + ";\n";
  s += "static const int recruit_units[RECRUIT_NUM_BUNDLES] = " + Ints(loop.units) + ";\n";
  s += "static const int recruit_held_only[RECRUIT_NUM_BUNDLES] = " + Ints(loop.held_only) + ";\n";
  s += "static const double co_contraction = " + w.Num(loop.co_contraction) +
       ", dT = " + w.Num(loop.dT) + ";\n";
  s += kAutoLoopC;
  code.outer = s;
  return code;
}

}  // namespace recruit::exporter
