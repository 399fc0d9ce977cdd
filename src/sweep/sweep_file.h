// A sweep file (JSON, docs/sweep.md): the task, the controller axes (dT, lambda, estimator,
// seeds) and named plant axes, each a JSON pointer into the task document ("/sensor/noise_std")
// or a plugin config key of the task's MJCF model ("model:bundle_units/units"), with values or a
// range, combined as a cartesian grid or a seeded Latin-hypercube / Sobol sample. Errors name the
// sweep file, the axis and the value.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "sim/task.h"
#include "sweep/grid.h"
#include "sweep/table.h"

namespace recruit::sweep {

struct PlantAxis {
  std::string name;
  std::string path;            // as written: "/json/pointer" or "model:INSTANCE/KEY"
  std::string instance;        // model axes: the plugin instance's name
  std::string key;             // model axes: the config key
  std::vector<double> values;  // explicit values (grid), or the range's grid points
  double lo = 0, hi = 0;       // range (for samples); lo == hi == 0 and !has_range: values only
  bool has_range = false;
  bool log = false;      // range in log scale
  bool integer = false;  // values rounded to whole numbers
  bool is_model() const { return !instance.empty(); }
  // Maps u in [0, 1) to a value of the axis (samples).
  double FromUnit(double u) const;
};

enum class Sampling { kGrid, kLatinHypercube, kSobol };

struct SweepFile {
  std::string source;  // the file it came from
  std::string task;    // task file, resolved relative to the sweep file ("" = from --task)
  std::optional<double> duration;
  std::vector<double> dTs, lambdas;     // empty = not given in the file
  std::vector<std::string> estimators;  // empty = not given
  std::optional<int> seeds;
  std::optional<std::uint64_t> base_seed;
  std::optional<sweep::TrackingCriterion> criterion;
  std::vector<PlantAxis> axes;
  Sampling sampling = Sampling::kGrid;
  int samples = 0;  // lhs / sobol
  std::uint64_t sample_seed = 1;

  static Result<SweepFile> FromFile(const std::string& path);
  static Result<SweepFile> FromJsonText(const std::string& text, const std::string& source);
};

// The plant points: the cartesian product of the axes (first axis outermost) or the sample.
// No axes: one point with no values.
Result<std::vector<sweep::PlantPoint>> PlantPoints(const SweepFile& file);

// One plant point applied to a task: the task document with the JSON-pointer axes set, and the
// model text with the model axes set (model_edited false: the task's own model file is used).
struct PlantInputs {
  std::string task_text;
  std::string model_text;
  bool model_edited = false;
};
// `where` prefixes errors (the sweep file). Bad paths and values are errors naming the axis.
Result<PlantInputs> ApplyPlantPoint(const std::string& task_text, const std::string& model_text,
                                    const std::vector<PlantAxis>& axes,
                                    const sweep::PlantPoint& point, const std::string& where);

// Sets `key`'s value in the plugin instance `instance` of an MJCF text (sim/task.h).
using sim::SetPluginConfig;

}  // namespace recruit::sweep
