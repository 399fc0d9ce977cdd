// The failure figures of docs/failures.md, over seeds the tests do not use (they use 1-3):
//   build/bench/failures/failure_measure [first_seed=100] [seeds=40] [MODE [CONFIG]]
// On the isometric bench (60 units, dT 0.5 s, lambda 0.2), "kalman-failures" estimator. Without
// MODE every figure below; MODE "detect" (item 2: detect and quiet), "track" (item 3: track and
// reach), "cost", "fatigue [CONFIG]", "trace CONFIG" (one run, every instant from 55 s):
//   detect   10 % and 30 % of the units fail open at 60 s (15 N held): control instants until
//            the working estimate is within 2 units of the truth, by the lost units that were
//            heated; mean on-count NEES per run, also without the instants whose force is still
//            within one noise standard deviation of the same seed's run without the loss
//   quiet    no failure, 500 s of changing references: declared failures (false alarms) per
//            control instant; mean NEES per run; the failure test's largest ratio per run
//   track    10 % and 30 % open, or 10 % stuck, at 60 s: the excess |error| over the same seed
//            without the loss per 5 s window after it, and |error| 10-20 s and 20-40 s after
//   reach    30 % open at 60 s and a reference out of reach (22 N) from 70 s to 130 s, back to
//            15 N after: saturated instants, and |error| 20-40 s after the reference returns
//   cost     the exploration set by FAILURE_EXPLORE_* with no failure: |error| against none
//   fatigue  functional fatigue in the plant: the estimated force scale against the plant's
// The environment sets the estimator (FAILURE_GLR_*, FAILURE_*_HAZARD, FAILURE_SCALE_VARIANCE) and
// the controller's exploration (FAILURE_EXPLORE_*), see Failures() and Exploration() below.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/control/failure_loop.h"

namespace fl = recruit::control::failure_loop;
using recruit::control::EstimatorSpec;

namespace {

// The estimator's detection settings can be varied: FAILURE_GLR_H, FAILURE_GLR_WINDOW,
// FAILURE_GLR_MIN, FAILURE_GLR_STD,
// FAILURE_SETTLE_HAZARD, FAILURE_OPEN_HAZARD, FAILURE_SCALE_VARIANCE (defaults:
// FailureFilterParams).
EstimatorSpec Failures() {
  EstimatorSpec s = *EstimatorSpec::Parse("kalman-failures");
  auto env = [](const char* name, double& v) {
    if (const char* e = std::getenv(name)) v = std::atof(e);
  };
  env("FAILURE_GLR_H", s.failure.glr_threshold);
  env("FAILURE_GLR_MIN", s.failure.glr_min_count);
  env("FAILURE_GLR_STD", s.failure.glr_max_std);
  env("FAILURE_SETTLE_HAZARD", s.failure.settle_hazard);
  env("FAILURE_OPEN_HAZARD", s.failure.open_hazard);
  env("FAILURE_SCALE_VARIANCE", s.failure.scale_variance);
  if (const char* e = std::getenv("FAILURE_GLR_WINDOW")) s.failure.glr_window = std::atoi(e);
  return s;
}

// The controller's exploration (ControllerParams::exploration): FAILURE_EXPLORE_P (p_on, 0 =
// off), FAILURE_EXPLORE_N (instants), FAILURE_EXPLORE_SUSPICION, FAILURE_EXPLORE_PERIOD (s),
// FAILURE_EXPLORE_DECLARED (0/1).
recruit::control::ExplorationParams Exploration() {
  recruit::control::ExplorationParams e;
  auto env = [](const char* name, double& v) {
    if (const char* s = std::getenv(name)) v = std::atof(s);
  };
  env("FAILURE_EXPLORE_P", e.p_on);
  env("FAILURE_EXPLORE_SUSPICION", e.suspicion);
  env("FAILURE_EXPLORE_PERIOD", e.period);
  if (const char* s = std::getenv("FAILURE_EXPLORE_N")) e.instants = std::atoi(s);
  if (const char* s = std::getenv("FAILURE_EXPLORE_REST")) e.rest = std::atoi(s);
  if (const char* s = std::getenv("FAILURE_EXPLORE_UNMEASURED")) e.unmeasured = std::atoi(s);
  if (const char* s = std::getenv("FAILURE_EXPLORE_BALANCED")) e.balanced = std::atoi(s);
  if (const char* s = std::getenv("FAILURE_EXPLORE_DECLARED")) e.after_declaration = std::atoi(s);
  return e;
}

// Runs whose value lies in [lo, hi].
int Within(const std::vector<double>& v, double lo, double hi) {
  int n = 0;
  for (double x : v) n += x >= lo && x <= hi;
  return n;
}

// The broadcast census (ControllerParams::census_period): FAILURE_CENSUS_PERIOD (s, 0 = off)
// and the plant's census keys FAILURE_CENSUS_CONFIG (default: census_noise=0.01);
// FAILURE_CENSUS_END=1: each census ends at the next control instant (Spec::census_at_end).
double CensusPeriod() {
  const char* e = std::getenv("FAILURE_CENSUS_PERIOD");
  return e ? std::atof(e) : 0.0;
}

std::vector<fl::Instant> MustRun(fl::Spec s) {
  if (s.estimator.failures) s.exploration = Exploration();
  if (s.estimator.failures && CensusPeriod() > 0) {
    s.census_period = CensusPeriod();
    if (const char* e = std::getenv("FAILURE_CENSUS_END")) s.census_at_end = std::atoi(e) != 0;
    const char* c = std::getenv("FAILURE_CENSUS_CONFIG");
    s.plant_config += std::string(" ") + (c ? c : "census_noise=0.01");
  }
  auto r = fl::Run(s);
  if (!r) {
    std::fprintf(stderr, "%s\n", r.error().c_str());
    std::exit(1);
  }
  return *r;
}

double Quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  return v[static_cast<size_t>(q * (v.size() - 1) + 0.5)];
}

void Report(const char* what, const std::vector<double>& v) {
  std::printf("  %-44s median %7.3f  p10 %7.3f  p90 %7.3f  min %7.3f  max %7.3f  (n %zu)\n", what,
              Quantile(v, 0.5), Quantile(v, 0.1), Quantile(v, 0.9), Quantile(v, 0), Quantile(v, 1),
              v.size());
}

// The force model's noise standard deviation (N): sqrt(R) of models/identified/bench_n60_dt0.5_m20.
constexpr double kNoiseStd = 0.153;

// What a run with a loss at t_fail shares with the same seed without it (`base`): the heated
// units lost (the on counts differ by them at t_fail: same broadcasts and draws until then), the
// control instants from t_fail whose force is still within one noise standard deviation of that
// of `base` (the lost heaters' wires still cooling: no estimator can tell the loss yet), and the
// mean on-count NEES over the other instants.
struct Blind {
  int heated_lost = 0, instants = 0;
  double nees_seen = 0;
};
Blind BlindInstants(const std::vector<fl::Instant>& run, const std::vector<fl::Instant>& base,
                    double t_fail) {
  Blind b;
  double sum = 0;
  int n = 0;
  bool seen = false, counted = false;
  for (size_t i = 0; i < run.size() && i < base.size(); ++i) {
    const fl::Instant& r = run[i];
    if (r.t >= t_fail - 1e-9 && r.open + r.stuck > 0 && !counted) {  // the first that has it
      b.heated_lost = base[i].on - r.on;
      counted = true;
    }
    if (r.t >= t_fail - 1e-9 && !seen && std::abs(r.force - base[i].force) < kNoiseStd) {
      ++b.instants;
      continue;
    }
    if (r.t >= t_fail - 1e-9) seen = true;
    if (!(r.est_on_var > 0)) continue;
    sum += (r.est_on - r.on) * (r.est_on - r.on) / r.est_on_var;
    ++n;
  }
  b.nees_seen = n > 0 ? sum / n : NAN;
  return b;
}

// One census on the bench in open loop: 60 units, p_on 0.55 broadcast at 0 s, settled for 20 s,
// then (0.3, 0.3) broadcast and the census `delay` s later (delay 0: at the settled hold, before
// that broadcast): the state copied, the census run on one copy, both stepped 0.5 s (one control
// period). Returns the largest |force difference| (N).
double CensusPulse(const std::string& keys, double period, std::uint64_t seed, double delay) {
  auto xml = fl::BenchXml(keys);
  auto model = recruit::LoadModelFromString(*xml);
  if (!model) {
    std::fprintf(stderr, "%s\n", model.error().c_str());
    std::exit(1);
  }
  const mjModel* m = model->get();
  auto host = recruit::sma::SmaHost::Create(m);
  const recruit::sma::SmaHost& p = **host;
  mjData* a = mj_makeData(m);
  p.Reset(a, seed);
  (void)p.Broadcast(a, 0, 0.55, 0);
  for (int i = 0; i < 20000; ++i) mj_step(m, a);
  if (delay > 0) {
    (void)p.Broadcast(a, 0, 0.3, 0.3);
    for (int i = 0; i < std::lround(delay / m->opt.timestep); ++i) mj_step(m, a);
  }
  mjData* b = mj_copyData(nullptr, m, a);
  const recruit::sma::SmaBundle& bundle = p.bundle(0);
  const recruit::sma::UnitModel& u = bundle.unit();
  const auto& cc = bundle.config().census;
  const int n = p.num_units(0), on = p.OnCount(a, 0);
  double p_off_units = 0, p_on_units = 0;  // heating power of the off and the on units (W)
  for (int i = 0; i < n; ++i) {
    (p.UnitOn(a, 0, i) ? p_on_units : p_off_units) += u.HeatingPower(true, p.UnitXi(a, 0, i));
  }
  (void)p.Census(a, 0);
  const int on_steps = static_cast<int>(std::lround(cc.on / m->opt.timestep));
  const int off_end = on_steps + static_cast<int>(std::lround(cc.off / m->opt.timestep)) - 1;
  double max_df = 0, rise_off = 0, drop_on = 0;
  for (int k = 0; k < 500; ++k) {
    mj_step(m, a);
    mj_step(m, b);
    max_df = std::max(max_df, std::abs(p.Force(a, 0) - p.Force(b, 0)));
    for (int i = 0; k == on_steps - 1 && i < n; ++i) {
      if (!p.UnitOn(a, 0, i)) {
        rise_off = std::max(rise_off, p.UnitTemperature(a, 0, i) - p.UnitTemperature(b, 0, i));
      }
    }
    for (int i = 0; k == off_end && i < n; ++i) {
      if (p.UnitOn(a, 0, i)) {
        drop_on = std::min(drop_on, p.UnitTemperature(a, 0, i) - p.UnitTemperature(b, 0, i));
      }
    }
  }
  const double extra = p_off_units * cc.on - p_on_units * cc.off;  // J
  std::printf("census pulse (%s; on %.3g s, off %.3g s), %d of %d units on, seed %llu, %s:\n",
              keys.c_str(), cc.on, cc.off, on, n, static_cast<unsigned long long>(seed),
              delay > 0 ? ("census " + std::to_string(delay).substr(0, 4) +
                           " s after a (0.3, 0.3) broadcast")
                              .c_str()
                        : "settled hold");
  std::printf(
      "  largest rise of an off unit at the end of the on phase +%.4f K, largest drop "
      "of an on unit after the off phase %.4f K\n",
      rise_off, drop_on);
  std::printf(
      "  force disturbance: max |dF| %.3g N over 0.5 s, %.3g N at 0.5 s (force noise "
      "std %.3g N)\n",
      max_df, std::abs(p.Force(a, 0) - p.Force(b, 0)), kNoiseStd);
  std::printf(
      "  energy: %+.4f J per census (off units heated %.4f J, on units' off phase "
      "-%.4f J); the bundle heats at %.2f W, %.1f J per %.3g s census period: %+.3g %%\n",
      extra, p_off_units * cc.on, p_on_units * cc.off, p_on_units, p_on_units * period, period,
      100 * extra / (p_on_units * period));
  std::printf("  shunt: %.3g A per unit, noise %.3g A = %.3g units\n", bundle.UnitCurrent(),
              cc.noise, cc.noise / bundle.UnitCurrent());
  mj_deleteData(a);
  mj_deleteData(b);
  return max_df;
}

double Steps(double t) {  // 10, 20, 5, 15 N, every 25 s
  static const double level[] = {10, 20, 5, 15};
  return level[static_cast<int>(t / 25) % 4];
}

// A setting's price with no failure, on one seed: mean |error| 20-100 s at a 15 N hold and over
// 500 s of steps, with the setting (`with`) and without it (`without`, the same seed). `steps`
// keeps the steps run with it.
struct PairedCost {
  double hold = 0, hold0 = 0, steps = 0, steps0 = 0;
  std::vector<fl::Instant> steps_run;
};

PairedCost RunPairedCost(fl::Spec with, fl::Spec without) {
  PairedCost c;
  auto a = fl::Run(with), b = fl::Run(without);
  c.hold = fl::MeanError(*a, 20, 100);
  c.hold0 = fl::MeanError(*b, 20, 100);
  with.duration = without.duration = 500;
  with.reference = without.reference = Steps;
  a = fl::Run(with), b = fl::Run(without);
  c.steps = fl::MeanError(*a, 0, 500);
  c.steps0 = fl::MeanError(*b, 0, 500);
  c.steps_run = std::move(*a);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  const int first = argc > 1 ? std::atoi(argv[1]) : 100;
  const int seeds = argc > 2 ? std::atoi(argv[2]) : 40;
  // "detect": only the detection, false-alarm and NEES figures (item 2).
  const bool detect_only = argc > 3 && std::string(argv[3]) == "detect";
  // "trace CONFIG": one run of seed first_seed with the plant keys CONFIG (15 N held), every
  // control instant from 55 s printed.
  if (argc > 4 && std::string(argv[3]) == "trace") {
    const auto run = MustRun({argv[4],
                              Failures(),
                              0.5,
                              0.2,
                              static_cast<std::uint64_t>(first),
                              100,
                              [](double) { return 15.0; },
                              {}});
    std::printf(
        "t force on est_on var_on working est_working var_working declared susp expl census\n");
    for (const auto& r : run) {
      if (r.t < 55) continue;
      std::printf("%.1f %.2f %d %.2f %.2f %d %.2f %.2f %d %.1f %d %d\n", r.t, r.force, r.on,
                  r.est_on, r.est_on_var, r.working, r.est_working, r.est_working_var, r.declared,
                  r.suspicion, r.exploring, r.census);
    }
    return 0;
  }
  std::printf("seeds %d..%d, isometric bench, dT 0.5 s, lambda 0.2, kalman-failures\n", first,
              first + seeds - 1);
  const recruit::control::ExplorationParams explore = Exploration();
  if (explore.p_on > 0) {
    std::printf(
        "exploration: p_on %.3g (%s), %d instants, rest %d, after declaration %d, "
        "suspicion %.3g, period %.3g s\n",
        explore.p_on, explore.balanced ? "balanced" : "toggle", explore.instants, explore.rest,
        explore.after_declaration, explore.suspicion, explore.period);
  }
  // "cost": the exploration's price with no failure: mean |error| 20-100 s (15 N held) and over
  // 500 s of steps, with the exploration set by the environment and without it.
  if (argc > 3 && std::string(argv[3]) == "cost") {
    std::vector<double> hold, hold0, steps, steps0, frac;
    for (int s = first; s < first + seeds; ++s) {
      const auto seed = static_cast<std::uint64_t>(s);
      auto ref = [](double) { return 15.0; };
      const PairedCost c = RunPairedCost({"", Failures(), 0.5, 0.2, seed, 100, ref, explore},
                                         {"", Failures(), 0.5, 0.2, seed, 100, ref, {}});
      hold.push_back(c.hold);
      hold0.push_back(c.hold0);
      steps.push_back(c.steps);
      steps0.push_back(c.steps0);
      int n = 0;
      for (const auto& r : c.steps_run) n += r.exploring;
      frac.push_back(double(n) / c.steps_run.size());
    }
    Report("mean |error| 20-100 s at 15 N, exploring", hold);
    Report("the same seeds, no exploration", hold0);
    Report("mean |error| over 500 s of steps, exploring", steps);
    Report("the same seeds, no exploration", steps0);
    Report("fraction of instants exploring (steps)", frac);
    return 0;
  }

  // "census": the census's price. Open loop on the bench (about 33 of 60 units settled on):
  // the pulse's temperature change and force disturbance against a copy without it, and its
  // energy; closed loop with no failure: |error| with a census every FAILURE_CENSUS_PERIOD s
  // (default 2.5) against none, same seeds.
  if (argc > 3 && std::string(argv[3]) == "census") {
    const double period = CensusPeriod() > 0 ? CensusPeriod() : 2.5;
    const char* keys = std::getenv("FAILURE_CENSUS_CONFIG");
    double worst = 0;
    for (double delay : {0.0, 0.5, 1.0, 1.5, 2.0, 3.0}) {
      worst = std::max(worst, CensusPulse(keys ? keys : "census_noise=0.01", period,
                                          static_cast<std::uint64_t>(first), delay));
    }
    std::printf("largest force disturbance over these: %.3g N\n", worst);
    std::vector<double> hold, hold0, steps, steps0;
    for (int s = first; s < first + seeds; ++s) {
      const auto seed = static_cast<std::uint64_t>(s);
      auto ref = [](double) { return 15.0; };
      fl::Spec with{"", Failures(), 0.5, 0.2, seed, 100, ref, {}};
      with.census_period = period;
      const PairedCost c = RunPairedCost(with, {"", Failures(), 0.5, 0.2, seed, 100, ref, {}});
      hold.push_back(c.hold);
      hold0.push_back(c.hold0);
      steps.push_back(c.steps);
      steps0.push_back(c.steps0);
    }
    std::printf("closed loop, no failure, census every %.3g s:\n", period);
    Report("mean |error| 20-100 s at 15 N, census", hold);
    Report("the same seeds, no census", hold0);
    Report("mean |error| over 500 s of steps, census", steps);
    Report("the same seeds, no census", steps0);
    return 0;
  }

  // "fatigue [CONFIG]": functional fatigue in the plant (CONFIG, default below), 500 s of steps,
  // no failure; the force scale estimated (scale_variance FAILURE_SCALE_VARIANCE, default 1e-6)
  // against the plant's mean over its heated working units, and the same runs with the scale
  // fixed at 1.
  if (argc > 3 && std::string(argv[3]) == "fatigue") {
    const std::string config =
        argc > 4 ? argv[4] : "fatigue_loss=0.3 fatigue_cycles=30 fatigue_exponent=0";
    std::printf("fatigue: %s, 500 s of 10/20/5/15 N steps\n", config.c_str());
    EstimatorSpec scaled = Failures();
    if (!(scaled.failure.scale_variance > 0)) scaled.failure.scale_variance = 1e-6;
    std::printf("  scale_variance %.3g per control period\n", scaled.failure.scale_variance);
    std::vector<double> truth, err_end, err_mean, z2, decl_s, decl_f, track_s, track_f, nees_s,
        nees_f;
    for (int s = first; s < first + seeds; ++s) {
      const auto seed = static_cast<std::uint64_t>(s);
      const auto a = MustRun({config, scaled, 0.5, 0.2, seed, 500, Steps, {}});
      EstimatorSpec fixed = scaled;
      fixed.failure.scale_variance = 0;
      const auto b = MustRun({config, fixed, 0.5, 0.2, seed, 500, Steps, {}});
      truth.push_back(a.back().scale);
      err_end.push_back(a.back().est_scale - a.back().scale);
      double sum = 0;
      int n = 0;
      for (const auto& r : a) {
        if (r.t < 250) continue;
        sum += std::abs(r.est_scale - r.scale);
        ++n;
      }
      err_mean.push_back(sum / n);
      decl_s.push_back(fl::DeclarationsBefore(a, 1e9));
      decl_f.push_back(fl::DeclarationsBefore(b, 1e9));
      track_s.push_back(fl::MeanError(a, 250, 500));
      track_f.push_back(fl::MeanError(b, 250, 500));
      nees_s.push_back(fl::MeanNees(a));
      nees_f.push_back(fl::MeanNees(b));
    }
    Report("plant's force scale at 500 s (heated units)", truth);
    Report("estimate - plant at 500 s", err_end);
    Report("mean |estimate - plant| 250-500 s", err_mean);
    Report("declared failures per run, scale estimated", decl_s);
    Report("declared failures per run, scale fixed at 1", decl_f);
    Report("mean |error| 250-500 s (N), scale estimated", track_s);
    Report("mean |error| 250-500 s (N), scale fixed", track_f);
    Report("mean on-count NEES per run, scale estimated", nees_s);
    Report("mean on-count NEES per run, scale fixed", nees_f);
    return 0;
  }

  // "track": only the track and reach figures (item 3).
  const bool track_only = argc > 3 && std::string(argv[3]) == "track";
  if (!track_only) {
    // detect: 10 % and 30 % open at 60 s, 15 N held, and the same seeds without a loss
    std::vector<double> quiet_nees, quiet_working, quiet_suspicion;
    long quiet_instants = 0, false_alarms = 0;
    for (int lost : {6, 18}) {
      std::vector<double> found, nees_loss, nees_after, nees_later, error10;
      int within10 = 0, never = 0, at10 = 0;
      std::vector<double> blind, nees_seen;
      int by_heated[10][2] = {};  // runs and runs within 10 instants, by heated units lost
      std::string missed;         // seeds not within 2 units within 10 instants
      // FAILURE_LOSS_AT: the loss's time (s, default 60; e.g. 60.25, within a control period).
      const char* at = std::getenv("FAILURE_LOSS_AT");
      const std::string config =
          std::string("failures=") + (at ? at : "60") + ":" + std::to_string(lost) + ":open";
      for (int s = first; s < first + seeds; ++s) {
        fl::Spec spec{config,
                      Failures(),
                      0.5,
                      0.2,
                      static_cast<std::uint64_t>(s),
                      100,
                      [](double) { return 15.0; },
                      {}};
        const auto run = MustRun(spec);
        spec.plant_config = "";  // the same seed without the loss: the same run until 60 s
        const auto base = MustRun(spec);
        const int k = fl::InstantsToFind(run, 60);
        found.push_back(k);
        within10 += k >= 0 && k <= 10;
        const Blind b = BlindInstants(run, base, 60);
        blind.push_back(b.instants);
        nees_seen.push_back(b.nees_seen);
        const int h = std::min(b.heated_lost, 9);
        ++by_heated[h][0];
        by_heated[h][1] += k >= 0 && k <= 10;
        if (!(k >= 0 && k <= 10)) missed += " " + std::to_string(s);
        never += k < 0;
        nees_loss.push_back(fl::MeanNees(run));
        nees_after.push_back(fl::MeanNees(run, 60));
        nees_later.push_back(fl::MeanNees(run, 62.5));
        for (const auto& r : run) {  // 10 instants after the first that sees the loss (60 s)
          if (std::abs(r.t - 65) > 1e-9) continue;
          error10.push_back(std::abs(r.est_working - r.working));
          at10 += error10.back() <= 2;
        }
        false_alarms += fl::DeclarationsBefore(run, 60);
        quiet_instants += 120;
      }
      std::printf("detect: %d of 60 units open at 60 s, 15 N\n", lost);
      Report("instants to |working est - true| <= 2", found);
      std::printf("  within 10 instants: %d of %d runs (never: %d)\n", within10, seeds, never);
      if (!missed.empty()) std::printf("  not within 10 instants, seeds:%s\n", missed.c_str());
      std::printf("  by heated units lost at 60 s (runs: within 10 instants / of):");
      for (int h = 0; h < 10; ++h) {
        if (by_heated[h][0] > 0) {
          std::printf(" %d%s: %d/%d", h, h == 9 ? "+" : "", by_heated[h][1], by_heated[h][0]);
        }
      }
      std::printf("\n");
      Report("|working est - true| 10 instants after (65 s)", error10);
      std::printf("  within 2 units at 10 instants after: %d of %d runs\n", at10, seeds);
      Report("mean on-count NEES per run (0-100 s)", nees_loss);
      std::printf("  runs with mean NEES in [0.3, 2]: %d of %d\n", Within(nees_loss, 0.3, 2),
                  seeds);
      Report("blind instants (force within 0.153 N of no loss)", blind);
      Report("mean NEES per run without the blind instants", nees_seen);
      std::printf("  runs with it in [0.3, 2]: %d of %d\n", Within(nees_seen, 0.3, 2), seeds);
      Report("mean on-count NEES per run (60-100 s)", nees_after);
      Report("mean on-count NEES per run (62.5-100 s)", nees_later);
      std::printf("  runs with mean NEES (62.5-100 s) in [0.3, 2]: %d of %d\n",
                  Within(nees_later, 0.3, 2), seeds);
    }
    for (int s = first; s < first + seeds; ++s) {
      fl::Spec quiet{"", Failures(), 0.5, 0.2, static_cast<std::uint64_t>(s), 500, Steps, {}};
      const auto q = MustRun(quiet);
      false_alarms += fl::DeclarationsBefore(q, 1e9);
      double worst = 0;
      for (const auto& r : q) worst = std::max(worst, std::abs(r.est_working - r.working));
      quiet_working.push_back(worst);
      quiet_instants += static_cast<long>(q.size());
      quiet_nees.push_back(fl::MeanNees(q));
      double top = 0;
      for (const auto& r : q) top = std::max(top, r.suspicion);
      quiet_suspicion.push_back(top);
    }
    std::printf("quiet: no failure (500 s of 10/20/5/15 N steps, and the first 60 s above)\n");
    std::printf("  declared failures: %ld in %ld control instants (%.2g per instant)\n",
                false_alarms, quiet_instants, double(false_alarms) / quiet_instants);
    Report("mean on-count NEES per run", quiet_nees);
    std::printf("  runs with mean NEES in [0.3, 2]: %d of %d\n", Within(quiet_nees, 0.3, 2), seeds);
    Report("largest |working est - 60| per run", quiet_working);
    Report("largest failure-test ratio per run (suspicion)", quiet_suspicion);
  }
  if (detect_only) return 0;

  // track
  struct Case {
    const char* name;
    const char* config;
  };
  for (const Case& c :
       {Case{"10 % open", "failures=60:6:open"}, Case{"30 % open", "failures=60:18:open"},
        Case{"10 % stuck", "failures=60:6:stuck"}}) {
    std::vector<double> after, base, ratio, aug_after, nees, early, early_base;
    std::vector<double> diff[8];  // per 5 s window after the loss: |error| with - without
    for (int s = first; s < first + seeds; ++s) {
      auto ref = [](double) { return 15.0; };
      const auto f =
          MustRun({c.config, Failures(), 0.5, 0.2, static_cast<std::uint64_t>(s), 100, ref, {}});
      const auto n =
          MustRun({"", Failures(), 0.5, 0.2, static_cast<std::uint64_t>(s), 100, ref, {}});
      const auto a = MustRun({c.config,
                              *EstimatorSpec::Parse("kalman-augmented"),
                              0.5,
                              0.2,
                              static_cast<std::uint64_t>(s),
                              100,
                              ref,
                              {}});
      for (int w = 0; w < 8; ++w) {
        const double t0 = 60 + 5 * w;
        diff[w].push_back(fl::MeanError(f, t0, t0 + 5) - fl::MeanError(n, t0, t0 + 5));
      }
      early.push_back(fl::MeanError(f, 70, 80));
      early_base.push_back(fl::MeanError(n, 70, 80));
      after.push_back(fl::MeanError(f, 80, 100));
      base.push_back(fl::MeanError(n, 80, 100));
      aug_after.push_back(fl::MeanError(a, 80, 100));
      nees.push_back(fl::MeanNees(f));
    }
    std::printf("track: %s at 60 s, 15 N (|error| in N)\n", c.name);
    std::printf(
        "  mean over runs of |error| with the loss - without, per 5 s window (N, +- 2 SE):\n   ");
    for (int w = 0; w < 8; ++w) {
      double m = 0, v = 0;
      for (double x : diff[w]) m += x;
      m /= diff[w].size();
      for (double x : diff[w]) v += (x - m) * (x - m);
      const double se = std::sqrt(v / (diff[w].size() - 1) / diff[w].size());
      std::printf(" %d-%ds %+.3f+-%.3f", 5 * w, 5 * w + 5, m, 2 * se);
    }
    std::printf("\n");
    Report("mean |error| 70-80 s, with the loss", early);
    Report("mean |error| 70-80 s, same seeds, no loss", early_base);
    Report("mean |error| 80-100 s, with the loss", after);
    Report("mean |error| 80-100 s, same seeds, no loss", base);
    Report("80-100 s, kalman-augmented (unaware), loss", aug_after);
    Report("mean on-count NEES per run (kalman-failures)", nees);
  }

  // reach
  std::vector<double> saturated, recovered, base_rec, nees_reach;
  for (int s = first; s < first + seeds; ++s) {
    auto ref = [](double t) { return t >= 70 && t < 130 ? 22.0 : 15.0; };
    const auto f = MustRun(
        {"failures=60:18:open", Failures(), 0.5, 0.2, static_cast<std::uint64_t>(s), 180, ref, {}});
    const auto n = MustRun({"",
                            Failures(),
                            0.5,
                            0.2,
                            static_cast<std::uint64_t>(s),
                            180,
                            [](double) { return 15.0; },
                            {}});
    int sat = 0, total = 0;
    for (const auto& r : f) {
      if (r.t >= 80 && r.t < 130) sat += r.saturation == 1, ++total;
    }
    saturated.push_back(double(sat) / total);
    recovered.push_back(fl::MeanError(f, 150, 170));
    base_rec.push_back(fl::MeanError(n, 150, 170));
    nees_reach.push_back(fl::MeanNees(f));
  }
  std::printf("reach: 30 %% open at 60 s; 22 N (beyond 42 units) 70-130 s, then 15 N\n");
  Report("fraction of 80-130 s flagged saturated", saturated);
  Report("mean |error| 150-170 s, N", recovered);
  Report("same seeds, no loss, 15 N throughout", base_rec);
  Report("mean on-count NEES per run", nees_reach);
  return 0;
}
