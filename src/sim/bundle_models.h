// Each bundle's identified chain model, as a run and an export use it: the filter model file of
// a bundle (the task's, else found or identified for the plant and dT) and the tension step
// response the self-tuned loop is designed on.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "control/actuator_response.h"
#include "control/on_count_estimator.h"
#include "estimation/filter_model.h"
#include "sim/plant.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::sim {

// The filter model file of bundle i for `spec`: spec.model_file (its "{bundle}" replaced by the
// bundle's actuator name), else the one identified on this bundle for this dT, from the model
// search path, else (options.identify_missing_models) identified now and cached
// (identification/model_cache.h). `identify_s` accumulates the time spent identifying.
Result<std::string> BundleModelFile(const Task& task, const ControllerSettings& settings,
                                    const Plant& plant, int i, const RunOptions& options,
                                    const control::EstimatorSpec& spec, double& identify_s);

// A warning when an identified model explains less than kMinHoldoutR2 of the force it was
// checked on (held-out data at the identification pose): the estimate and the self-tuned loop's
// design rest on it. Each text once in `warnings`.
inline constexpr double kMinHoldoutR2 = 0.9;
void IdentificationWarning(const estimation::FilterModel& model, const std::string& bundle,
                           std::vector<std::string>& warnings);

// Each bundle's tension step response under the law, rise and release
// (control::PredictBundleResponse), predicted on
// the chain identified for it: its Kalman estimator's own model (estimators[i]), else the
// identified one, else (none found and none to be made) the unit's thermal lag, with a warning.
Result<std::vector<control::ActuatorResponse>> ActuatorResponses(
    const Task& task, const ControllerSettings& settings, const Plant& plant,
    const std::vector<const control::OnCountEstimator*>& estimators, const RunOptions& options,
    double& identify_s, std::vector<std::string>& warnings);

// The same for bundles that each hold a `controller` (control::RecruitmentController): a run's
// channels, an export's sim::BundleController.
template <class Bundle>
Result<std::vector<control::ActuatorResponse>> ActuatorResponses(
    const Task& task, const ControllerSettings& settings, const Plant& plant,
    const std::vector<Bundle>& bundles, const RunOptions& options, double& identify_s,
    std::vector<std::string>& warnings) {
  std::vector<const control::OnCountEstimator*> estimators;
  for (const Bundle& b : bundles) estimators.push_back(&b.controller.estimator());
  return ActuatorResponses(task, settings, plant, estimators, options, identify_s, warnings);
}

}  // namespace recruit::sim
