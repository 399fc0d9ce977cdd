// A closed loop on the isometric bench (models/isometric_bench.xml, 60 units) whose units fail:
// the plugin's failure keys are added to the bundle's instance, the controller runs on the
// bench's exact force every dT, and every control instant is recorded with the plugin's true
// working/open/stuck counts. Used by tests/control/failure_loop_test.cc and by
// bench/failures/failure_measure.cc (the figures of docs/failures.md).
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "common/mujoco_load.h"
#include "common/result.h"
#include "control/recruitment_controller.h"
#include "plugin/sma_host.h"

namespace recruit::control::failure_loop {

struct Spec {
  // Extra plugin config as key=value tokens, e.g. "failures=60:6:open".
  std::string plant_config;
  EstimatorSpec estimator;
  double dT = 0.5, lambda = 0.2;
  std::uint64_t seed = 1;
  double duration = 120;                    // s
  std::function<double(double)> reference;  // N, at time t
  ExplorationParams exploration;            // the controller's (off by default)
  // The broadcast census every this many s (ControllerParams::census_period; 0 = none). The
  // plant's census keys come from plant_config; without any, census_noise=0.01 is added.
  double census_period = 0;
  // Where in the control period the census runs: right after the broadcast (false; its count
  // is then dT old when the estimator gets it) or ending at the next control instant (true).
  bool census_at_end = false;
};

struct Instant {
  double t = 0, reference = 0, force = 0;
  int on = 0, working = 0, open = 0, stuck = 0;  // truth
  double est_on = 0, est_on_var = 0;
  double est_working = 0, est_working_var = 0;  // N and 0 without a failure-aware estimator
  int saturation = 0;
  bool declared = false, exploring = false;
  bool census = false;   // a census's counts reached the estimator at this instant
  double suspicion = 0;  // the failure test's largest ratio
  // Fatigue: the plant's mean force scale over its heated working units (1 without fatigue or
  // with none heated) and the estimator's (FailureEstimate::force_scale).
  double scale = 1, est_scale = 1;
};

// The mean fatigue force scale (SmaBundle::UnitForceScale) of bundle b's heated working units.
inline double HeatedWorkingScale(const sma::SmaHost& p, const mjData* d, int b) {
  const double* s = p.State(d, b);
  double sum = 0;
  int n = 0;
  for (int i = 0; i < p.num_units(b); ++i) {
    if (p.bundle(b).UnitFailure(s, i) != 0 || !p.UnitOn(d, b, i)) continue;
    sum += p.bundle(b).UnitForceScale(s, i);
    ++n;
  }
  return n > 0 ? sum / n : 1.0;
}

// The bench's MJCF with `config` (key=value tokens) added to the bundle's instance.
inline Result<std::string> BenchXml(const std::string& config) {
  std::ifstream in(RECRUIT_SOURCE_DIR "/models/isometric_bench.xml");
  if (!in) return Error{"cannot read models/isometric_bench.xml"};
  std::stringstream buf;
  buf << in.rdbuf();
  std::string xml = buf.str();
  const std::string anchor = "<instance name=\"bundle_units\">";
  const auto at = xml.find(anchor);
  if (at == std::string::npos) return Error{"isometric_bench.xml: no bundle_units instance"};
  std::string extra;
  std::istringstream tokens(config);
  std::string token;
  while (tokens >> token) {
    const auto eq = token.find('=');
    if (eq == std::string::npos) return Error{"config token '" + token + "' is not key=value"};
    extra += "<config key=\"" + token.substr(0, eq) + "\" value=\"" + token.substr(eq + 1) + "\"/>";
  }
  xml.insert(at + anchor.size(), extra);
  return xml;
}

inline Result<std::vector<Instant>> Run(const Spec& spec) {
  std::string config = spec.plant_config;
  if (spec.census_period > 0 && config.find("census_") == std::string::npos) {
    config += " census_noise=0.01";
  }
  auto xml = BenchXml(config);
  if (!xml) return Error{xml.error()};
  auto model = LoadModelFromString(*xml);
  if (!model) return Error{model.error()};
  const mjModel* m = model->get();
  auto host = sma::SmaHost::Create(m);
  if (!host) return Error{host.error()};
  const sma::SmaHost& p = **host;
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  p.Reset(d.get(), spec.seed);
  mj_forward(m, d.get());
  ControllerParams params;
  params.num_units = p.num_units(0);
  params.unit_force = p.SettledUnitForce(0);
  params.dT = spec.dT;
  params.lambda = spec.lambda;
  params.exploration = spec.exploration;
  params.census_period = spec.census_period;
  auto c = RecruitmentController::Create(params, spec.estimator);
  if (!c) return Error{c.error()};
  const int steps = static_cast<int>(std::lround(spec.dT / m->opt.timestep));
  const int instants = static_cast<int>(std::lround(spec.duration / spec.dT));
  std::vector<Instant> out;
  out.reserve(instants);
  int censuses = 0;  // censuses handed to the controller
  for (int k = 0; k < instants; ++k) {
    Instant r;
    if (spec.census_period > 0) {
      const auto cr = p.LastCensus(d.get(), 0);
      if (cr.number > censuses) {  // the shunt's currents as unit counts
        censuses = cr.number;
        const double unit = p.bundle(0).UnitCurrent();
        const double sd = p.bundle(0).config().census.noise / unit;
        c->Census(cr.on_current / unit, cr.off_current / unit, std::max(sd * sd, 1e-9));
        r.census = true;
      }
    }
    r.t = d->time;
    r.reference = spec.reference(r.t);
    r.force = p.Force(d.get(), 0);
    r.on = p.OnCount(d.get(), 0);
    const auto f = p.Failures(d.get(), 0);
    r.working = f.working, r.open = f.open, r.stuck = f.stuck;
    r.scale = HeatedWorkingScale(p, d.get(), 0);
    const Broadcast b = c->Step(r.reference, r.force);
    r.est_on = c->estimated_on();
    r.est_on_var = c->estimated_on_variance();
    r.saturation = c->saturation();
    r.exploring = c->exploring();
    r.est_working = params.num_units;
    if (const auto fe = c->estimator().Failures()) {
      r.est_working = fe->working;
      r.est_working_var = fe->working_variance;
      r.declared = fe->declared;
      r.suspicion = fe->suspicion;
      r.est_scale = fe->force_scale;
    }
    out.push_back(r);
    if (Status s = p.Broadcast(d.get(), 0, b.p_on, b.p_off); !s) return Error{s.error()};
    const auto& cc = p.bundle(0).config().census;
    const int start =
        !c->census() ? -1
        : spec.census_at_end
            ? std::max(0, steps - static_cast<int>(std::lround((cc.on + cc.off) / m->opt.timestep)))
            : 0;
    for (int i = 0; i < steps; ++i) {
      if (i == start) {
        if (Status s = p.Census(d.get(), 0); !s) return Error{s.error()};
      }
      mj_step(m, d.get());
    }
  }
  return out;
}

// Mean |force - reference| over instants with t in [t0, t1), N.
inline double MeanError(const std::vector<Instant>& run, double t0, double t1) {
  double sum = 0;
  int n = 0;
  for (const Instant& r : run) {
    if (r.t >= t0 - 1e-9 && r.t < t1 - 1e-9) sum += std::abs(r.force - r.reference), ++n;
  }
  return n > 0 ? sum / n : NAN;
}

// Mean NEES of the on-count over instants from t0: (est - true)^2 / variance.
inline double MeanNees(const std::vector<Instant>& run, double t0 = 0) {
  double sum = 0;
  int n = 0;
  for (const Instant& r : run) {
    if (r.t < t0 - 1e-9 || !(r.est_on_var > 0)) continue;
    sum += (r.est_on - r.on) * (r.est_on - r.on) / r.est_on_var;
    ++n;
  }
  return n > 0 ? sum / n : NAN;
}

// Control instants from the first one that sees failed units (at or after t_fail) until the
// working estimate is within `tol` units of the truth; -1 if never.
inline int InstantsToFind(const std::vector<Instant>& run, double t_fail, double tol = 2) {
  int k = 0;
  for (const Instant& r : run) {
    if (r.t < t_fail - 1e-9 || r.open + r.stuck == 0) continue;
    if (std::abs(r.est_working - r.working) <= tol) return k;
    ++k;
  }
  return -1;
}

// Declarations before t (false alarms when nothing failed before t).
inline int DeclarationsBefore(const std::vector<Instant>& run, double t) {
  int n = 0;
  for (const Instant& r : run) n += r.t < t - 1e-9 && r.declared ? 1 : 0;
  return n;
}

}  // namespace recruit::control::failure_loop
