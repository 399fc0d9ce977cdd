#include "sim/run_task.h"

#include <fmt/format.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "common/mujoco_load.h"
#include "common/mujoco_ptr.h"
#include "common/rng.h"
#include "control/kalman_estimator.h"
#include "control/recruitment_controller.h"
#include "estimation/filter_model.h"
#include "identification/model_cache.h"
#include "identification/plant_record.h"
#include "plugin/sma_host.h"
#include "sim/bundle_models.h"
#include "sim/force_sensor.h"
#include "sim/joint_loop.h"
#include "sim/metrics_stream.h"
#include "sim/plant.h"

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
  j["identification_seconds"] = identification_seconds;
  j["metrics"] = MetricsToJson(metrics);
  nlohmann::json steps_json = nlohmann::json::array();
  for (size_t k = 0; k < steps.size(); ++k) {
    const StepResponse& s = steps[k];
    steps_json.push_back({{"time", s.step.time},
                          {"from", s.step.from},
                          {"to", s.step.to},
                          {"end", s.step.end},
                          {"overshoot", s.overshoot},
                          {"settling_time", s.settling_time},
                          {"settled", s.settled}});
    if (k < step_joints.size()) steps_json.back()["joint"] = step_joints[k];
  }
  j["steps"] = steps_json;
  if (!pushes.empty()) {
    nlohmann::json ps = nlohmann::json::array();
    for (const DisturbanceResponse& d : pushes) {
      ps.push_back({{"start", d.window.start},
                    {"end", d.window.end},
                    {"peak_deviation", d.peak_deviation},
                    {"final_deviation", d.final_deviation}});
    }
    j["pushes"] = ps;
  }
  if (!joints.empty()) {
    nlohmann::json js = nlohmann::json::array();
    for (const JointSummary& x : joints) {
      js.push_back({{"joint", x.joint},
                    {"tracking_rmse", x.tracking_rmse},
                    {"iae", x.iae},
                    {"max_overshoot", x.max_overshoot},
                    {"settled_fraction", x.settled_fraction},
                    {"num_steps", x.num_steps}});
    }
    j["joints"] = js;
    j["loop_designs"] = loop_designs;
  }
  nlohmann::json bundles_json = nlohmann::json::array();
  for (const auto& b : bundles) {
    bundles_json.push_back({{"actuator", b.actuator},
                            {"estimator_rmse", b.estimator_rmse},
                            {"mean_nees", b.mean_nees},
                            {"estimator_within3", b.estimator_within3},
                            {"estimator_band", b.estimator_band},
                            {"estimator_within_band", b.estimator_within_band},
                            {"peak_temperature", b.peak_temperature},
                            {"peak_wire_stress", b.peak_wire_stress},
                            {"max_temperature", b.max_temperature},
                            {"max_wire_stress", b.max_wire_stress}});
    if (b.censuses) bundles_json.back()["censuses"] = *b.censuses;
  }
  j["bundles"] = bundles_json;
  j["sensor"] = sensor.ToJson();
  j["warnings"] = warnings;
  return j;
}

namespace {

// A count estimate's band for a bundle of n units: 3 units, or 5 % of n for a bundle of many.
double EstimatorBand(int n) { return std::max(3.0, 0.05 * n); }

// One bundle's controller side: its load cell and its recruitment controller (which owns the
// on-count estimator), and what it did at the control instants, for the scores.
struct Channel {
  ForceSensor sensor;
  control::RecruitmentController controller;
  EstimatorScoreAccumulator score;  // the estimate against the truth at the control instants
  SwitchingCounter switches;        // on-count after each broadcast
  // Control instants at which the reference needed more than the working units could give, and
  // at which the stuck units alone gave more (RecruitmentController::saturation; only estimators
  // that count failed units set it).
  long out_of_reach = 0, stuck_over = 0;
  long instants = 0;
  long censuses = 0;        // censuses whose counts reached the controller
  bool census_due = false;  // the controller asked for a census in this period
};

// What loading the plant's model warned of for its bundles, each text once.
std::vector<std::string> LoadWarnings(const Plant& plant) {
  std::vector<std::string> out;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    for (std::string& w : plant.host().LoadWarnings(plant.bundle_index(i))) {
      if (std::find(out.begin(), out.end(), w) == out.end()) out.push_back(std::move(w));
    }
  }
  return out;
}

Result<std::vector<Channel>> MakeChannels(const Task& task, const ControllerSettings& settings,
                                          const Plant& plant, const RunOptions& options,
                                          const std::string& where, double& identify_s,
                                          std::vector<std::string>& warnings) {
  auto spec = control::EstimatorSpec::Parse(settings.estimator, "extended", settings.filter_model,
                                            20, settings.force_noise_std);
  if (!spec.ok()) return Error{where + ".controller.estimator: " + spec.error(), spec.code()};
  if (settings.force_scale_variance > 0 && !spec->failures) {
    return Error{where + ".controller.force_scale_variance: " +
                 std::to_string(settings.force_scale_variance) +
                 "; allowed: 0 unless the estimator is kalman-failures (the one that estimates "
                 "the working units' force scale)"};
  }
  spec->failure.scale_variance = settings.force_scale_variance;
  if (settings.census_period > 0 && !spec->failures) {
    return Error{where + ".controller.census_period: " + fmt::format("{}", settings.census_period) +
                 "; allowed: 0 unless the estimator is kalman-failures (the one that reads a "
                 "census's counts)"};
  }
  const sma::SmaHost& host = plant.host();
  std::vector<Channel> channels;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const int b = plant.bundle_index(i);
    control::ControllerParams p;
    p.num_units = host.num_units(b);
    p.unit_force = host.SettledUnitForce(b);
    p.dT = settings.dT;
    p.lambda = settings.lambda;
    p.census_period = settings.census_period;
    // The estimator and the target follow the tendon's length (the joint encoder's reading).
    p.geometry = control::UnitGeometry{host.bundle(b).config().unit, host.unit_ref_length(b)};
    // A model identified on another plant (unit, geometry) is refused with both named.
    control::EstimatorSpec bundle_spec = *spec;
    bundle_spec.sensor_variance = task.sensor.Variance();
    bundle_spec.plant = identification::PlantRecord(host, b, task.model_path);
    if (bundle_spec.kind == control::EstimatorKind::kKalmanAugmented ||
        !bundle_spec.model_file.empty()) {
      auto file = BundleModelFile(task, settings, plant, i, options, bundle_spec, identify_s);
      if (!file) return Error{where + ".controller: " + file.error(), file.code()};
      bundle_spec.model_file = *file;
    }
    auto c = control::RecruitmentController::Create(p, bundle_spec);
    if (!c.ok()) return Error{where + ".controller: " + c.error(), c.code()};
    if (const auto* k = dynamic_cast<const control::KalmanOnCountEstimator*>(&c->estimator())) {
      IdentificationWarning(k->model(), host.bundle_name(b), warnings);
    }
    // Each load cell has its own noise stream derived from the run seed (the plugin's unit
    // streams use the seed itself).
    auto sensor =
        ForceSensor::Create(task.sensor, Rng::DeriveSeed(options.seed, kSensorStream + i));
    if (!sensor.ok()) return Error{where + ".sensor: " + sensor.error(), sensor.code()};
    channels.push_back({std::move(sensor).value(),
                        std::move(c).value(),
                        EstimatorScoreAccumulator(EstimatorBand(p.num_units)),
                        {}});
    channels.back().switches.Add(plant.OnCount(i));
  }
  return channels;
}

// Each bundle's unit force map (its controller's), for the loop design.
std::vector<UnitForce> UnitForces(const std::vector<Channel>& channels) {
  std::vector<UnitForce> out;
  for (const Channel& c : channels) {
    out.push_back([&c](double L) { return c.controller.OnUnitForce(L); });
  }
  return out;
}

// The force reference of each bundle at a control instant: the task's force reference for a
// force task; for an angle task the outer loop's net force, split into agonist and antagonist
// on top of their tone.
void ForceReferences(const Task& task, AngleLoop& loop, JointLoops* joints, const Plant& plant,
                     double t, double dT, std::vector<double>& force_ref) {
  if (joints != nullptr) {
    joints->Step(t, plant, force_ref);
    return;
  }
  const double r = task.reference(t);
  if (task.tracked == Tracked::kForce) {
    force_ref[0] = r;
    return;
  }
  const double limit = task.outer->max_force;
  const double u = loop.Step(r, plant.angle(), plant.angular_velocity(), dT, limit);
  if (plant.num_bundles() == 1) {
    force_ref[0] = std::clamp(task.outer->tone + u, 0.0, limit);
  } else {
    force_ref[0] = std::clamp(task.outer->tone + std::max(u, 0.0), 0.0, limit);
    force_ref[1] = std::clamp(task.outer->tone + std::max(-u, 0.0), 0.0, limit);
  }
}

// One control instant: each load cell samples its tendon's force and each encoder the tendon's
// length; the outer loop sets the force references and each bundle's controller estimates and
// broadcasts (or `hook` decides in their place, or records what they decided).
Status ControlInstantStep(const Task& task, AngleLoop& loop, JointLoops* joints, Plant& plant,
                          std::vector<Channel>& channels, double t, double dT,
                          ControlInstantHook* hook, ControlInstant& ci, std::vector<int>& on_before,
                          std::vector<double>& force_ref, TelemetrySample& sample) {
  const int nb = plant.num_bundles();
  ci.time = t;
  ci.reference = task.reference(t);
  ci.angle = plant.angle();
  ci.angular_velocity = plant.angular_velocity();
  ci.sensed_force.resize(nb);
  ci.tendon_length.resize(nb);
  ci.force_reference.resize(nb);
  ci.broadcast.resize(nb);
  ci.estimated_on.resize(nb);
  ci.estimated_on_variance.resize(nb);
  ci.estimated_working.assign(nb, std::numeric_limits<double>::quiet_NaN());
  on_before.resize(nb);  // the a-posteriori estimate is of the state before broadcasting
  for (int i = 0; i < nb; ++i) {
    on_before[i] = plant.OnCount(i);
    ci.sensed_force[i] = channels[i].sensor.SampleAndHold(plant.Force(i));
    ci.tendon_length[i] = plant.UnitLength(i);
  }
  if (hook != nullptr && hook->Replaces()) {
    if (joints != nullptr) {
      return Error{"a replacing control hook cannot drive \"outer_loop\": \"auto\""};
    }
    if (Status st = hook->OnInstant(ci); !st.ok()) return st;
    force_ref = ci.force_reference;
  } else {
    ForceReferences(task, loop, joints, plant, t, dT, force_ref);
    for (int i = 0; i < nb; ++i) {
      control::RecruitmentController& c = channels[i].controller;
      ci.force_reference[i] = force_ref[i];
      ci.broadcast[i] = c.Step(force_ref[i], ci.sensed_force[i], ci.tendon_length[i]);
      ci.estimated_on[i] = c.estimated_on();
      ci.estimated_on_variance[i] = c.estimated_on_variance();
      if (const auto f = c.estimator().Failures()) ci.estimated_working[i] = f->working;
      channels[i].out_of_reach += c.saturation() > 0;
      channels[i].stuck_over += c.saturation() < 0;
      ++channels[i].instants;
    }
    if (hook != nullptr) {
      if (Status st = hook->OnInstant(ci); !st.ok()) return st;
    }
  }
  for (int i = 0; i < nb; ++i) {
    const control::Broadcast& bc = ci.broadcast[i];
    if (Status st = plant.Broadcast(i, bc.p_on, bc.p_off); !st.ok()) return st;
    const double var = ci.estimated_on_variance[i];
    BundleTelemetry& bt = sample.bundles[i];
    bt.estimated_on = ci.estimated_on[i];
    bt.estimated_on_std = std::isfinite(var) ? std::sqrt(std::max(var, 0.0))
                                             : std::numeric_limits<double>::quiet_NaN();
    bt.p_on = bc.p_on;
    bt.p_off = bc.p_off;
    bt.force_reference = force_ref[i];
    bt.sensed_force = ci.sensed_force[i];
    if (!ci.estimated_working.empty()) bt.estimated_working = ci.estimated_working[i];
    channels[i].score.Add(bt.estimated_on, on_before[i], var);
  }
  return Status::Ok();
}

// The broadcast census (docs/failures.md section 5), as tests/control/failure_loop.h drives it.
// Before a control instant's Step: each bundle's last finished census not yet handed over goes to
// its controller, as unit counts with the shunt's variance.
void HandCensuses(const Plant& plant, std::vector<Channel>& channels) {
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const int b = plant.bundle_index(i);
    const auto reading = plant.host().LastCensus(plant.data(), b);
    if (reading.number <= channels[i].censuses) continue;
    channels[i].censuses = reading.number;
    const sma::SmaBundle& bundle = plant.host().bundle(b);
    const double unit = bundle.UnitCurrent();
    const double sd = bundle.config().census.noise / unit;
    channels[i].controller.Census(reading.on_current / unit, reading.off_current / unit,
                                  std::max(sd * sd, 1e-9));
  }
}

// Before a physics step: a census the controller asked for at the last instant starts so that
// it ends at the next one (its counts are then the state the controller decides on, fresh).
Status StartDueCensuses(Plant& plant, std::vector<Channel>& channels, double next_control) {
  const double t = plant.time(), h = plant.timestep();
  for (int i = 0; i < plant.num_bundles(); ++i) {
    if (!channels[i].census_due) continue;
    const int b = plant.bundle_index(i);
    const sma::CensusConfig& cc = plant.host().bundle(b).config().census;
    if (t + 0.5 * h < next_control - (cc.on + cc.off)) continue;
    if (Status st = plant.host().Census(plant.data(), b); !st.ok()) return st;
    channels[i].census_due = false;
  }
  return Status::Ok();
}

// The per-step telemetry observers see (the plant keeps each bundle's reads from one pass).
// `heat`: only the drawing observers use it (another pass over the units).
void FillTelemetry(const Plant& plant, double reference, double measured, bool heat,
                   const std::vector<Channel>& channels, TelemetrySample& sample) {
  sample.time = plant.time();
  sample.reference = reference;
  sample.measured = measured;
  sample.angle = plant.angle();
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const int b = plant.bundle_index(i);
    BundleTelemetry& bt = sample.bundles[i];
    bt.force = plant.Force(i);
    // Units switch only when a broadcast reaches them: the on-count is the one counted at the
    // last control instant (RunTask), and its fraction is worked out only then (~20 instructions).
    if (sample.control_instant) {
      bt.true_on = channels[i].switches.last();
      bt.on_fraction = static_cast<double>(bt.true_on) / plant.num_units(i);
    }
    bt.mean_temperature = plant.MeanTemperature(i);
    if (heat) bt.heat = plant.host().Heat(plant.data(), b);
  }
}

void Summarize(const Task& task, const Plant& plant, const SignalMetrics& sig,
               const std::vector<Channel>& channels, bool task_census, RunSummary& s) {
  const double duration = plant.time(), h = plant.timestep();
  RunMetrics& mt = s.metrics;
  mt.tracking_rmse = sig.TrackingRmse();
  mt.iae = sig.IntegralAbsoluteError(duration + h);
  s.steps = sig.StepResponses();
  s.pushes = sig.DisturbanceResponses();
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
  mt.oscillation = sig.ExcessTotalVariation();
  long units = 0;
  double rate = 0;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const int n = plant.num_units(i);
    rate += channels[i].switches.Rate(n, duration) * n;
    units += n;
  }
  mt.switching_rate = units > 0 ? rate / units : 0;
  s.sensor = task.sensor;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const Channel& ch = channels[i];
    const EstimatorScore es = ch.score.Score();
    const sma::UnitLimits& lim = plant.host().bundle(plant.bundle_index(i)).limits();
    BundleSummary bs;
    bs.actuator = plant.bundle_name(i);
    bs.estimator_rmse = es.rmse;
    bs.mean_nees = es.mean_nees;
    bs.estimator_within3 = es.within3;
    bs.estimator_band = ch.score.band();
    bs.estimator_within_band = es.within_band;
    bs.peak_temperature = plant.peak_temperature(i);
    bs.peak_wire_stress = plant.peak_wire_stress(i);
    bs.max_temperature = lim.max_temperature;
    bs.max_wire_stress = lim.max_wire_stress;
    if (task_census) bs.censuses = ch.censuses;
    s.bundles.push_back(bs);
    if (i == 0) {
      mt.estimator_rmse = es.rmse;
      mt.mean_nees = es.mean_nees;
      mt.estimator_within3 = es.within3;
    }
    char buf[320];
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
    if (ch.out_of_reach > 0) {
      std::snprintf(
          buf, sizeof buf,
          "%s: the reference needed more than the working units could give at %ld of "
          "%ld control instants (the law asked for every working unit there, without wind-up)",
          bs.actuator.c_str(), ch.out_of_reach, ch.instants);
      s.warnings.push_back(buf);
    }
    if (ch.stuck_over > 0) {
      std::snprintf(buf, sizeof buf,
                    "%s: the stuck units alone pulled more than the reference at %ld of %ld "
                    "control instants",
                    bs.actuator.c_str(), ch.stuck_over, ch.instants);
      s.warnings.push_back(buf);
    }
  }
}

JointSummary ScoreJoint(const std::string& joint, const SignalMetrics& sig, double t_end,
                        std::vector<StepResponse>& steps) {
  JointSummary js;
  js.joint = joint;
  js.tracking_rmse = sig.TrackingRmse();
  js.iae = sig.IntegralAbsoluteError(t_end);
  steps = sig.StepResponses();
  js.num_steps = static_cast<int>(steps.size());
  int settled = 0;
  for (const StepResponse& st : steps) {
    js.max_overshoot = std::max(js.max_overshoot, st.overshoot);
    settled += st.settled ? 1 : 0;
  }
  if (!steps.empty()) js.settled_fraction = static_cast<double>(settled) / steps.size();
  return js;
}

nlohmann::json DesignJson(const JointDesignRecord& r) {
  const control::LoopDesign& d = r.design;
  nlohmann::json unit_angle = nlohmann::json::object();
  for (const auto& [bundle, angle] : r.unit_angle) unit_angle[bundle] = angle * 180 / M_PI;
  return {{"joint", r.joint},
          {"reference", r.reference},
          {"inertia", r.dynamics.inertia},
          {"damping", r.dynamics.damping},
          {"stiffness", r.dynamics.stiffness},
          {"bundle_stiffness", r.bundle_stiffness},
          {"actuator_t63", r.actuator_t63},
          {"kp", d.gains.kp},
          {"ki", d.gains.ki},
          {"kd", d.gains.kd},
          {"predicted_overshoot", d.nominal.overshoot},
          {"predicted_settling_time", d.nominal.settling_time},
          {"robust_overshoot", d.robust.overshoot},
          {"robust_settled", d.robust.settled},
          {"meets", d.meets},
          {"note", d.note},
          {"unit_angle_deg", unit_angle}};
}

// Several driven joints: each scored on its own reference, and the run's metrics over all of
// their steps (RMSE: the root mean square over joints).
void SummarizeJoints(const Task& task, const Plant& plant, const SignalMetrics& first,
                     const std::vector<SignalMetrics>& more, const JointLoops& loops,
                     RunSummary& s) {
  const double t_end = plant.time() + plant.timestep();
  std::vector<StepResponse> all, steps;
  std::vector<std::string> names;
  double sq = 0, iae = 0, tv = 0;
  for (int j = 0; j < plant.num_joints(); ++j) {
    const SignalMetrics& sig = j == 0 ? first : more[j - 1];
    s.joints.push_back(ScoreJoint(plant.joint_name(j), sig, t_end, steps));
    sq += s.joints.back().tracking_rmse * s.joints.back().tracking_rmse;
    iae += s.joints.back().iae;
    tv += sig.ExcessTotalVariation();
    for (const StepResponse& st : steps) {
      all.push_back(st);
      names.push_back(plant.joint_name(j));
    }
  }
  s.loop_designs = nlohmann::json::array();
  for (const JointDesignRecord& r : loops.designs()) {
    s.loop_designs.push_back(DesignJson(r));
    // A pose the bundles hold unstably at constant counts drifts faster than they can follow.
    if (r.dynamics.stiffness <= 0) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "joint '%s' at %.4g deg: the bundles cannot hold this pose at constant "
                    "on-counts (stiffness %.3g N m/rad, the bundles' %.3g): the loop may not "
                    "settle there",
                    r.joint.c_str(), r.reference * 180 / M_PI, r.dynamics.stiffness,
                    r.bundle_stiffness);
      s.warnings.push_back(buf);
    }
    // A pose whose static torque is beyond the bundles: the loop gets as near as they go.
    if (!r.holding.holds()) {
      char buf[320];
      std::snprintf(buf, sizeof buf,
                    "joint '%s' at %.4g deg: the bundles cannot hold this pose (its static torque "
                    "%.3g N m, theirs at most %.3g N m with every unit that helps on)",
                    r.joint.c_str(), r.reference * 180 / M_PI, r.holding.static_torque,
                    r.holding.held_torque);
      s.warnings.push_back(buf);
    }
  }
  if (plant.num_joints() < 2) return;  // the one joint's metrics are already the run's
  RunMetrics& mt = s.metrics;
  mt.tracking_rmse = std::sqrt(sq / plant.num_joints());
  mt.iae = iae;
  mt.oscillation = tv;
  mt.num_steps = static_cast<int>(all.size());
  mt.overshoot = mt.max_overshoot = mt.settling_time = mt.settled_fraction = 0;
  int settled = 0;
  for (const StepResponse& st : all) {
    mt.overshoot += st.overshoot / all.size();
    mt.max_overshoot = std::max(mt.max_overshoot, st.overshoot);
    mt.settling_time += st.settling_time / all.size();
    settled += st.settled ? 1 : 0;
  }
  if (!all.empty()) mt.settled_fraction = static_cast<double>(settled) / all.size();
  s.steps = std::move(all);
  s.step_joints = std::move(names);
}

// Progress on stderr, at most about 5 updates per second of wall time.
class Progress {
 public:
  Progress(bool show, double duration, std::chrono::steady_clock::time_point start)
      : show_(show), duration_(duration), start_(start) {}
  void Update(long step, long num_steps, double t) {
    if (!show_ || step < next_step_) return;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    if (wall >= next_wall_) {
      std::fprintf(stderr, "\r  %.1f / %.1f s simulated (%3.0f %%)", t, duration_,
                   100.0 * step / num_steps);
      next_wall_ = wall + 0.2;
    }
    next_step_ = step + std::max(1L, num_steps / 1000);
  }
  void Done(double t) {
    if (show_) std::fprintf(stderr, "\r  %.1f / %.1f s simulated (100 %%)\n", t, duration_);
  }

 private:
  bool show_;
  double duration_;
  std::chrono::steady_clock::time_point start_;
  long next_step_ = 0;
  double next_wall_ = 0;
};

// With a census: every bundle whose model gives no census key gets the plugin's census block
// (census_noise at its default), set on its plugin instance in `xml`.
Status AddCensusKeys(const mjModel* m, std::string& xml) {
  auto host = sma::SmaHost::Create(m);
  if (!host.ok()) return Error{host.error(), host.code()};
  std::vector<std::string> done;
  for (int b = 0; b < (*host)->num_bundles(); ++b) {
    if ((*host)->bundle(b).config().census.given) continue;
    const char* instance = mj_id2name(m, mjOBJ_PLUGIN, m->actuator_plugin[(*host)->actuator_id(b)]);
    if (instance == nullptr) {
      return Error{"bundle '" + (*host)->bundle_name(b) +
                   "': its plugin instance has no name (name it: <instance name=\"...\">) "
                   "for the census keys"};
    }
    if (std::find(done.begin(), done.end(), instance) != done.end()) continue;
    done.push_back(instance);
    auto edited = SetPluginConfig(xml, instance, "census_noise",
                                  fmt::format("{}", sma::CensusConfig{}.noise));
    if (!edited.ok()) return edited.failure();
    xml = std::move(edited).value();
  }
  return Status::Ok();
}

// The plant of a task. With "failures", the model is the task's with each named bundle's
// failure keys set on its plugin instance, and with a census (controller.census_period > 0) the
// census keys AddCensusKeys sets; the model is written beside the original (so that relative
// includes and assets resolve as for the original) for the compiler and removed once loaded;
// `holder` keeps the task the plant reads (with that model's path). Without either,
// Plant::Create(task).
Result<std::unique_ptr<Plant>> CreatePlant(const Task& task, bool drawn, Task& holder) {
  const bool census = task.controller.census_period > 0;
  if (task.failures.empty() && !census) return Plant::Create(task, drawn);
  const std::string file_name = task.source.empty() ? task.name : task.source;
  const std::string where = file_name + (census ? "" : ".failures");
  auto text = ReadFile(task.model_path);
  if (!text.ok()) return Error{where + ": " + text.error(), text.code()};
  auto model = LoadModel(task.model_path);
  if (!model.ok()) return model.failure().In(where + ": ");
  const mjModel* m = model->get();
  std::string xml = std::move(text).value();
  std::vector<std::string> instances;  // of the bundles given failures, in the task's order
  for (const BundleFailures& f : task.failures) {
    const std::string fw = file_name + ".failures";
    const int id = mj_name2id(m, mjOBJ_ACTUATOR, f.actuator.c_str());
    if (id < 0 || m->actuator_plugin[id] < 0) {
      std::string bundles;
      for (int a = 0; a < m->nu; ++a) {
        if (m->actuator_plugin[a] < 0) continue;
        const char* n = mj_id2name(m, mjOBJ_ACTUATOR, a);
        bundles += (bundles.empty() ? "" : ", ") + std::string(n ? n : "?");
      }
      return Error{fw + "." + f.actuator + ": no SMA bundle '" + f.actuator + "' in '" +
                   task.model_path + "'; bundles: " + (bundles.empty() ? "none" : bundles)};
    }
    const char* instance = mj_id2name(m, mjOBJ_PLUGIN, m->actuator_plugin[id]);
    if (instance == nullptr) {
      return Error{fw + "." + f.actuator + ": its plugin instance has no name in '" +
                   task.model_path + "' (name it: <instance name=\"...\">)"};
    }
    if (std::find(instances.begin(), instances.end(), instance) != instances.end()) {
      return Error{fw + "." + f.actuator + ": its plugin instance '" + instance +
                   "' drives a bundle already given failures; give them once per instance"};
    }
    instances.push_back(instance);
    for (const auto& [key, value] : f.keys) {
      auto edited = SetPluginConfig(xml, instance, key, value);
      if (!edited.ok()) return edited.failure().In(fw + "." + f.actuator + ": ");
      xml = std::move(edited).value();
    }
  }
  if (census) {
    if (Status st = AddCensusKeys(m, xml); !st.ok()) {
      return Error{file_name + ".controller.census_period: " + st.error(), st.code()};
    }
  }
  namespace fs = std::filesystem;
  const fs::path original(task.model_path);
  const fs::path file =
      original.parent_path() / fmt::format(".{}.failures-{}-{}.xml", original.stem().string(),
                                           ::getpid(), ContentHash().Add(xml).Hex().substr(0, 12));
  if (Status st = WriteFileAtomically(file.string(), xml); !st.ok()) {
    return Error{where + ": cannot write the model with failure keys beside '" + task.model_path +
                     "': " + st.error(),
                 st.code()};
  }
  holder = task;
  holder.model_path = file.string();
  auto plant = Plant::Create(holder, drawn);
  std::error_code ec;
  fs::remove(file, ec);
  if (!plant.ok()) return Error{where + ": " + plant.error(), plant.code()};
  return plant;
}

}  // namespace

Result<std::vector<JointDesignRecord>> DesignTaskLoops(const Task& task,
                                                       const RunOptions& options) {
  const std::string where = task.source.empty() ? task.name : task.source;
  if (!task.auto_loop) {
    return Error{where + ".outer_loop: only a task with \"outer_loop\": \"auto\" designs its loop"};
  }
  const ControllerSettings settings = EffectiveSettings(task, options);
  Task holder;
  auto plant_or = CreatePlant(task, /*drawn=*/false, holder);
  if (!plant_or.ok()) return Error{plant_or.error(), plant_or.code()};
  Plant& plant = **plant_or;
  plant.Reset(options.seed);
  double identify_s = 0;
  std::vector<std::string> warnings;
  auto channels = MakeChannels(task, settings, plant, options, where, identify_s, warnings);
  if (!channels.ok()) return Error{channels.error(), channels.code()};
  auto responses =
      ActuatorResponses(task, settings, plant, *channels, options, identify_s, warnings);
  if (!responses) return Error{where + ".outer_loop: " + responses.error(), responses.code()};
  auto loops = JointLoops::Create(task, plant, std::move(responses).value(), UnitForces(*channels),
                                  settings.dT);
  if (!loops) return Error{where + ".outer_loop: " + loops.error(), loops.code()};
  const double duration = options.duration ? *options.duration : task.duration;
  std::vector<JointDesignRecord> out;
  for (int j = 0; j < plant.num_joints(); ++j) {
    std::vector<double> times{0};
    for (const ReferenceStep& st : task.joints[j].reference.Steps(duration)) {
      times.push_back(st.time);
    }
    std::vector<double> done;
    double from = plant.JointAngle(j);  // the limb at rest where the run starts
    for (double t : times) {
      const Eigen::VectorXd r = loops->LoopReference(plant, t + 1e-9);
      const double step = r[j] - from;
      from = r[j];
      if (std::find(done.begin(), done.end(), r[j]) != done.end()) continue;
      done.push_back(r[j]);
      auto rec = loops->Design(plant, j, r, step);
      if (!rec) return Error{where + ": " + rec.error(), rec.code()};
      out.push_back(std::move(rec).value());
    }
  }
  return out;
}

Result<std::vector<BundleController>> TaskControllers(const Task& task, const RunOptions& options) {
  const std::string where = task.source.empty() ? task.name : task.source;
  const ControllerSettings settings = EffectiveSettings(task, options);
  Task holder;
  auto plant_or = CreatePlant(task, /*drawn=*/false, holder);
  if (!plant_or.ok()) return plant_or.failure();
  Plant& plant = **plant_or;
  plant.Reset(options.seed);
  double identify_s = 0;
  std::vector<std::string> warnings;
  auto channels = MakeChannels(task, settings, plant, options, where, identify_s, warnings);
  if (!channels.ok()) return channels.failure();
  std::vector<BundleController> out;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    out.push_back({plant.bundle_name(i), std::move((*channels)[i].controller)});
  }
  return out;
}

// The block diagram: at each control instant (every dT) the outer loop sets each bundle's force
// reference, its load cell and encoder are sampled and its controller broadcasts; then the plant
// steps (disturbances, physics) and the signals are recorded.
Result<RunSummary> RunTask(const Task& task, const RunOptions& options,
                           const std::vector<StepObserver*>& observers) {
  const auto wall_start = std::chrono::steady_clock::now();
  const std::string where = task.source.empty() ? task.name : task.source;
  const ControllerSettings settings = EffectiveSettings(task, options);
  const double duration = options.duration ? *options.duration : task.duration;
  if (!(duration > 0)) return Error{where + ": duration must be > 0 s"};
  RECRUIT_TRY(control::CheckDT(settings.dT, where + ": controller"));
  if (!(settings.lambda > 0 && settings.lambda <= 1)) {
    return Error{where + ": controller.lambda must be in (0, 1]"};
  }

  const bool draws = std::any_of(observers.begin(), observers.end(),
                                 [](const StepObserver* o) { return o->Draws(); });
  Task holder;
  auto plant_or = CreatePlant(task, /*drawn=*/draws, holder);
  if (!plant_or.ok()) return Error{plant_or.error(), plant_or.code()};
  Plant& plant = **plant_or;
  plant.Reset(options.seed);
  double identify_s = 0;  // time spent identifying filter models, left out of wall_seconds
  // Every warning of the run, in its summary: what loading the model warned of (design limits,
  // fit), the identified models' quality, then the limits the run exceeded.
  std::vector<std::string> warnings = LoadWarnings(plant);
  auto channels_or = MakeChannels(task, settings, plant, options, where, identify_s, warnings);
  if (!channels_or.ok()) return Error{channels_or.error(), channels_or.code()};
  std::vector<Channel>& channels = *channels_or;
  const int nb = plant.num_bundles();
  AngleLoop angle_loop;
  if (task.outer) angle_loop.gains = *task.outer;
  std::optional<JointLoops> joint_loops;
  if (task.auto_loop) {
    auto responses =
        ActuatorResponses(task, settings, plant, channels, options, identify_s, warnings);
    if (!responses) return Error{where + ".outer_loop: " + responses.error(), responses.code()};
    auto loops = JointLoops::Create(task, plant, std::move(responses).value(), UnitForces(channels),
                                    settings.dT);
    if (!loops) return Error{where + ".outer_loop: " + loops.error(), loops.code()};
    joint_loops = std::move(loops).value();
  }
  // Steps are scored up to a push; each push's response is scored on its own.
  std::vector<double> push_starts;
  for (const Push& p : task.pushes) push_starts.push_back(p.start);
  // Joints after the first score against their own references (the first is `measured`).
  std::vector<SignalMetrics> more_joints;
  for (int j = 1; j < plant.num_joints(); ++j) {
    more_joints.emplace_back(
        StepsUntilDisturbances(task.joints[j].reference.Steps(duration), push_starts),
        task.settle_band);
  }

  TelemetrySample sample;
  sample.reference_unit = task.tracked == Tracked::kForce ? "N" : "rad";
  sample.bundles.resize(nb);
  for (int j = 1; j < plant.num_joints(); ++j) sample.joints.push_back({plant.joint_name(j)});
  for (int i = 0; i < nb; ++i) {
    sample.bundles[i].actuator = plant.bundle_name(i);
    sample.bundles[i].tendon_id = plant.host().tendon_id(plant.bundle_index(i));
    sample.bundles[i].estimated_on = std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> force_ref(nb, 0.0);
  ControlInstant instant;
  std::vector<int> on_before;
  const double h = plant.timestep();
  const long num_steps = std::lround(duration / h);
  // The metrics accumulate as the run goes: memory does not grow with its length.
  const std::vector<ReferenceStep> steps = task.reference.Steps(duration);
  SignalMetrics sig(StepsUntilDisturbances(steps, push_starts), task.settle_band,
                    DisturbanceWindows(push_starts, steps, duration));
  auto measured = [&]() {
    return task.tracked == Tracked::kForce ? plant.Force(0) : plant.angle();
  };
  // The references read after every step, at increasing times: each cursor keeps the segment
  // the last read fell in (the same values as the references give).
  ReferenceCursor reference(task.reference);
  std::vector<ReferenceCursor> joint_references;
  for (int j = 1; j < plant.num_joints(); ++j) {
    joint_references.emplace_back(task.joints[j].reference);
  }

  const bool census = settings.census_period > 0;
  long control_instants = 0;
  double next_control = 0;
  Progress progress(options.progress, duration, wall_start);
  for (long step = 0; step < num_steps; ++step) {
    const double t = plant.time();
    sample.control_instant = t + 0.5 * h >= next_control;
    if (sample.control_instant) {
      // The controller's clock is its own: the instant is k dT, not MuJoCo's accumulated time
      // (20 s is 19.999999999999794 after 10^4 steps of 2 ms, which would read a step's
      // reference one period late).
      const double instant_time = next_control;
      ++control_instants;
      next_control = control_instants * settings.dT;
      if (census) HandCensuses(plant, channels);
      if (Status st =
              ControlInstantStep(task, angle_loop, joint_loops ? &*joint_loops : nullptr, plant,
                                 channels, instant_time, settings.dT, options.control_hook, instant,
                                 on_before, force_ref, sample);
          !st.ok()) {
        return Error{where + ": " + st.error(), st.code()};
      }
      sample.p_on = sample.bundles[0].p_on;
      sample.p_off = sample.bundles[0].p_off;
      for (Channel& c : channels) c.census_due = census && c.controller.census();
    }
    if (census) {
      if (Status st = StartDueCensuses(plant, channels, next_control); !st.ok()) {
        return Error{where + ": " + st.error(), st.code()};
      }
    }
    plant.Step();

    const double y = measured();
    const double r = reference(plant.time());
    sig.Add(plant.time(), r, y);
    for (int j = 1; j < plant.num_joints(); ++j) {
      JointTelemetry& jt = sample.joints[j - 1];
      jt.reference = joint_references[j - 1](plant.time());
      jt.angle = plant.JointAngle(j);
      more_joints[j - 1].Add(plant.time(), jt.reference, jt.angle);
    }
    // Units switch only when a broadcast reaches them, so the on-counts change only at control
    // instants: counted there (after the broadcast took effect) for the switching rate.
    if (sample.control_instant) {
      for (int i = 0; i < nb; ++i) channels[i].switches.Add(plant.OnCount(i));
    }
    if (!observers.empty()) {
      FillTelemetry(plant, r, y, draws, channels, sample);
      for (StepObserver* o : observers) {
        if (Status st = o->OnStep(plant.model(), plant.data(), sample); !st.ok()) {
          return Error{st.error(), st.code()};
        }
      }
    }
    if (Status st = plant.CheckFinite(); !st.ok())
      return Error{where + ": " + st.error(), st.code()};
    progress.Update(step, num_steps, plant.time());
  }
  progress.Done(plant.time());
  for (StepObserver* o : observers) {
    if (Status st = o->Finish(); !st.ok()) return Error{st.error(), st.code()};
  }

  RunSummary s;
  s.task = task.name;
  s.estimator = settings.estimator;
  s.dT = settings.dT;
  s.lambda = settings.lambda;
  s.seed = options.seed;
  s.duration = plant.time();
  s.physics_steps = num_steps;
  s.control_instants = control_instants;
  s.unit = sample.reference_unit;
  s.warnings = std::move(warnings);
  const size_t load_warnings = s.warnings.size();  // already printed when the model loaded
  Summarize(task, plant, sig, channels, settings.census_period > 0, s);
  if (joint_loops) SummarizeJoints(task, plant, sig, more_joints, *joint_loops, s);
  s.identification_seconds = identify_s;
  for (size_t k = load_warnings; k < s.warnings.size(); ++k) {
    std::fprintf(stderr, "warning: %s\n", s.warnings[k].c_str());
  }
  s.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count() -
      identify_s;
  return s;
}

}  // namespace recruit::sim
