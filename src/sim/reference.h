// Reference: the time profile a task tracks (force in N, or a joint angle in rad). Every kind
// (constant, steps, ramp, piecewise, the paper's Fig. 5 profile) is stored as one piecewise-linear
// list of knots; two knots at the same time make a jump (a step).
#pragma once

#include <limits>
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

// A Reference read at times that mostly move forward a little (once a physics step): it keeps the
// stretch of time the last read fell in, where the value is one formula (a constant, or one
// segment's interpolation), so that a read there is two comparisons instead of Reference's
// binary search (~35 instructions a step). Each read gives the same double as the Reference.
// A cursor is one run's (not shared between threads); the Reference must outlive it.
class ReferenceCursor {
 public:
  explicit ReferenceCursor(const Reference& reference) : ref_(&reference) {}

  double operator()(double t) { return t >= lo_ && t < hi_ ? Value(t) : Seek(t); }

 private:
  double Value(double t) const { return constant_ ? v0_ : v0_ + dv_ * (t - t0_) / dt_; }
  // Keeps the stretch holding t; the Reference's value at t.
  double Seek(double t);

  const Reference* ref_;
  // Reads in [lo_, hi_) give v0_ (constant_), or v0_ + dv_ (t - t0_) / dt_: Reference's
  // interpolation a.v + (b.v - a.v) (t - a.t) / (b.t - a.t) with the same operands. Empty until
  // the first read.
  double lo_ = std::numeric_limits<double>::infinity(), hi_ = 0;
  bool constant_ = true;
  double v0_ = 0, t0_ = 0, dv_ = 0, dt_ = 1;
};

}  // namespace recruit::sim
