#include "identification/plant_identification.h"

#include <algorithm>
#include <cmath>

#include "control/unit_force_map.h"
#include "identification/bench_recorder.h"
#include "identification/excitation.h"
#include "identification/model_export.h"

namespace recruit::control {
namespace {

Excitation ExcitationFor(const PlantIdentificationOptions& o, double duration, std::uint64_t seed) {
  const int total = static_cast<int>(duration / o.dT + 0.5);
  const int settle = std::max(2, static_cast<int>(o.settle / o.dT + 0.5));
  return MakeExcitation(settle, total, seed);
}

// R^2 and RMSE of the mean force the chain and the map predict for a recording held at another
// length (the realized switching fractions as inputs, as in the fit).
FitMetrics CheckAtLength(const TransientChain& chain, const UnitForceMap& map,
                         const BenchRecording& rec) {
  const SwitchingLog& log = rec.log;
  const int m = chain.num_states();
  Eigen::RowVectorXd h(m);
  map.Forces(rec.tendon_length, h);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m), predicted(log.size());
  x[chain.cold()] = log.num_units;
  for (int k = 0; k < log.size(); ++k) {
    predicted[k] = h.dot(x);
    chain.PropagateMean(log.InputOn(k), log.InputOff(k), x);
  }
  return Score(predicted, log, 0, log.size());
}

}  // namespace

nlohmann::json MetricsJson(const FitMetrics& m) {
  return {{"samples", m.samples}, {"rmse_N", m.rmse}, {"r2", m.r2}};
}

Result<PlantIdentification> IdentifyOnPlant(const std::string& model_path,
                                            const std::string& actuator,
                                            const PlantIdentificationOptions& o,
                                            const std::string& command) {
  if (!(o.dT > 0) || !(o.duration > 0) || !(o.settle > 0) || !(o.check_duration > 0)) {
    return Error{"identify: dT, duration, settle and check duration must be > 0 s"};
  }
  auto rec = RecordBench(model_path, actuator, ExcitationFor(o, o.duration, o.seed), o.dT, o.seed);
  if (!rec) return Error{rec.error()};
  FitOptions fo;
  fo.num_states = o.num_states;
  fo.holdout_fraction = o.holdout;
  fo.smoothness = o.smoothness;
  auto fit = IdentifyTransientModel(rec->log, fo);
  if (!fit) return Error{fit.error()};
  const TransientChain& c = fit->chain;
  auto map = UnitForceMap::FromForces(rec->geometry, rec->stretch, c.force);
  if (!map) return Error{"identify: " + map.error()};

  PlantIdentification out;
  out.fit = *fit;
  out.log = rec->log;
  // The fitted forces become those of the fractions (>= 0, on the force law) at the pose.
  TransientChain exported = c;
  map->Forces(rec->tendon_length, exported.force);
  const FilterModel model =
      ToFilterModel(exported, rec->log.num_units, rec->log.dT, fit->force_noise_var);
  if (Status s = model.Validate("identified model"); !s) return Error{s.error()};

  nlohmann::json checks = nlohmann::json::array();
  if (!rec->pose.empty()) {
    for (size_t i = 0; i < o.check_places.size(); ++i) {
      RecordOptions ro;
      ro.length_place = o.check_places[i];
      const std::uint64_t seed = o.seed + 1 + i;
      auto chk = RecordBench(model_path, actuator, ExcitationFor(o, o.check_duration, seed), o.dT,
                             seed, ro);
      if (!chk) return Error{chk.error()};
      LengthCheck lc{chk->pose, chk->tendon_length, CheckAtLength(c, *map, *chk)};
      checks.push_back(
          {{"pose", lc.pose}, {"tendon_length_m", lc.tendon_length}, {"fit", MetricsJson(lc.fit)}});
      out.checks.push_back(lc);
    }
  }
  const Eigen::VectorXd& xi = map->fractions();
  nlohmann::json j = model.ToJson();
  j["identification"] = {
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
      {"R_N2", fit->force_noise_var},
      {"plant", rec->plant}};
  out.model = std::move(j);
  return out;
}

}  // namespace recruit::control
