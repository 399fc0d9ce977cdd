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

namespace recruit::identification {
namespace {

struct HeldPose {
  int qadr = -1;  // -1: nothing held
  double q = 0;
  double q_short = 0, q_long = 0;  // the joint where the tendon is shortest and longest
  std::string text;
};

// The pose of the limited 1-dof joint that moves `tendon` the most (the first of equals),
// sampled over its range, whose tendon length is at `place` of that joint's length range (0
// shortest, 1 longest), the other joints at qpos0. (A joint that barely moves the tendon, such
// as a finger's abduction for its extensor, would hold it where a unit pulls little.)
HeldPose ChoosePose(const mjModel* m, mjData* d, int tendon, double place) {
  constexpr int kSamples = 201;
  HeldPose chosen;
  double chosen_span = 0;
  for (int j = 0; j < m->njnt; ++j) {
    const int type = m->jnt_type[j];
    if ((type != mjJNT_HINGE && type != mjJNT_SLIDE) || !m->jnt_limited[j]) continue;
    const int qadr = m->jnt_qposadr[j];
    const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
    std::vector<double> q(kSamples), len(kSamples);
    for (int i = 0; i < kSamples; ++i) {
      mju_copy(d->qpos, m->qpos0, m->nq);
      q[i] = lo + (hi - lo) * i / (kSamples - 1);
      d->qpos[qadr] = q[i];
      mj_kinematics(m, d);
      mj_comPos(m, d);
      mj_tendon(m, d);
      len[i] = d->ten_length[tendon];
    }
    const auto [mn, mx] = std::minmax_element(len.begin(), len.end());
    if (*mx - *mn < 1e-9 || *mx - *mn <= chosen_span) continue;  // moves it less
    const double want = *mn + place * (*mx - *mn);
    int best = 0;
    for (int i = 1; i < kSamples; ++i) {
      if (std::abs(len[i] - want) < std::abs(len[best] - want)) best = i;
    }
    HeldPose p;
    p.qadr = qadr;
    p.q = q[best];
    p.q_short = q[mn - len.begin()];
    p.q_long = q[mx - len.begin()];
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    char buf[160];
    if (type == mjJNT_HINGE) {
      std::snprintf(buf, sizeof buf, "%s %.1f deg", name ? name : "joint", q[best] * 180 / M_PI);
    } else {
      std::snprintf(buf, sizeof buf, "%s %.4f m", name ? name : "joint", q[best]);
    }
    p.text = buf;
    chosen = p;
    chosen_span = *mx - *mn;
  }
  mju_copy(d->qpos, m->qpos0, m->nq);
  return chosen;
}

// Holds the pose before each physics step: the joint at q and every velocity zero; with a
// sweep period T > 0 the joint is driven instead, q(t) = q_short + (q_long - q_short)
// (1 - cos(2 pi t / T)) / 2, from the shortest tendon to the longest and back.
void Hold(const mjModel* m, mjData* d, const HeldPose& p, double period) {
  if (p.qadr < 0) return;
  mju_zero(d->qvel, m->nv);
  if (period > 0) {
    const double w = 2 * M_PI / period, span = p.q_long - p.q_short;
    d->qpos[p.qadr] = p.q_short + span * 0.5 * (1 - std::cos(w * d->time));
  } else {
    d->qpos[p.qadr] = p.q;
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
