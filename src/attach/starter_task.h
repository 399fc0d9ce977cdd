// A starter task for a model `recruit attach` wrote: posture steps on every limited hinge the
// bundles' tendons cross (minus locked joints), inside the part of each joint's usable range the
// bundles can hold (attach/holdable.h), the Kalman estimator and the self-tuned outer loop.
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
// The starter task's co_contraction (each bundle's least tension, a fraction of its capacity):
// written into the task, and the floor its holdable ranges are found with.
inline constexpr double kStarterCoContraction = 0.05;

// The hinges the bundles cross, in first-seen order, minus the locked ones, each with the usable
// range common to every bundle that crosses it.
std::vector<JointUse> DrivenJoints(const AttachReport& report,
                                   const std::vector<std::string>& lock);

// The task JSON (docs/howto-own-model.md), its steps inside report.holdable's ranges where given;
// `task_path` is where it will be written (the model path in it is relative to that folder). Error
// when every joint the bundles cross is locked.
Result<nlohmann::json> StarterTask(const AttachReport& report, const std::vector<std::string>& lock,
                                   const std::string& task_path);

}  // namespace recruit::attach
