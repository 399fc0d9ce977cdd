// Reference: the time profile a task tracks (force in N, or a joint angle in rad). Every kind
// (constant, steps, ramp, piecewise, the paper's Fig. 5 profile) is stored as one piecewise-linear
// list of knots; two knots at the same time make a jump (a step).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/result.h"

namespace recruit::sim {

struct Knot {
  double t;  // s
  double v;  // N or rad
};

// One step of the reference: a jump at `time` from `from` to `to`, followed by a hold that lasts
// until `end` (the next change of the reference or the end of the run).
struct ReferenceStep {
  double time, from, to, end;
};

class Reference {
 public:
  Reference() = default;

  static Reference Constant(double value);
  // values[i] holds from times[i]; `initial` holds before times[0].
  static Result<Reference> Steps(double initial, const std::vector<double>& times,
                                 const std::vector<double>& values);
  // Knots in non-decreasing time; equal times make a jump.
  static Result<Reference> Piecewise(std::vector<Knot> knots);
  // The paper's kind of force profile (Fig. 5): 0-25 N over 200 s, six steps and a ramp.
  static Reference PaperFig5();

  // From a task file's "reference" object. `where` names the file and field for errors,
  // `scale` converts the file's unit to SI (e.g. pi/180 for degrees).
  static Result<Reference> FromJson(const nlohmann::json& j, const std::string& where,
                                    double scale = 1.0);

  double operator()(double t) const;
  const std::vector<Knot>& knots() const { return knots_; }

  // The jumps of the reference within [0, duration], each with its hold segment.
  std::vector<ReferenceStep> Steps(double duration) const;

  double MaxValue() const;
  double MinValue() const;

 private:
  std::vector<Knot> knots_;  // at least one
};

}  // namespace recruit::sim
