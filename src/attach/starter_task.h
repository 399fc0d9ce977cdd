// A starter task for a model `recruit attach` wrote: posture steps on every limited hinge the
// bundles' tendons cross (minus locked joints), inside each joint's usable range, the Kalman
// estimator and the self-tuned outer loop.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "attach/attach.h"
#include "common/result.h"

namespace recruit::attach {

inline constexpr double kStepHold = 20;  // s per step
// s before the first step: the limb goes from its rest pose to the middle of the usable range
// (the references' initial value), so that the first scored step starts settled and is as
// large as the others.
inline constexpr double kStepStart = 20;

// The task JSON (docs/howto-own-model.md); `task_path` is where it will be written (the model
// path in it is relative to that folder). Error when every joint the bundles
// cross is locked.
Result<nlohmann::json> StarterTask(const AttachReport& report, const std::vector<std::string>& lock,
                                   const std::string& task_path);

}  // namespace recruit::attach
