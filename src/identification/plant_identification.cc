#include "identification/plant_identification.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "control/sampling_period.h"
#include "control/unit_force_map.h"
#include "identification/bench_recorder.h"
#include "identification/excitation.h"
#include "identification/model_export.h"
#include "identification/ordered_fractions.h"
#include "identification/settled_fraction.h"

namespace recruit::identification {
namespace {

Excitation ExcitationFor(const PlantIdentificationOptions& o, double duration, std::uint64_t seed) {
  const int total = static_cast<int>(duration / o.dT + 0.5);
  const int settle = std::max(2, static_cast<int>(o.settle / o.dT + 0.5));
  return MakeExcitation(settle, total, seed);
}

// The mean counts per state at each sample of a recording (realized switching fractions as
// inputs, as in the fit), one row per sample.
Eigen::MatrixXd MeanCounts(const TransientChain& chain, const SwitchingLog& log) {
  const int m = chain.num_states();
  Eigen::MatrixXd X(log.size(), m);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  x[chain.cold()] = log.num_units;
  for (int k = 0; k < log.size(); ++k) {
    X.row(k) = x.transpose();
    chain.PropagateMean(log.InputOn(k), log.InputOff(k), x);
  }
  return X;
}

// R^2 and RMSE of the mean force the chain and the map predict over samples [begin, end).
FitMetrics CheckAtLength(const TransientChain& chain, const control::UnitForceMap& map,
                         const BenchRecording& rec, int begin, int end) {
  const Eigen::MatrixXd X = MeanCounts(chain, rec.log);
  Eigen::RowVectorXd h(chain.num_states());
  Eigen::VectorXd predicted(rec.log.size());
  for (int k = 0; k < rec.log.size(); ++k) {
    map.Forces(rec.lengths[k], h);
    predicted[k] = h.dot(X.row(k));
  }
  return Score(predicted, rec.log, begin, end);
}

// The fractions that best fit the first `fraction` of every recording, the chain fixed:
// bounded Gauss-Newton (Levenberg-Marquardt damping) on sum_k (y_k - sum_i x_ki T(xi_i, s_k))^2
// from xi0. Recordings at several lengths and in motion pin what one length cannot: states
// slack at the longest tendon, and the stress each state's transformation sees in use. Cold and
// hot keep their fractions of xi0 (the settled ones, settled_fraction.h); every other state
// stays between them in the transient's order (OrderedFractions).
Eigen::VectorXd RefineFractions(const TransientChain& chain, const control::UnitForceMap& map0,
                                const std::vector<BenchRecording>& recs, double fraction) {
  const int m = chain.num_states();
  std::vector<bool> fixed(m, false);
  fixed[chain.cold()] = fixed[chain.hot()] = true;
  const sma::UnitModel& unit = map0.unit();
  std::vector<Eigen::MatrixXd> X;
  for (const auto& r : recs) X.push_back(MeanCounts(chain, r.log));
  auto cost_and_normal = [&](const Eigen::VectorXd& xi, Eigen::MatrixXd* JtJ, Eigen::VectorXd* g) {
    double cost = 0;
    if (JtJ) JtJ->setZero(m, m), g->setZero(m);
    Eigen::RowVectorXd row(m);
    for (size_t r = 0; r < recs.size(); ++r) {
      const int n = static_cast<int>(fraction * recs[r].log.size());
      for (int k = 0; k < n; ++k) {
        const double s = map0.Stretch(recs[r].lengths[k]);
        double predicted = 0;
        for (int i = 0; i < m; ++i) {
          double slope;
          predicted += X[r](k, i) * unit.Tension(xi[i], s, &slope);
          row[i] = X[r](k, i) * slope;
        }
        const double e = recs[r].log.force[k] - predicted;
        cost += e * e;
        for (int i = 0; i < m; ++i) {
          if (fixed[i]) row[i] = 0;  // no step along a fixed fraction
        }
        if (JtJ) {
          JtJ->noalias() += row.transpose() * row;
          *g -= e * row.transpose();  // gradient of cost / 2
        }
      }
    }
    return cost;
  };
  // Projected onto the order first (the identity metric), so every trial below keeps it.
  Eigen::VectorXd xi = OrderedFractions(chain, map0.fractions(), Eigen::MatrixXd::Identity(m, m),
                                        Eigen::VectorXd::Zero(m));
  Eigen::MatrixXd JtJ;
  Eigen::VectorXd g;
  double cost = cost_and_normal(xi, &JtJ, &g), damping = 1e-3;
  for (int it = 0; it < 30; ++it) {
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Eigen::MatrixXd M = JtJ;
      M.diagonal().array() += damping * (JtJ.diagonal().array() + 1e-9 * JtJ.trace() / m + 1e-12);
      for (int i = 0; i < m; ++i) {
        if (fixed[i]) M(i, i) = 1;  // its row and gradient are 0: the step leaves it
      }
      const Eigen::VectorXd trial = OrderedFractions(chain, xi, M, g);
      const double c = cost_and_normal(trial, nullptr, nullptr);
      if (c < cost) {
        const bool converged = cost - c < 1e-10 * cost;
        xi = trial;
        cost = cost_and_normal(xi, &JtJ, &g);
        damping = std::max(damping / 3, 1e-9);
        improved = true;
        if (converged) return xi;
      } else {
        damping *= 10;
      }
    }
    if (!improved) break;
  }
  return xi;
}

// `n` extensions evenly spread from the least to the greatest the recordings saw.
std::vector<double> StretchGrid(const control::UnitForceMap& map,
                                const std::vector<BenchRecording>& recs, int n) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const BenchRecording& r : recs) {
    for (double L : r.lengths) lo = std::min(lo, map.Stretch(L)), hi = std::max(hi, map.Stretch(L));
  }
  std::vector<double> grid;
  for (int i = 0; i < n; ++i) grid.push_back(lo + (hi - lo) * i / (n - 1));
  return grid;
}

}  // namespace

nlohmann::json MetricsJson(const FitMetrics& m) {
  return {{"samples", m.samples}, {"rmse_N", m.rmse}, {"r2", m.r2}};
}

Result<PlantIdentification> IdentifyOnPlant(const std::string& model_path,
                                            const std::string& actuator,
                                            const PlantIdentificationOptions& o,
                                            const std::string& command) {
  RECRUIT_TRY(control::CheckDT(o.dT, "identify"));
  if (!(o.duration > 0) || !(o.settle > 0) || !(o.check_duration > 0)) {
    return Error{"identify: duration, settle and check duration must be > 0 s"};
  }
  // 1-2. The chain and its forces, held at the longest tendon.
  auto rec = RecordBench(model_path, actuator, ExcitationFor(o, o.duration, o.seed), o.dT, o.seed);
  if (!rec) return Error{rec.error(), rec.code()};
  FitOptions fo;
  fo.num_states = o.num_states;
  fo.holdout_fraction = o.holdout;
  fo.smoothness = o.smoothness;
  auto fit = IdentifyTransientModel(rec->log, fo);
  if (!fit) return Error{fit.error(), fit.code()};
  const TransientChain& c = fit->chain;
  auto map = control::UnitForceMap::FromForces(rec->geometry, rec->stretch, c.force);
  if (!map) return Error{"identify: " + map.error(), map.code()};

  // 3. Recordings at other lengths and in motion (a limb only): the fractions refined on the
  // first part of every recording, the checks scored on the rest.
  std::vector<BenchRecording> recordings = {*rec};
  std::vector<std::string> poses;
  if (!rec->pose.empty()) {
    std::vector<RecordOptions> plan;
    for (double place : o.check_places) plan.push_back({place, 0.0});
    plan.push_back({1.0, o.sweep_period});
    for (size_t i = 0; i < plan.size(); ++i) {
      const std::uint64_t seed = o.seed + 1 + i;
      auto chk = RecordBench(model_path, actuator, ExcitationFor(o, o.check_duration, seed), o.dT,
                             seed, plan[i]);
      if (!chk) return Error{chk.error(), chk.code()};
      char moving[80];
      std::snprintf(moving, sizeof moving, "moving over the range, period %g s", o.sweep_period);
      poses.push_back(plan[i].sweep_period > 0 ? moving : chk->pose);
      recordings.push_back(std::move(chk).value());
    }
    // The settled states: a settled unit's fraction over the extensions recorded, not fitted.
    const std::vector<double> stretches = StretchGrid(*map, recordings, 5);
    Eigen::VectorXd xi0 = map->fractions();
    xi0[c.hot()] = SettledStateFraction(map->unit(), stretches, true);
    xi0[c.cold()] = SettledStateFraction(map->unit(), stretches, false);
    auto settled = control::UnitForceMap::FromFractions(rec->geometry, xi0);
    if (!settled) return Error{"identify: " + settled.error(), settled.code()};
    const double train = 1.0 - o.holdout;
    auto refined = control::UnitForceMap::FromFractions(
        rec->geometry, RefineFractions(c, *settled, recordings, train));
    if (!refined) return Error{"identify: " + refined.error(), refined.code()};
    map = std::move(refined);
  }

  PlantIdentification out;
  out.fit = *fit;
  out.log = rec->log;
  nlohmann::json checks = nlohmann::json::array();
  for (size_t i = 1; i < recordings.size(); ++i) {
    const int n = recordings[i].log.size();
    const int begin = static_cast<int>((1.0 - o.holdout) * n);
    LengthCheck lc{poses[i - 1], recordings[i].tendon_length,
                   CheckAtLength(c, *map, recordings[i], begin, n)};
    checks.push_back({{"pose", lc.pose}, {"holdout", MetricsJson(lc.fit)}});
    out.checks.push_back(lc);
  }
  // The exported H: the forces of the fractions at the recorded pose (>= 0, on the force law).
  TransientChain exported = c;
  map->Forces(rec->tendon_length, exported.force);
  // R with the forces the filter will use: a limb's settled forces are the force law's, not
  // the fit's (whose cold and hot states may sit a newton off to fit the transients better).
  if (!rec->pose.empty()) {
    const int train = static_cast<int>(std::lround(rec->log.size() * (1 - o.holdout)));
    out.fit.noise = FitNoiseModel(exported, rec->log, train, fit->force_noise_var, fo);
  }
  const NoiseModel& noise = out.fit.noise;
  const estimation::FilterModel model = ToFilterModel(exported, rec->log.num_units, rec->log.dT,
                                                      noise.r0, noise.r_transit, noise.r_transit2);
  if (Status s = model.Validate("identified model"); !s) return Error{s.error(), s.code()};
  const Eigen::VectorXd& xi = map->fractions();
  nlohmann::json j = model.ToJson();
  j["identification"] = {
      {"version", kIdentificationVersion},
      {"command", command},
      {"source", model_path},
      {"dT", rec->log.dT},
      {"num_units", rec->log.num_units},
      {"settled_unit_force_N", rec->unit_force},
      {"pose", rec->pose},
      {"tendon_length_m", rec->tendon_length},
      {"stretch", rec->stretch},
      {"output_fractions", std::vector<double>(xi.data(), xi.data() + xi.size())},
      {"heat_advance",
       std::vector<double>(c.heat_advance.data(), c.heat_advance.data() + c.heat_advance.size())},
      {"cool_advance",
       std::vector<double>(c.cool_advance.data(), c.cool_advance.data() + c.cool_advance.size())},
      {"train", MetricsJson(fit->train)},
      {"holdout", MetricsJson(fit->holdout)},
      {"two_state_holdout", MetricsJson(fit->two_state_holdout)},
      {"length_checks", checks},
      {"R_N2", noise.r0},
      {"R_transit_N2", noise.r_transit},
      {"R_transit2_N2", noise.r_transit2},
      {"R_constant_N2", fit->force_noise_var},
      {"plant", rec->plant}};
  out.model = std::move(j);
  return out;
}

}  // namespace recruit::identification
