#include "sim/bundle_models.h"

#include <algorithm>
#include <chrono>
#include <cstdio>

#include "control/kalman_estimator.h"
#include "identification/model_cache.h"
#include "identification/plant_record.h"
#include "plugin/sma_host.h"
#include "sim/response_store.h"

namespace recruit::sim {

Result<std::string> BundleModelFile(const Task& task, const ControllerSettings& settings,
                                    const Plant& plant, int i, const RunOptions& options,
                                    const control::EstimatorSpec& spec, double& identify_s) {
  const sma::SmaHost& host = plant.host();
  const int b = plant.bundle_index(i);
  std::string file = spec.model_file;
  const std::string key = "{bundle}";
  for (size_t at; (at = file.find(key)) != std::string::npos;) {
    file.replace(at, key.size(), host.bundle_name(b));
  }
  if (!file.empty()) return file;
  identification::ModelRequest req{task.model_path, host.bundle_name(b),
                                   identification::PlantRecord(host, b, task.model_path),
                                   settings.dT, spec.num_states};
  auto found = identification::FindOrIdentifyModel(req, /*identify=*/false, nullptr);
  if (found.ok() || !options.identify_missing_models) return found;
  // Not on the search path: identified now; the time it takes is reported apart.
  const auto start = std::chrono::steady_clock::now();
  found = identification::FindOrIdentifyModel(req, true, options.quiet ? nullptr : stderr);
  identify_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return found;
}

void IdentificationWarning(const estimation::FilterModel& model, const std::string& bundle,
                           std::vector<std::string>& warnings) {
  if (!(model.holdout_r2 < kMinHoldoutR2)) return;  // NaN: not recorded
  char buf[300];
  std::snprintf(buf, sizeof buf,
                "%s: its identified model explains R^2 = %.2f of held-out force (below %.2f): the "
                "estimate and the loop's design rest on it",
                bundle.c_str(), model.holdout_r2, kMinHoldoutR2);
  if (std::find(warnings.begin(), warnings.end(), buf) == warnings.end()) warnings.push_back(buf);
}

Result<std::vector<control::ActuatorResponse>> ActuatorResponses(
    const Task& task, const ControllerSettings& settings, const Plant& plant,
    const std::vector<const control::OnCountEstimator*>& estimators, const RunOptions& options,
    double& identify_s, std::vector<std::string>& warnings) {
  std::vector<control::ActuatorResponse> out;
  for (int i = 0; i < plant.num_bundles(); ++i) {
    const auto* kalman = dynamic_cast<const control::KalmanOnCountEstimator*>(estimators.at(i));
    estimation::FilterModel model;
    if (kalman != nullptr) {
      model = kalman->model();
    } else {
      control::EstimatorSpec spec;
      spec.model_file = settings.filter_model;
      auto file = BundleModelFile(task, settings, plant, i, options, spec, identify_s);
      if (!file && options.identify_missing_models) return file.failure();
      if (!file) {
        // No identified model and none to be made: the design rests on the unit's own lag.
        const double tau = plant.host().bundle(plant.bundle_index(i)).unit().time_constant();
        out.push_back(control::FirstOrderActuatorResponse(settings.dT, settings.lambda, tau));
        warnings.push_back(plant.bundle_name(i) +
                           ": no identified model for this dT; the loop is designed on the "
                           "unit's thermal lag");
        continue;
      }
      auto loaded = estimation::FilterModel::FromJson(*file);
      if (!loaded) return loaded.failure();
      model = std::move(loaded).value();
      IdentificationWarning(model, plant.bundle_name(i), warnings);
    }
    if (model.transition != estimation::TransitionSource::kBroadcast || model.H.rows() < 1) {
      return Error{"bundle '" + plant.bundle_name(i) +
                   "': the self-tuned loop needs a broadcast chain model with a force row"};
    }
    const Eigen::VectorXd h = model.H.row(0).transpose();
    auto r = StoredBundleResponse(
        model.broadcast, std::vector<double>(h.data(), h.data() + h.size()), settings.lambda);
    if (r) {
      out.push_back(std::move(r).value());
    } else {
      // A chain whose force does not follow its count (a poor identification): the law's
      // approach through the unit's own thermal lag.
      const double tau = plant.host().bundle(plant.bundle_index(i)).unit().time_constant();
      out.push_back(control::FirstOrderActuatorResponse(settings.dT, settings.lambda, tau));
      warnings.push_back(plant.bundle_name(i) + ": " + r.error() +
                         "; the loop is designed on the unit's thermal lag instead");
    }
  }
  return out;
}

}  // namespace recruit::sim
