#include "attach/starter_task.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace recruit::attach {
namespace {

namespace fs = std::filesystem;

// Fractions of the usable range the steps go to: away from the ends, alternating.
constexpr double kStepFractions[] = {0.3, 0.7, 0.45, 0.8};

double Round1(double v) { return std::round(10 * v) / 10; }

}  // namespace

std::vector<JointUse> DrivenJoints(const AttachReport& report,
                                   const std::vector<std::string>& lock) {
  std::vector<JointUse> joints;
  for (const BundleReport& b : report.bundles) {
    for (const JointUse& u : b.joints) {
      if (!u.hinge) continue;
      auto it = std::find_if(joints.begin(), joints.end(),
                             [&](const JointUse& j) { return j.joint == u.joint; });
      if (it == joints.end()) {
        joints.push_back(u);
      } else {
        it->usable_lo = std::max(it->usable_lo, u.usable_lo);
        it->usable_hi = std::min(it->usable_hi, u.usable_hi);
      }
    }
  }
  for (const std::string& l : lock) {  // held by the model: not driven
    joints.erase(std::remove_if(joints.begin(), joints.end(),
                                [&](const JointUse& j) { return j.joint == l; }),
                 joints.end());
  }
  return joints;
}

Result<nlohmann::json> StarterTask(const AttachReport& report, const std::vector<std::string>& lock,
                                   const std::string& task_path) {
  std::vector<JointUse> joints = DrivenJoints(report, lock);
  if (joints.empty()) return Error{"the starter task drives no joint (every one locked or none)"};
  for (JointUse& j : joints) {  // steps where the bundles hold the limb
    for (const HoldableRange& h : report.holdable) {
      if (h.joint == j.joint) j.usable_lo = h.hold_lo, j.usable_hi = h.hold_hi;
    }
  }
  nlohmann::json task;
  const std::string stem = fs::path(report.output).stem().string();
  task["name"] = stem + "_steps";
  std::string driven;
  for (const JointUse& j : joints) driven += (driven.empty() ? "" : ", ") + j.joint;
  task["description"] = "Starter task written by recruit attach: posture steps of " + driven +
                        " inside each joint's usable range, " + std::to_string(int(kStepHold)) +
                        " s holds, Kalman estimator, self-tuned outer loop.";
  std::error_code ec;
  const fs::path task_dir = fs::absolute(task_path, ec).parent_path();
  task["model"] = fs::relative(fs::absolute(report.output, ec), task_dir, ec).string();
  task["tracked"] = "angle";
  const int steps = static_cast<int>(std::size(kStepFractions));
  nlohmann::json list = nlohmann::json::array();
  for (const JointUse& j : joints) {
    std::vector<double> times, values;
    for (int k = 0; k < steps; ++k) {
      times.push_back(kStepStart + k * kStepHold);
      const double q = j.usable_lo + kStepFractions[k] * (j.usable_hi - j.usable_lo);
      values.push_back(Round1(q * 180 / M_PI));
    }
    const double middle = Round1(0.5 * (j.usable_lo + j.usable_hi) * 180 / M_PI);
    list.push_back({{"joint", j.joint},
                    {"reference",
                     {{"type", "steps"},
                      {"initial", middle},
                      {"times", times},
                      {"values", values},
                      {"unit", "deg"}}}});
  }
  task["joints"] = list;
  nlohmann::json bundles = nlohmann::json::array();
  for (const BundleReport& b : report.bundles) bundles.push_back(b.name);
  task["bundles"] = bundles;
  task["duration"] = kStepStart + steps * kStepHold;
  task["controller"] = {{"estimator", "kalman-augmented"}, {"dT", 1.0}, {"lambda", 0.2}};
  task["sensor"] = {{"noise_std", 0.05}, {"resolution", 0.0125}};
  task["outer_loop"] = "auto";
  task["co_contraction"] = kStarterCoContraction;
  return task;
}

}  // namespace recruit::attach
