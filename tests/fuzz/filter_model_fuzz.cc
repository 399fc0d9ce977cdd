// Fuzz target: the filter model parser (ParseJsonText, common/json_file.h, then
// FilterModel::FromJsonValue: what FilterModel::FromJson does with a file's text;
// docs/formats/filter.md). A model that validates must also give a working Kalman filter: one
// prediction and one update must not crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/json_file.h"
#include "estimation/count_filter.h"
#include "estimation/filter_model.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto j = recruit::ParseJsonText(text, "fuzz_model.json");
  if (!j.ok()) return 0;
  auto model = recruit::estimation::FilterModel::FromJsonValue(*j, "fuzz_model.json");
  if (!model.ok()) return 0;
  const recruit::estimation::FilterModel& m = *model;
  auto filter = recruit::estimation::MakeCountFilter(m, recruit::estimation::CountFilterOptions{});
  if (!filter.ok()) return 0;
  recruit::estimation::CountFilter& f = **filter;
  switch (m.transition) {
    case recruit::estimation::TransitionSource::kBroadcast:
      f.PredictBroadcast(m.broadcast, 0.25, 0.5);
      break;
    case recruit::estimation::TransitionSource::kConstant:
      f.Predict(m.A);
      break;
    case recruit::estimation::TransitionSource::kExplicit:  // identity is column-stochastic
      f.Predict(Eigen::MatrixXd::Identity(m.num_states(), m.num_states()));
      break;
  }
  f.Update(m.H * m.x0);
  Eigen::VectorXd mean, var;
  f.MeanAndVariance(mean, var);
  return 0;
}
