#include "sim/reference.h"

#include <algorithm>
#include <cmath>

namespace recruit::sim {
namespace {

bool Finite(double x) { return std::isfinite(x); }

Result<double> GetNumber(const nlohmann::json& j, const char* key, const std::string& where) {
  if (!j.contains(key)) return Error{where + ": missing field '" + key + "'"};
  const auto& v = j.at(key);
  if (!v.is_number() || !Finite(v.get<double>())) {
    return Error{where + "." + key + ": must be a finite number, got " + v.dump()};
  }
  return v.get<double>();
}

Result<std::vector<double>> GetNumbers(const nlohmann::json& j, const char* key,
                                       const std::string& where) {
  if (!j.contains(key)) return Error{where + ": missing field '" + key + "'"};
  const auto& v = j.at(key);
  if (!v.is_array()) return Error{where + "." + key + ": must be an array of numbers"};
  std::vector<double> out;
  for (const auto& x : v) {
    if (!x.is_number() || !Finite(x.get<double>())) {
      return Error{where + "." + key + ": must be an array of finite numbers, got " + x.dump()};
    }
    out.push_back(x.get<double>());
  }
  return out;
}

}  // namespace

Reference Reference::Constant(double value) {
  Reference r;
  r.knots_ = {{0.0, value}};
  return r;
}

Result<Reference> Reference::Steps(double initial, const std::vector<double>& times,
                                   const std::vector<double>& values) {
  if (times.size() != values.size() || times.empty()) {
    return Error{"steps: 'times' and 'values' must be non-empty and of equal length"};
  }
  std::vector<Knot> knots;  // before times[0] the first knot's value, `initial`, holds
  double prev = initial;
  for (size_t i = 0; i < times.size(); ++i) {
    if (i > 0 && !(times[i] > times[i - 1])) {
      return Error{"steps: 'times' must be strictly increasing"};
    }
    knots.push_back({times[i], prev});
    knots.push_back({times[i], values[i]});
    prev = values[i];
  }
  return Piecewise(std::move(knots));
}

Result<Reference> Reference::Piecewise(std::vector<Knot> knots) {
  if (knots.empty()) return Error{"piecewise: needs at least one point"};
  for (size_t i = 0; i < knots.size(); ++i) {
    if (!Finite(knots[i].t) || !Finite(knots[i].v)) {
      return Error{"piecewise: point " + std::to_string(i) + " is not finite"};
    }
    if (i > 0 && knots[i].t < knots[i - 1].t) {
      return Error{"piecewise: point " + std::to_string(i) +
                   " goes back in time (times must be non-decreasing)"};
    }
    if (i > 1 && knots[i].t == knots[i - 1].t && knots[i - 1].t == knots[i - 2].t) {
      return Error{"piecewise: more than two points at time " + std::to_string(knots[i].t)};
    }
  }
  Reference r;
  r.knots_ = std::move(knots);
  return r;
}

Reference Reference::PaperFig5() {
  // Steps up through the range, a slow ramp down, then steps up and down again: the kind of
  // profile of the paper's Fig. 5 (0-30 N over about 200 s), with its peak at 25 N because the
  // calibrated 60-unit bench saturates at about 27 N (all units on): a reference above that
  // cannot settle and would only measure saturation. Holds last 25 s, several times the units'
  // settling time (about 5 s, Fig. 4), so each step can be scored.
  auto r = Piecewise({{0, 0},
                      {5, 0},
                      {5, 8},
                      {30, 8},
                      {30, 16},
                      {55, 16},
                      {55, 25},
                      {80, 25},
                      {110, 8},
                      {130, 8},
                      {130, 20},
                      {155, 20},
                      {155, 12},
                      {180, 12},
                      {180, 4},
                      {200, 4}});
  return std::move(r).value();
}

Result<Reference> Reference::FromJson(const nlohmann::json& j, const std::string& where,
                                      double scale) {
  if (!j.is_object()) return Error{where + ": must be an object with a 'type'"};
  if (!j.contains("type") || !j["type"].is_string()) {
    return Error{where + ".type: missing; allowed: constant, steps, ramp, piecewise, paper_fig5"};
  }
  const std::string type = j["type"];
  const std::string w = where;
  auto wrap = [&](Result<Reference> r) -> Result<Reference> {
    if (!r.ok()) return Error{w + ": " + r.error(), r.code()};
    return r;
  };
  if (type == "constant") {
    auto v = GetNumber(j, "value", w);
    if (!v.ok()) return Error{v.error(), v.code()};
    return Constant(*v * scale);
  }
  if (type == "steps") {
    auto times = GetNumbers(j, "times", w);
    if (!times.ok()) return Error{times.error(), times.code()};
    auto values = GetNumbers(j, "values", w);
    if (!values.ok()) return Error{values.error(), values.code()};
    double initial = 0;
    if (j.contains("initial")) {
      auto i = GetNumber(j, "initial", w);
      if (!i.ok()) return Error{i.error(), i.code()};
      initial = *i;
    }
    for (double& v : *values) v *= scale;
    return wrap(Steps(initial * scale, *times, *values));
  }
  if (type == "ramp") {
    double vals[4];
    const char* keys[4] = {"start", "end", "from", "to"};
    for (int k = 0; k < 4; ++k) {
      auto v = GetNumber(j, keys[k], w);
      if (!v.ok()) return Error{v.error(), v.code()};
      vals[k] = *v;
    }
    if (!(vals[1] > vals[0])) return Error{w + ".end: must be greater than 'start'"};
    return wrap(Piecewise({{vals[0], vals[2] * scale}, {vals[1], vals[3] * scale}}));
  }
  if (type == "piecewise") {
    if (!j.contains("points") || !j["points"].is_array() || j["points"].empty()) {
      return Error{w + ".points: must be a non-empty array of [time, value] pairs"};
    }
    std::vector<Knot> knots;
    for (const auto& p : j["points"]) {
      if (!p.is_array() || p.size() != 2 || !p[0].is_number() || !p[1].is_number()) {
        return Error{w + ".points: each point must be [time, value], got " + p.dump()};
      }
      knots.push_back({p[0].get<double>(), p[1].get<double>() * scale});
    }
    return wrap(Piecewise(std::move(knots)));
  }
  if (type == "paper_fig5") {
    if (scale != 1.0) return Error{w + ": paper_fig5 is a force profile (N)"};
    return PaperFig5();
  }
  return Error{w + ".type: unknown '" + type +
               "'; allowed: constant, steps, ramp, piecewise, paper_fig5"};
}

double Reference::operator()(double t) const {
  if (!(t > knots_.front().t)) {  // NaN too: no knot to search for it
    // At a jump at the first time, the value after the jump.
    if (knots_.size() > 1 && knots_[1].t == knots_[0].t && t == knots_[0].t) return knots_[1].v;
    return knots_.front().v;
  }
  if (t >= knots_.back().t) return knots_.back().v;
  auto ub = std::upper_bound(knots_.begin(), knots_.end(), t,
                             [](double x, const Knot& k) { return x < k.t; });
  const Knot& a = *(ub - 1);
  const Knot& b = *ub;  // b.t > t >= a.t
  return a.v + (b.v - a.v) * (t - a.t) / (b.t - a.t);
}

double ReferenceCursor::Seek(double t) {
  const std::vector<Knot>& k = ref_->knots();
  const double first = k.front().t, last = k.back().t;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  // The stretches of Reference::operator()'s branches: before the first knot, past the last one,
  // and between two knots. A time at the first knot (where a jump there takes the value after it)
  // or a NaN is read from the Reference and kept nowhere.
  const double after_first = std::nextafter(first, kInf);  // the least time > first
  constant_ = true;
  if (t < first) {
    lo_ = -kInf, hi_ = first, v0_ = k.front().v;
  } else if (t >= last && t > first) {
    lo_ = std::max(last, after_first), hi_ = kInf, v0_ = k.back().v;
  } else if (t > first && t < last) {
    // upper_bound's knot b and the one before it, a: a.t <= t < b.t.
    auto b = std::upper_bound(k.begin(), k.end(), t,
                              [](double x, const Knot& knot) { return x < knot.t; });
    const Knot& a = *(b - 1);
    lo_ = std::max(a.t, after_first), hi_ = b->t;
    constant_ = false;
    v0_ = a.v, t0_ = a.t, dv_ = b->v - a.v, dt_ = b->t - a.t;
  } else {
    lo_ = kInf, hi_ = 0;
    return (*ref_)(t);
  }
  return Value(t);
}

std::vector<ReferenceStep> Reference::Steps(double duration) const {
  std::vector<ReferenceStep> steps;
  for (size_t i = 0; i + 1 < knots_.size(); ++i) {
    const Knot& a = knots_[i];
    const Knot& b = knots_[i + 1];
    if (a.t != b.t || a.v == b.v || a.t < 0 || a.t >= duration) continue;
    double end = duration;
    for (size_t j = i + 2; j < knots_.size(); ++j) {
      if (knots_[j].v != b.v) {
        end = knots_[j - 1].t;
        break;
      }
    }
    steps.push_back({a.t, a.v, b.v, std::min(end, duration)});
  }
  return steps;
}

double Reference::MaxValue() const {
  double m = knots_.front().v;
  for (const auto& k : knots_) m = std::max(m, k.v);
  return m;
}

double Reference::MinValue() const {
  double m = knots_.front().v;
  for (const auto& k : knots_) m = std::min(m, k.v);
  return m;
}

}  // namespace recruit::sim
