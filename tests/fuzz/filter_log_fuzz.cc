// Fuzz target: the log reader of `recruit filter` (FilterLogReader, docs/formats/filter.md) and
// the filter run over it (RunFilterOverText). The first byte picks one of three fixed models (a
// broadcast, an explicit and a constant transition), the second the estimator; the rest is the
// CSV log.
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/json_file.h"
#include "estimation/count_filter.h"
#include "estimation/filter_log.h"
#include "estimation/filter_model.h"

namespace {

// models/filter/three_state_model.json: broadcast, one output.
constexpr const char* kBroadcast = R"({
  "states": ["off", "warming", "on"], "N": 60, "H": [[0.0, 0.2, 0.45]], "R": [[0.09]],
  "transition": {"type": "broadcast", "dt": 0.5, "is_on": [false, true, true],
    "interior": [[1.0, 0.0, 0.0], [0.0, 0.4, 0.0], [0.0, 0.6, 1.0]],
    "on_target": [1, -1, -1], "off_target": [-1, 0, 0]},
  "initial": {"x0": [60.0, 0.0, 0.0]}})";
// Explicit A(k) columns A_i_j, small N (the exact filter stays fast), two outputs.
constexpr const char* kExplicit = R"({
  "states": ["off", "on"], "N": 6, "H": [[0.0, 1.0], [1.0, 0.0]], "R": [[0.5, 0.1], [0.1, 0.5]],
  "transition": {"type": "explicit"},
  "initial": {"x0": [4.0, 2.0]}})";
// Constant A with process noise and an uncertain start (Kalman only: the exact and particle
// filters refuse process noise).
constexpr const char* kConstant = R"({
  "states": ["a", "b", "c"], "N": 9, "H": [[1.0, 2.0, 3.0]], "R": [[0.25]],
  "G": [[1.0], [-1.0], [0.0]], "Qw": [[0.01]],
  "transition": {"type": "constant", "A": [[0.9, 0.1, 0.0], [0.1, 0.8, 0.2], [0.0, 0.1, 0.8]]},
  "initial": {"x0": [3.0, 3.0, 3.0], "P0": [[1.0, -0.5, -0.5], [-0.5, 1.0, -0.5], [-0.5, -0.5, 1.0]]}})";

recruit::estimation::FilterModel Load(const char* text) {
  auto j = recruit::ParseJsonText(text, "fuzz");
  auto m = recruit::estimation::FilterModel::FromJsonValue(*j, "fuzz");
  if (!m.ok()) __builtin_trap();  // the fixed models are valid
  return *m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const recruit::estimation::FilterModel kModels[] = {Load(kBroadcast), Load(kExplicit),
                                                             Load(kConstant)};
  static const char* const kEstimators[] = {"extended", "conservative", "plain", "exact",
                                            "particle"};
  if (size < 2) return 0;
  const recruit::estimation::FilterModel& model = kModels[data[0] % 3];
  recruit::estimation::CountFilterOptions options;
  options.estimator = kEstimators[data[1] % 5];
  options.particles = 64;
  options.max_states = 100;  // the exact filter only for the small explicit model
  auto filter = recruit::estimation::MakeCountFilter(model, options);
  if (!filter.ok()) return 0;  // e.g. exact or particle with process noise
  const std::string log(reinterpret_cast<const char*>(data) + 2, size - 2);
  auto out = recruit::estimation::RunFilterOverText(model, log, "fuzz_log.csv", **filter);
  (void)out;
  return 0;
}
