// EstimatorSpec validation and MakeEstimator.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/data_path.h"
#include "control/failure_estimator.h"
#include "control/kalman_estimator.h"
#include "control/model_plant.h"
#include "control/on_count_estimator.h"
#include "control/output_estimator.h"
#include "control/sampling_period.h"
#include "estimation/filter_model.h"
#include "estimation/filter_model_cache.h"
#include "estimation/json_matrix.h"
#include "estimation/population_kalman_filter.h"

namespace recruit::control {
namespace {

// A relative path is tried from the working directory, then from the data folder the program
// set (common/data_path.h), so that the shipped models/identified/ files are found from a build
// directory too.
std::string ResolveModelPath(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty() || fs::path(path).is_absolute() || fs::exists(path, ec)) return path;
  if (const std::string data = DataDir(); !data.empty()) {
    const fs::path alt = fs::path(data) / path;
    if (fs::exists(alt, ec)) return alt.string();
  }
  return path;
}

}  // namespace

Result<EstimatorKind> ParseEstimatorKind(const std::string& name) {
  if (name == "output") return EstimatorKind::kOutput;
  if (name == "kalman2") return EstimatorKind::kKalman2;
  if (name == "kalman-augmented") return EstimatorKind::kKalmanAugmented;
  return Error{"estimator: kind \"" + name +
               "\" is not one of \"output\", \"kalman2\", \"kalman-augmented\""};
}

const char* EstimatorKindName(EstimatorKind kind) {
  switch (kind) {
    case EstimatorKind::kOutput:
      return "output";
    case EstimatorKind::kKalman2:
      return "kalman2";
    case EstimatorKind::kKalmanAugmented:
      return "kalman-augmented";
  }
  return "?";
}

Result<EstimatorSpec> EstimatorSpec::Parse(const std::string& kind, const std::string& covariance,
                                           const std::string& model_file, int num_states,
                                           double force_noise_std) {
  // "kalman-failures": the augmented kind with failed states (EstimatorSpec::failures).
  const bool failures = kind == "kalman-failures";
  auto k = ParseEstimatorKind(failures ? "kalman-augmented" : kind);
  if (!k) return Error{k.error(), k.code()};
  auto c = estimation::ParseCovarianceMode(covariance);
  if (!c) {
    return Error{"estimator: covariance \"" + covariance +
                 "\" is not one of \"extended\", \"conservative\", \"plain\""};
  }
  if (num_states < 4 || num_states % 2 != 0) {
    return Error{"estimator: num_states = " + std::to_string(num_states) +
                 " must be even and >= 4 (a heating and a cooling chain, each ending in a "
                 "settled state)"};
  }
  if (!std::isfinite(force_noise_std) || force_noise_std < 0) {
    return Error{"estimator: force_noise_std = " + std::to_string(force_noise_std) +
                 " N must be finite and >= 0 (0 = default)"};
  }
  EstimatorSpec s;
  s.kind = *k;
  s.covariance = *c;
  s.model_file = model_file;
  s.num_states = num_states;
  s.force_noise_std = force_noise_std;
  s.failures = failures;
  return s;
}

Result<EstimatorSpec> EstimatorSpec::FromJson(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) return Error{where + ": estimator must be a JSON object"};
  struct {
    std::string kind = "kalman-augmented", covariance = "extended", model_file;
    int num_states = 20;
    double force_noise_std = 0;
  } d;
  auto str = [&](const char* key, std::string& out) -> Status {
    if (!j.contains(key)) return Status::Ok();
    if (!j[key].is_string()) return Error{where + ": estimator." + key + " must be a string"};
    out = j[key].get<std::string>();
    return Status::Ok();
  };
  if (Status s = str("kind", d.kind); !s) return Error{s.error(), s.code()};
  if (Status s = str("covariance", d.covariance); !s) return Error{s.error(), s.code()};
  if (Status s = str("model_file", d.model_file); !s) return Error{s.error(), s.code()};
  if (j.contains("num_states")) {
    if (!j["num_states"].is_number_integer()) {
      return Error{where + ": estimator.num_states must be an integer"};
    }
    d.num_states = j["num_states"].get<int>();
  }
  if (j.contains("force_noise_std")) {
    if (!j["force_noise_std"].is_number()) {
      return Error{where + ": estimator.force_noise_std must be a number (N)"};
    }
    d.force_noise_std = j["force_noise_std"].get<double>();
  }
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    if (k != "kind" && k != "covariance" && k != "model_file" && k != "num_states" &&
        k != "force_noise_std") {
      return Error{where + ": unknown estimator field \"" + k +
                   "\" (allowed: kind, covariance, model_file, num_states, force_noise_std)"};
    }
  }
  auto r = Parse(d.kind, d.covariance, d.model_file, d.num_states, d.force_noise_std);
  if (!r) return Error{where + ": " + r.error(), r.code()};
  return r;
}

std::string DefaultModelFile(double dT, int num_states) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.2f", dT);
  std::string t = buf;  // "0.50" -> "0.5", "2.00" -> "2.0", "0.25" stays
  if (t.size() > 1 && t.back() == '0' && t[t.size() - 2] != '.') t.pop_back();
  return "models/identified/bench_n60_dt" + t + "_m" + std::to_string(num_states) + ".json";
}

namespace {

// The identification record of a model file's content ("identification" object), {} when
// absent.
nlohmann::json IdentificationOf(const nlohmann::json& j) {
  if (j.is_object() && j.contains("identification") && j["identification"].is_object()) {
    return j["identification"];
  }
  return nlohmann::json::object();
}

// The unit force map of an identified model: its recorded fractions, or the fractions of its H
// at the extension it was identified at (the plant's prestretch when not recorded).
Result<UnitForceMap> ModelForceMap(const estimation::FilterModel& model,
                                   const nlohmann::json& ident, const UnitGeometry& g,
                                   const std::string& file) {
  if (ident.contains("output_fractions")) {
    const auto& f = ident["output_fractions"];
    if (!f.is_array() || static_cast<int>(f.size()) != model.num_states()) {
      return Error{file + ": identification.output_fractions must be an array of " +
                   std::to_string(model.num_states()) + " numbers"};
    }
    Eigen::VectorXd xi(model.num_states());
    for (int i = 0; i < model.num_states(); ++i) {
      if (!f[i].is_number()) {
        return Error{file + ": identification.output_fractions[" + std::to_string(i) +
                     "] must be a number in [0, 1]"};
      }
      xi[i] = f[i].get<double>();
    }
    auto map = UnitForceMap::FromFractions(g, xi);
    if (!map) return Error{file + ": identification.output_fractions: " + map.error(), map.code()};
    return map;
  }
  const double stretch = ident.contains("stretch") && ident["stretch"].is_number()
                             ? ident["stretch"].get<double>()
                             : g.unit.prestretch;
  return UnitForceMap::FromForces(g, stretch, model.H.row(0).transpose());
}

}  // namespace

Result<std::unique_ptr<OnCountEstimator>> MakeEstimator(const EstimatorSpec& spec, int num_units,
                                                        double unit_force, double dT,
                                                        const UnitGeometry* geometry) {
  auto checked = EstimatorSpec::Parse(EstimatorKindName(spec.kind), ToString(spec.covariance),
                                      spec.model_file, spec.num_states, spec.force_noise_std);
  if (!checked) return Error{checked.error(), checked.code()};
  if (num_units < 1) return Error{"estimator: num_units must be >= 1"};
  if (!std::isfinite(unit_force) || unit_force <= 0) {
    return Error{"estimator: unit_force must be finite and > 0 N"};
  }
  RECRUIT_TRY(CheckDT(dT, "estimator"));
  // The settled on unit's force as a function of length, for the length-aware output estimator.
  std::optional<UnitForceMap> on_force;
  if (geometry) {
    auto map = UnitForceMap::FromForces(*geometry, geometry->unit.prestretch,
                                        Eigen::VectorXd::Constant(1, unit_force));
    if (!map) return Error{"estimator: " + map.error(), map.code()};
    on_force = std::move(map).value();
  }
  if (spec.kind == EstimatorKind::kOutput) {
    return std::unique_ptr<OnCountEstimator>(
        new OutputOnlyEstimator(num_units, unit_force, std::move(on_force)));
  }
  const estimation::CovarianceMode mode = spec.covariance;
  estimation::FilterModel model;
  std::optional<UnitForceMap> output;
  double relative_noise = 0;
  if (spec.kind == EstimatorKind::kKalman2) {
    const double sd = spec.force_noise_std > 0 ? spec.force_noise_std : unit_force;
    model = estimation::FilterModel::TwoState(num_units, dT, unit_force, sd);
    if (geometry) {
      auto map = UnitForceMap::FromForces(*geometry, geometry->unit.prestretch,
                                          Eigen::Vector2d(0.0, unit_force));
      if (!map) return Error{"estimator: " + map.error(), map.code()};
      output = std::move(map).value();
    }
  } else {
    const std::string file = ResolveModelPath(
        spec.model_file.empty() ? DefaultModelFile(dT, spec.num_states) : spec.model_file);
    // The file is read and parsed once, for the model, its plant and its identification record
    // (and once per process for each content: a sweep's runs share the parse).
    auto parsed = estimation::ParseFilterModelFile(file);
    auto loaded = parsed.ok() ? Result<estimation::FilterModel>((*parsed)->model)
                              : Result<estimation::FilterModel>(parsed.failure());
    if (!loaded) {
      return Error{"estimator: " + loaded.error() +
                       (spec.model_file.empty()
                            ? " (no identified model for this dT and number of states: make one "
                              "with `recruit identify --dt DT --states M -o FILE` and pass it as "
                              "the model file)"
                            : ""),
                   loaded.code()};
    }
    model = std::move(loaded).value();
    if (!spec.plant.is_null()) {
      if (Status s = CheckModelPlant(file, (*parsed)->json, spec.plant); !s) {
        return Error{"estimator: " + s.error(), s.code()};
      }
    }
    if (model.transition != estimation::TransitionSource::kBroadcast) {
      return Error{"estimator: " + file + ": transition.type must be \"broadcast\""};
    }
    if (model.num_states() != spec.num_states) {
      return Error{
          "estimator: " + file + " has " + std::to_string(model.num_states()) +
          " states, the estimator asks for num_states = " + std::to_string(spec.num_states)};
    }
    if (std::abs(model.broadcast.dt - dT) > 1e-9 * std::max(1.0, dT)) {
      return Error{"estimator: " + file +
                   " was identified for dt = " + std::to_string(model.broadcast.dt) +
                   " s, the controller samples every dT = " + std::to_string(dT) +
                   " s (identify a model for this dT)"};
    }
    if (model.num_outputs() != 1) {
      return Error{"estimator: " + file + ": H must have one row (the bundle's force)"};
    }
    if (model.N != num_units) model = model.WithPopulation(num_units);
    if (spec.force_noise_std > 0) {  // the user's noise replaces the model's, all of it
      model.R = Eigen::MatrixXd::Constant(1, 1, spec.force_noise_std * spec.force_noise_std);
      model.R_transit.resize(0, 0);
      model.R_transit2.resize(0, 0);
    }
    const nlohmann::json ident = IdentificationOf((*parsed)->json);
    if (geometry) {
      auto map = ModelForceMap(model, ident, *geometry, file);
      if (!map) return Error{"estimator: " + map.error(), map.code()};
      output = std::move(map).value();
      // H >= 0 at the reference length, whatever the file held.
      auto h = model.H.row(0);
      output->Forces(geometry->ref_length, h);
    }
    if (spec.force_noise_std <= 0 && ident.contains("relative_noise") &&
        ident["relative_noise"].is_number()) {
      relative_noise = ident["relative_noise"].get<double>();
    }
  }
  if (!std::isfinite(spec.sensor_variance) || spec.sensor_variance < 0) {
    return Error{"estimator: sensor_variance must be finite and >= 0 N^2"};
  }
  model.R(0, 0) += spec.sensor_variance;
  if (spec.failures) {
    auto est = FailureOnCountEstimator::Create(model, mode, spec.failure, std::move(output),
                                               relative_noise);
    if (!est) return est.failure().In("estimator: ");
    return std::unique_ptr<OnCountEstimator>(std::move(est).value());
  }
  auto est = KalmanOnCountEstimator::Create(model, mode, std::move(output), relative_noise);
  if (!est) return Error{"estimator: " + est.error(), est.code()};
  return std::unique_ptr<OnCountEstimator>(std::move(est).value());
}

}  // namespace recruit::control
