// One rule for the controller's sampling period dT (control/sampling_period.h): task files,
// sweep files, the sweep grid, the controller and the estimators accept exactly the same values.
#include "control/sampling_period.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "control/output_estimator.h"
#include "control/recruitment_controller.h"
#include "sim/task.h"
#include "sweep/grid.h"
#include "sweep/sweep_file.h"

namespace recruit {
namespace file_sampling_period_test {

std::string Number(double x) {
  if (std::isnan(x)) return "NaN";  // not JSON: the task's parser refuses it anyway
  if (std::isinf(x)) return x > 0 ? "1e999" : "-1e999";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

TEST(SamplingPeriod, EveryPlaceAcceptsTheSameDt) {
  const double inf = std::numeric_limits<double>::infinity();
  for (double dT : {1e-9, 0.5, 2.0, 1000.0, 0.0, -1.0, 1000.0001, 5000.0, inf, std::nan("")}) {
    const bool valid = dT > 0 && dT <= 1000 && std::isfinite(dT);
    EXPECT_EQ(control::ValidDT(dT), valid) << dT;
    EXPECT_EQ(control::CheckDT(dT, "x").ok(), valid) << dT;

    const std::string task = R"({"name": "t", "model": ")" RECRUIT_SOURCE_DIR
                             R"(/models/isometric_bench.xml", "tracked": "force",
      "agonist": "bundle", "reference": {"type": "constant", "value": 1}, "duration": 1,
      "controller": {"dT": )" +
                             Number(dT) + "}}";
    auto t = sim::Task::FromJsonText(task, "t.json");
    EXPECT_EQ(t.ok(), valid) << dT << ": " << (t.ok() ? "ok" : t.error());

    if (std::isfinite(dT)) {
      auto f = sweep::SweepFile::FromJsonText(R"({"controller": {"dT": [)" + Number(dT) + "]}}",
                                              "s.json");
      EXPECT_EQ(f.ok(), valid) << dT << ": " << (f.ok() ? "ok" : f.error());
    }
    sweep::SweepSpec spec;
    spec.dTs = {dT};
    spec.lambdas = {0.2};
    spec.estimators = {"output"};
    EXPECT_EQ(sweep::ExpandGrid(spec).ok(), valid) << dT;

    control::ControllerParams p;
    p.num_units = 10;
    p.unit_force = 1;
    p.dT = dT;
    EXPECT_EQ(p.Validate().ok(), valid) << dT;
  }
  // One default: a task without dT and a controller left at its default agree.
  EXPECT_EQ(sim::ControllerSettings{}.dT, control::ControllerParams{}.dT);
  EXPECT_EQ(control::ControllerParams{}.dT, control::kDefaultDT);
}

}  // namespace file_sampling_period_test
}  // namespace recruit
