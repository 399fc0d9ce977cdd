#include "identification/bench_recorder.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include "common/mujoco_ptr.h"
#include "identification/plant_record.h"
#include "plugin/sma_host.h"
#include "plugin/tendon_range.h"

namespace recruit::identification {
namespace {

struct HeldPose {
  std::vector<int> qadr;  // empty: nothing held
  std::vector<double> q;
  std::vector<double> q_short, q_long;  // where the tendon is shortest and longest
  std::string text;
};

void SetPose(const mjModel* m, mjData* d, const HeldPose& p, const std::vector<double>& q) {
  for (std::size_t i = 0; i < p.qadr.size(); ++i) d->qpos[p.qadr[i]] = q[i];
}

// The pose of every joint that moves `tendon` (plugin/tendon_range.h: usable ranges, cut at
// path jumps, joints a lock holds left out) whose tendon length is at `place` of the tendon's
// length range over them (0 shortest, 1 longest), on the straight path between the poses of the
// shortest and the longest, the other joints at qpos0. All the joints: a bundle that crosses
// two (a biarticular muscle's) reaches lengths one joint alone does not, and its units are seen
// there.
HeldPose ChoosePose(const mjModel* m, mjData* d, int tendon, double place) {
  constexpr int kSamples = 201;
  const sma::TendonRange range = sma::SampleTendonRange(m, d, tendon);
  HeldPose p;
  if (range.joints.empty() || !(range.excursion() > 1e-9)) {
    mju_copy(d->qpos, m->qpos0, m->nq);
    return p;
  }
  for (int j : range.joints) p.qadr.push_back(m->jnt_qposadr[j]);
  p.q_short = range.q_shortest;
  p.q_long = range.q_longest;
  const double want = range.length_min + place * range.excursion();
  double best_gap = INFINITY;
  std::vector<double> q(p.qadr.size());
  for (int k = 0; k < kSamples; ++k) {
    const double f = double(k) / (kSamples - 1);
    for (std::size_t i = 0; i < q.size(); ++i)
      q[i] = p.q_short[i] + f * (p.q_long[i] - p.q_short[i]);
    mju_copy(d->qpos, m->qpos0, m->nq);
    SetPose(m, d, p, q);
    mj_kinematics(m, d);
    mj_comPos(m, d);
    mj_tendon(m, d);
    const double gap = std::abs(d->ten_length[tendon] - want);
    if (gap < best_gap) best_gap = gap, p.q = q;
  }
  for (std::size_t i = 0; i < p.q.size(); ++i) {
    const int j = range.joints[i];
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    char buf[160];
    if (m->jnt_type[j] == mjJNT_HINGE) {
      std::snprintf(buf, sizeof buf, "%s %.1f deg", name ? name : "joint", p.q[i] * 180 / M_PI);
    } else {
      std::snprintf(buf, sizeof buf, "%s %.4f m", name ? name : "joint", p.q[i]);
    }
    p.text += (p.text.empty() ? "" : ", ") + std::string(buf);
  }
  mju_copy(d->qpos, m->qpos0, m->nq);
  return p;
}

// Holds the pose before each physics step: the joints at q and every velocity zero; with a
// sweep period T > 0 the joints are driven instead, q(t) = q_short + (q_long - q_short)
// (1 - cos(2 pi t / T)) / 2, from the shortest tendon to the longest and back.
void Hold(const mjModel* m, mjData* d, const HeldPose& p, double period) {
  if (p.qadr.empty()) return;
  mju_zero(d->qvel, m->nv);
  if (period > 0) {
    const double f = 0.5 * (1 - std::cos(2 * M_PI / period * d->time));
    for (std::size_t i = 0; i < p.qadr.size(); ++i) {
      d->qpos[p.qadr[i]] = p.q_short[i] + (p.q_long[i] - p.q_short[i]) * f;
    }
  } else {
    SetPose(m, d, p, p.q);
  }
}

}  // namespace

Result<BenchRecording> RecordBench(const std::string& model_path, const std::string& actuator,
                                   const Excitation& excitation, double dT, std::uint64_t seed,
                                   const RecordOptions& options) {
  auto loaded = LoadBundle(model_path, actuator);
  if (!loaded) return Error{loaded.error(), loaded.code()};
  const ModelPtr& m = loaded->model;
  const sma::SmaHost& p = *loaded->host;
  const int b = loaded->bundle;
  const double h = m->opt.timestep;
  const double ratio = dT / h;
  const int steps = static_cast<int>(std::lround(ratio));
  if (!(dT > 0) || steps < 1 || std::abs(ratio - steps) > 1e-6 * ratio) {
    return Error{"identify: dT = " + std::to_string(dT) + " s must be a positive whole number of " +
                 model_path + "'s timesteps (" + std::to_string(h) + " s)"};
  }
  if (!(options.sweep_period >= 0) || !std::isfinite(options.sweep_period)) {
    return Error{"identify: the sweep period must be finite and >= 0 s"};
  }
  if (!(options.length_place >= 0 && options.length_place <= 1)) {
    return Error{"identify: the pose's place in the tendon's length range must be in [0, 1]"};
  }
  DataPtr d(mj_makeData(m.get()));
  const HeldPose pose = ChoosePose(m.get(), d.get(), p.tendon_id(b), options.length_place);
  Hold(m.get(), d.get(), pose, options.sweep_period);
  mj_forward(m.get(), d.get());  // the held tendon length, which Reset reads
  p.Reset(d.get(), seed);
  BenchRecording rec;
  rec.unit_force = p.SettledUnitForce(b);
  rec.timestep = h;
  rec.plant = PlantRecord(p, b, model_path);
  SwitchingLog& log = rec.log;
  log.num_units = p.num_units(b);
  log.dT = dT;
  // Forces and sensors at t = 0 (nothing is on yet).
  mj_forward(m.get(), d.get());
  rec.tendon_length = p.UnitLength(d.get(), b);
  rec.stretch = p.Stretch(d.get(), b);
  rec.pose = pose.text;
  rec.geometry = {p.bundle(b).config().unit, p.unit_ref_length(b)};
  std::vector<char> was_on(p.num_units(b));
  for (int k = 0; k < excitation.size(); ++k) {
    log.time.push_back(k * dT);
    log.force.push_back(p.Force(d.get(), b));
    rec.lengths.push_back(p.UnitLength(d.get(), b));
    log.true_on.push_back(p.OnCount(d.get(), b));
    log.p_on.push_back(excitation.p_on[k]);
    log.p_off.push_back(excitation.p_off[k]);
    // Which units switched, from the per-unit debug state (the fit's realized inputs).
    const int n = p.num_units(b);
    for (int i = 0; i < n; ++i) was_on[i] = p.UnitOn(d.get(), b, i);
    if (Status s = p.Broadcast(d.get(), b, excitation.p_on[k], excitation.p_off[k]); !s) {
      return Error{"identify: broadcast " + std::to_string(k) + ": " + s.error(), s.code()};
    }
    int on_before = 0, turned_on = 0, turned_off = 0;
    for (int i = 0; i < n; ++i) {
      const bool now = p.UnitOn(d.get(), b, i);
      on_before += was_on[i];
      turned_on += !was_on[i] && now;
      turned_off += was_on[i] && !now;
    }
    log.realized_on.push_back(on_before < n ? double(turned_on) / (n - on_before) : 0.0);
    log.realized_off.push_back(on_before > 0 ? double(turned_off) / on_before : 0.0);
    for (int i = 0; i < steps; ++i) {
      Hold(m.get(), d.get(), pose, options.sweep_period);
      mj_step(m.get(), d.get());
    }
    Hold(m.get(), d.get(), pose, options.sweep_period);
    mj_forward(m.get(), d.get());
  }
  return rec;
}

}  // namespace recruit::identification
