#include "sim/run_task.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>

#include "common/mujoco_ptr.h"
#include "common/rng.h"
#include "sim/force_sensor.h"

#if RECRUIT_CONTROL_AVAILABLE && RECRUIT_SMA_AVAILABLE
#include "control/recruitment_controller.h"
#include "identification/model_cache.h"
#include "identification/plant_record.h"
#include "plugin/sma_host.h"
#define RECRUIT_SIM_CLOSED_LOOP 1
#endif

namespace recruit::sim {
namespace {

// Index of the load cells' noise streams in Rng::DeriveSeed(run seed, index): apart from any
// stream the plugin or the sweep derives.
constexpr std::uint64_t kSensorStream = 0x5E750000;

// Outer loop state of an angle task (PI with anti-windup, derivative on the measured velocity).
struct AngleLoop {
  OuterLoop gains;
  double integral = 0;  // rad s

  // Net tendon force (N): positive pulls the agonist (flexor), negative the antagonist.
  double Step(double reference, double angle, double velocity, double dT, double limit) {
    const double e = reference - angle;
    // Gravity compensation at the reference pose: the force that holds the arm there.
    const double ff = gains.feedforward * std::sin(reference);
    const double unsat = gains.kp * e + gains.ki * (integral + e * dT) - gains.kd * velocity + ff;
    // Integrate only while the command is not saturated the same way (anti-windup).
    if (std::abs(unsat) < limit || unsat * e < 0) integral += e * dT;
    return gains.kp * e + gains.ki * integral - gains.kd * velocity + ff;
  }
};

}  // namespace

ControllerSettings EffectiveSettings(const Task& task, const RunOptions& options) {
  ControllerSettings s = task.controller;
  if (options.estimator) s.estimator = *options.estimator;
  if (options.filter_model) s.filter_model = *options.filter_model;
  if (options.dT) s.dT = *options.dT;
  if (options.lambda) s.lambda = *options.lambda;
  if (options.force_noise_std) s.force_noise_std = *options.force_noise_std;
  return s;
}

nlohmann::json RunSummary::ToJson() const {
  nlohmann::json j;
  j["task"] = task;
  j["estimator"] = estimator;
  j["dT"] = dT;
  j["lambda"] = lambda;
  j["seed"] = seed;
  j["duration"] = duration;
  j["unit"] = unit;
  j["physics_steps"] = physics_steps;
  j["control_instants"] = control_instants;
  j["wall_seconds"] = wall_seconds;
  const RunMetrics& m = metrics;
  j["metrics"] = {{"tracking_rmse", m.tracking_rmse},
                  {"iae", m.iae},
                  {"overshoot", m.overshoot},
                  {"max_overshoot", m.max_overshoot},
                  {"settling_time", m.settling_time},
                  {"settled_fraction", m.settled_fraction},
                  {"oscillation", m.oscillation},
                  {"switching_rate", m.switching_rate},
                  {"estimator_rmse", m.estimator_rmse},
                  {"mean_nees", m.mean_nees},
                  {"estimator_within3", m.estimator_within3},
                  {"num_steps", m.num_steps}};
  nlohmann::json steps_json = nlohmann::json::array();
  for (const auto& s : steps) {
    steps_json.push_back({{"time", s.step.time},
                          {"from", s.step.from},
                          {"to", s.step.to},
                          {"end", s.step.end},
                          {"overshoot", s.overshoot},
                          {"settling_time", s.settling_time},
                          {"settled", s.settled}});
  }
  j["steps"] = steps_json;
  nlohmann::json bundles_json = nlohmann::json::array();
  for (const auto& b : bundles) {
    bundles_json.push_back({{"actuator", b.actuator},
                            {"estimator_rmse", b.estimator_rmse},
                            {"mean_nees", b.mean_nees},
                            {"estimator_within3", b.estimator_within3},
                            {"peak_temperature", b.peak_temperature},
                            {"peak_wire_stress", b.peak_wire_stress},
                            {"max_temperature", b.max_temperature},
                            {"max_wire_stress", b.max_wire_stress}});
  }
  j["bundles"] = bundles_json;
  j["sensor"] = sensor.ToJson();
  j["warnings"] = warnings;
  return j;
}

#if !RECRUIT_SIM_CLOSED_LOOP
Result<RunSummary> RunTask(const Task& task, const RunOptions& options,
                           const std::vector<StepObserver*>& observers) {
  return Error{"RunTask: built without the SMA plugin and the controller"};
}
#else
Result<RunSummary> RunTask(const Task& task, const RunOptions& options,
                           const std::vector<StepObserver*>& observers) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::string where = task.source.empty() ? task.name : task.source;
  const ControllerSettings settings = EffectiveSettings(task, options);
  const double duration = options.duration ? *options.duration : task.duration;
  if (!(duration > 0)) return Error{where + ": duration must be > 0 s"};
  if (!(settings.dT > 0)) return Error{where + ": controller.dT must be > 0 s"};
  if (!(settings.lambda > 0 && settings.lambda <= 1)) {
    return Error{where + ": controller.lambda must be in (0, 1]"};
  }

  // Plant.
  char load_error[1000] = "";
  ModelPtr model(mj_loadXML(task.model_path.c_str(), nullptr, load_error, sizeof load_error));
  if (!model) {
    return Error{where + ".model: cannot load '" + task.model_path + "': " + load_error};
  }
  mjModel* m = model.get();
  if (task.timestep > 0) m->opt.timestep = task.timestep;
  const double h = m->opt.timestep;

  auto plugin_or = sma::SmaHost::Create(m);
  if (!plugin_or.ok()) return Error{where + ".model: " + plugin_or.error()};
  const sma::SmaHost& plugin = **plugin_or;

  std::vector<int> bundles;
  for (const std::string* name : {&task.agonist, &task.antagonist}) {
    if (name->empty()) continue;
    const int b = plugin.BundleIndex(*name);
    if (b < 0) {
      std::string have;
      for (int i = 0; i < plugin.num_bundles(); ++i) {
        have += (i ? ", " : "") + plugin.bundle_name(i);
      }
      return Error{where + "." + (name == &task.agonist ? "agonist" : "antagonist") + ": '" +
                   *name + "' is not an SMA bundle of '" + task.model_path +
                   "'; bundles: " + (have.empty() ? "none" : have)};
    }
    bundles.push_back(b);
  }
  const int nb = static_cast<int>(bundles.size());

  int joint = -1, qadr = -1, dadr = -1;
  if (!task.joint.empty()) {
    joint = mj_name2id(m, mjOBJ_JOINT, task.joint.c_str());
    if (joint < 0) {
      return Error{where + ".joint: no joint '" + task.joint + "' in '" + task.model_path + "'"};
    }
    if (m->jnt_type[joint] != mjJNT_HINGE) {
      return Error{where + ".joint: '" + task.joint + "' must be a hinge"};
    }
    qadr = m->jnt_qposadr[joint];
    dadr = m->jnt_dofadr[joint];
  }
  std::vector<int> push_body;
  for (size_t i = 0; i < task.pushes.size(); ++i) {
    const int id = mj_name2id(m, mjOBJ_BODY, task.pushes[i].body.c_str());
    if (id < 0) {
      return Error{where + ".pushes[" + std::to_string(i) + "].body: no body '" +
                   task.pushes[i].body + "' in '" + task.model_path + "'"};
    }
    push_body.push_back(id);
  }
  std::vector<int> payload_body;
  std::vector<bool> payload_done(task.payloads.size(), false);
  for (size_t i = 0; i < task.payloads.size(); ++i) {
    const int id = mj_name2id(m, mjOBJ_BODY, task.payloads[i].body.c_str());
    if (id <= 0) {
      return Error{where + ".payloads[" + std::to_string(i) + "].body: no body '" +
                   task.payloads[i].body + "' in '" + task.model_path + "'"};
    }
    payload_body.push_back(id);
  }
  auto apply_payloads = [&](double t) {
    for (size_t i = 0; i < task.payloads.size(); ++i) {
      if (payload_done[i] || t + 0.5 * h < task.payloads[i].time) continue;
      const int id = payload_body[i];
      // Scale the inertia with the mass: the payload keeps its shape.
      const double ratio = task.payloads[i].mass / m->body_mass[id];
      m->body_mass[id] = task.payloads[i].mass;
      for (int k = 0; k < 3; ++k) m->body_inertia[3 * id + k] *= ratio;
      payload_done[i] = true;
    }
  };
  apply_payloads(0);

  DataPtr data(mj_makeData(m));
  mjData* d = data.get();
  plugin.Reset(d, options.seed);
  mj_forward(m, d);

  // One recruitment controller per bundle.
  auto spec = control::EstimatorSpec::Parse(settings.estimator, "extended", settings.filter_model,
                                            20, settings.force_noise_std);
  if (!spec.ok()) return Error{where + ".controller.estimator: " + spec.error()};
  std::vector<control::RecruitmentController> controllers;
  for (int b : bundles) {
    control::ControllerParams p;
    p.num_units = plugin.num_units(b);
    p.unit_force = plugin.SettledUnitForce(b);
    p.dT = settings.dT;
    p.lambda = settings.lambda;
    // The estimator and the target follow the tendon's length (the joint encoder's reading).
    p.geometry = control::UnitGeometry{plugin.bundle(b).config().unit, plugin.ref_length(b)};
    // A model identified on another plant (unit, geometry) is refused with both named.
    control::EstimatorSpec bundle_spec = *spec;
    bundle_spec.sensor_variance = task.sensor.Variance();
    bundle_spec.plant = control::PlantRecord(plugin, b, task.model_path);
    // "{bundle}" in the model file name stands for the bundle's actuator name, so that each
    // bundle of a limb gets the model identified on it.
    const std::string key = "{bundle}";
    for (size_t at; (at = bundle_spec.model_file.find(key)) != std::string::npos;) {
      bundle_spec.model_file.replace(at, key.size(), plugin.bundle_name(b));
    }
    // No model named: the one identified on this bundle for this dT, from the model search path,
    // else identified now and cached (identification/model_cache.h).
    if (bundle_spec.kind == "kalman-augmented" && bundle_spec.model_file.empty()) {
      control::ModelRequest req{task.model_path, plugin.bundle_name(b), bundle_spec.plant,
                                settings.dT, bundle_spec.num_states};
      auto file = control::FindOrIdentifyModel(req, options.identify_missing_models,
                                               options.quiet ? nullptr : stderr);
      if (!file) return Error{where + ".controller: " + file.error()};
      bundle_spec.model_file = *file;
    }
    auto c = control::RecruitmentController::Create(p, bundle_spec);
    if (!c.ok()) return Error{where + ".controller: " + c.error()};
    controllers.push_back(std::move(c).value());
  }
  // One load cell per bundle, each with its own noise stream derived from the run seed (the
  // plugin's unit streams use the seed itself).
  std::vector<ForceSensor> sensors;
  for (int i = 0; i < nb; ++i) {
    auto sensor =
        ForceSensor::Create(task.sensor, Rng::DeriveSeed(options.seed, kSensorStream + i));
    if (!sensor.ok()) return Error{where + ".sensor: " + sensor.error()};
    sensors.push_back(std::move(sensor).value());
  }
  // Peaks of the units against their wire's datasheet limits.
  std::vector<double> peak_temperature(nb, -std::numeric_limits<double>::infinity());
  std::vector<double> peak_stress(nb, 0.0);
  auto track_peaks = [&]() {
    for (int i = 0; i < nb; ++i) {
      const sma::SmaBundle& bundle = plugin.bundle(bundles[i]);
      const double* state = plugin.State(d, bundles[i]);
      peak_temperature[i] = std::max(peak_temperature[i], bundle.MaxTemperature(state));
      peak_stress[i] =
          std::max(peak_stress[i], bundle.MaxWireStress(state, plugin.Stretch(d, bundles[i])));
    }
  };
  track_peaks();
  AngleLoop angle_loop;
  if (task.outer) angle_loop.gains = *task.outer;

  // Telemetry, filled in place every step.
  TelemetrySample sample;
  sample.reference_unit = task.tracked == Tracked::kForce ? "N" : "rad";
  sample.bundles.resize(nb);
  for (int i = 0; i < nb; ++i) {
    sample.bundles[i].actuator = plugin.bundle_name(bundles[i]);
    sample.bundles[i].tendon_id = plugin.tendon_id(bundles[i]);
    sample.bundles[i].estimated_on = std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> force_ref(nb, 0.0);

  // Signals for the metrics.
  const long num_steps = std::lround(duration / h);
  std::vector<double> ts, rs, ys;
  ts.reserve(num_steps);
  rs.reserve(num_steps);
  ys.reserve(num_steps);
  std::vector<std::vector<int> > on_counts(nb);
  for (int i = 0; i < nb; ++i) {
    on_counts[i].reserve(static_cast<size_t>(duration / settings.dT) + 2);
    on_counts[i].push_back(plugin.OnCount(d, bundles[i]));
  }
  // Per bundle, at control instants: the estimate, its variance and the true count.
  std::vector<std::vector<double> > est_on(nb), true_on(nb), est_var(nb);

  auto measured = [&]() {
    return task.tracked == Tracked::kForce ? plugin.Force(d, bundles[0]) : d->qpos[qadr];
  };

  long control_instants = 0;
  double next_control = 0;
  const bool show_progress = options.progress;
  long next_progress = 0;
  double next_progress_wall = 0;
  for (long step = 0; step < num_steps; ++step) {
    const double t = d->time;
    apply_payloads(t);
    sample.control_instant = false;
    if (t + 0.5 * h >= next_control) {
      // Control instant: sample, estimate, broadcast.
      sample.control_instant = true;
      ++control_instants;
      next_control = control_instants * settings.dT;
      const double r = task.reference(t);
      if (task.tracked == Tracked::kForce) {
        force_ref[0] = r;
      } else {
        const double limit = task.outer->max_force;
        const double u = angle_loop.Step(r, d->qpos[qadr], d->qvel[dadr], settings.dT, limit);
        if (nb == 1) {
          force_ref[0] = std::clamp(task.outer->tone + u, 0.0, limit);
        } else {
          force_ref[0] = std::clamp(task.outer->tone + std::max(u, 0.0), 0.0, limit);
          force_ref[1] = std::clamp(task.outer->tone + std::max(-u, 0.0), 0.0, limit);
        }
      }
      for (int i = 0; i < nb; ++i) {
        const int b = bundles[i];
        // The a-posteriori estimate is of the state at this instant, before its broadcast.
        const int on_before = plugin.OnCount(d, b);
        // The controller reads the load cell, not the plugin's exact tension.
        const double sensed = sensors[i].SampleAndHold(plugin.Force(d, b));
        // The encoder: the tendon's length follows the joint angle exactly (a known moment arm).
        const double length = d->ten_length[plugin.tendon_id(b)];
        const control::Broadcast bc = controllers[i].Step(force_ref[i], sensed, length);
        Status st = plugin.Broadcast(d, b, bc.p_on, bc.p_off);
        if (!st.ok()) return Error{where + ": " + st.error()};
        BundleTelemetry& bt = sample.bundles[i];
        bt.estimated_on = controllers[i].estimated_on();
        const double var = controllers[i].estimated_on_variance();
        bt.estimated_on_std = std::isfinite(var) ? std::sqrt(std::max(var, 0.0))
                                                 : std::numeric_limits<double>::quiet_NaN();
        bt.p_on = bc.p_on;
        bt.p_off = bc.p_off;
        bt.force_reference = force_ref[i];
        est_on[i].push_back(controllers[i].estimated_on());
        est_var[i].push_back(var);
        true_on[i].push_back(on_before);
      }
      sample.p_on = sample.bundles[0].p_on;
      sample.p_off = sample.bundles[0].p_off;
    }
    // Pushes act through xfrc_applied while active; several may share a body, so clear all
    // first and then add the active ones.
    for (size_t i = 0; i < task.pushes.size(); ++i) {
      for (int k = 0; k < 6; ++k) d->xfrc_applied[6 * push_body[i] + k] = 0;
    }
    for (size_t i = 0; i < task.pushes.size(); ++i) {
      const Push& p = task.pushes[i];
      if (t + 0.5 * h < p.start || t + 0.5 * h >= p.start + p.duration) continue;
      double* x = d->xfrc_applied + 6 * push_body[i];
      for (int k = 0; k < 3; ++k) {
        x[k] += p.force[k];
        x[3 + k] += p.torque[k];
      }
    }

    mj_step(m, d);
    track_peaks();

    const double y = measured();
    const double r = task.reference(d->time);
    ts.push_back(d->time);
    rs.push_back(r);
    ys.push_back(y);
    // Units switch only when a broadcast reaches them, so the on-counts change only at
    // control instants: sample them there (after the broadcast took effect) for the metrics.
    if (sample.control_instant) {
      for (int i = 0; i < nb; ++i) on_counts[i].push_back(plugin.OnCount(d, bundles[i]));
    }
    if (!observers.empty()) {
      sample.time = d->time;
      sample.reference = r;
      sample.measured = y;
      sample.angle = qadr >= 0 ? d->qpos[qadr] : 0.0;
      for (int i = 0; i < nb; ++i) {
        const int b = bundles[i];
        BundleTelemetry& bt = sample.bundles[i];
        bt.force = plugin.Force(d, b);
        bt.true_on = on_counts[i].back();
        bt.on_fraction = static_cast<double>(bt.true_on) / plugin.num_units(b);
        bt.mean_temperature = plugin.MeanTemperature(d, b);
        bt.heat = plugin.Heat(d, b);
      }
      for (StepObserver* o : observers) {
        Status st = o->OnStep(m, d, sample);
        if (!st.ok()) return Error{st.error()};
      }
    }
    for (int k = 0; k < m->nq; ++k) {
      if (!std::isfinite(d->qpos[k])) {
        return Error{where + ": the simulation diverged at t = " + std::to_string(d->time) +
                     " s (NaN in qpos); try a smaller timestep"};
      }
    }
    if (show_progress && step >= next_progress) {
      // At most about 5 updates per second of wall time.
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      if (wall >= next_progress_wall) {
        std::fprintf(stderr, "\r  %.1f / %.1f s simulated (%3.0f %%)", d->time, duration,
                     100.0 * step / num_steps);
        next_progress_wall = wall + 0.2;
      }
      next_progress = step + std::max(1L, num_steps / 1000);
    }
  }
  if (show_progress)
    std::fprintf(stderr, "\r  %.1f / %.1f s simulated (100 %%)\n", d->time, duration);
  for (StepObserver* o : observers) {
    Status st = o->Finish();
    if (!st.ok()) return Error{st.error()};
  }

  // Metrics.
  RunSummary s;
  s.task = task.name;
  s.estimator = settings.estimator;
  s.dT = settings.dT;
  s.lambda = settings.lambda;
  s.seed = options.seed;
  s.duration = d->time;
  s.physics_steps = num_steps;
  s.control_instants = control_instants;
  s.unit = sample.reference_unit;
  RunMetrics& mt = s.metrics;
  mt.tracking_rmse = TrackingRmse(rs, ys);
  mt.iae = IntegralAbsoluteError(ts, rs, ys, d->time + h);
  s.steps = StepResponses(ts, ys, task.reference.Steps(duration), task.settle_band);
  mt.num_steps = static_cast<int>(s.steps.size());
  int settled = 0;
  for (const auto& st : s.steps) {
    mt.overshoot += st.overshoot / s.steps.size();
    mt.max_overshoot = std::max(mt.max_overshoot, st.overshoot);
    mt.settling_time += st.settling_time / s.steps.size();
    settled += st.settled ? 1 : 0;
  }
  // A ratio of counts, so that "all settled" is exactly 1.
  if (!s.steps.empty()) mt.settled_fraction = static_cast<double>(settled) / s.steps.size();
  mt.oscillation = ExcessTotalVariation(rs, ys);
  long units = 0;
  double rate = 0;
  for (int i = 0; i < nb; ++i) {
    const int n = plugin.num_units(bundles[i]);
    rate += SwitchingRate(on_counts[i], n, d->time) * n;
    units += n;
  }
  mt.switching_rate = units > 0 ? rate / units : 0;
  s.sensor = task.sensor;
  for (int i = 0; i < nb; ++i) {
    const EstimatorScore es = ScoreEstimator(est_on[i], true_on[i], est_var[i]);
    const sma::UnitLimits& lim = plugin.bundle(bundles[i]).limits();
    BundleSummary bs;
    bs.actuator = plugin.bundle_name(bundles[i]);
    bs.estimator_rmse = es.rmse;
    bs.mean_nees = es.mean_nees;
    bs.estimator_within3 = es.within3;
    bs.peak_temperature = peak_temperature[i];
    bs.peak_wire_stress = peak_stress[i];
    bs.max_temperature = lim.max_temperature;
    bs.max_wire_stress = lim.max_wire_stress;
    s.bundles.push_back(bs);
    if (i == 0) {
      mt.estimator_rmse = es.rmse;
      mt.mean_nees = es.mean_nees;
      mt.estimator_within3 = es.within3;
    }
    char buf[200];
    if (bs.peak_temperature > lim.max_temperature) {
      std::snprintf(buf, sizeof buf, "%s: peak unit temperature %.1f C exceeds the limit %.1f C",
                    bs.actuator.c_str(), bs.peak_temperature, lim.max_temperature);
      s.warnings.push_back(buf);
    }
    if (bs.peak_wire_stress > lim.max_wire_stress) {
      std::snprintf(buf, sizeof buf, "%s: peak wire stress %.1f MPa exceeds the limit %.1f MPa",
                    bs.actuator.c_str(), bs.peak_wire_stress / 1e6, lim.max_wire_stress / 1e6);
      s.warnings.push_back(buf);
    }
  }
  for (const std::string& w : s.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  s.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return s;
}
#endif

}  // namespace recruit::sim
