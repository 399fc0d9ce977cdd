#include "estimation/broadcast_transition_model.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/json_fields.h"
#include "common/short_text.h"
#include "estimation/json_matrix.h"
#include "estimation/population_chain.h"

namespace recruit::estimation {

Eigen::SparseMatrix<double> BroadcastTransitionModel::SparsePattern() const {
  const int m = num_states();
  std::vector<Eigen::Triplet<double>> entries;
  for (int j = 0; j < m; ++j) {
    const int target = is_on[j] ? off_target[j] : on_target[j];
    for (int i = 0; i < m; ++i) {
      if (interior(i, j) != 0.0 || i == target) entries.emplace_back(i, j, 0.0);
    }
  }
  Eigen::SparseMatrix<double> A(m, m);
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  FillSparse(0.0, 0.0, A);
  return A;
}

Eigen::MatrixXd BroadcastTransitionModel::Matrix(double p_on, double p_off) const {
  Eigen::MatrixXd A(num_states(), num_states());
  FillMatrix(p_on, p_off, A);
  return A;
}

BroadcastTransitionModel BroadcastTransitionModel::TwoState(double dt) {
  BroadcastTransitionModel b;
  b.state_names = {"off", "on"};
  b.is_on = {false, true};
  b.interior = Eigen::MatrixXd::Identity(2, 2);
  b.on_target = {1, -1};
  b.off_target = {-1, 0};
  b.dt = dt;
  return b;
}

BroadcastTransitionModel BroadcastTransitionModel::HeatingChain(int m, double dt) {
  BroadcastTransitionModel b;
  const int h = m / 2;
  const int cooling = m - 1 - h;  // states h+1..m-1
  b.interior = Eigen::MatrixXd::Zero(m, m);
  b.interior(0, 0) = 1.0;
  for (int i = 1; i <= h; ++i) {
    if (i < h) {
      b.interior(i, i) = 0.5;
      b.interior(i + 1, i) = 0.5;
    } else {
      b.interior(i, i) = 1.0;
    }
  }
  for (int c = h + 1; c < m; ++c) {
    b.interior(c, c) = 0.5;
    b.interior(c + 1 < m ? c + 1 : 0, c) += 0.5;
  }
  for (int i = 0; i < m; ++i) {
    b.state_names.push_back(i == 0   ? "off"
                            : i <= h ? "heat" + std::to_string(i)
                                     : "cool" + std::to_string(i - h));
    b.is_on.push_back(i >= 1 && i <= h);
    b.on_target.push_back(b.is_on[i] ? -1 : 1);
    // On state i (temperature i / h) to the cooling state at about that temperature.
    int off = 0;
    if (b.is_on[i] && cooling > 0) off = h + 1 + (cooling - 1) * (h - i) / std::max(1, h - 1);
    b.off_target.push_back(b.is_on[i] ? off : -1);
  }
  b.dt = dt;
  return b;
}

Status BroadcastTransitionModel::Validate(const std::string& where) const {
  const int m = num_states();
  if (m < 1) return Error{where + ": needs at least one state"};
  if (static_cast<int>(is_on.size()) != m) {
    return Error{where + ".is_on: must have " + std::to_string(m) +
                 " entries (one per state), got " + std::to_string(is_on.size())};
  }
  if (static_cast<int>(on_target.size()) != m || static_cast<int>(off_target.size()) != m) {
    return Error{where + ": on_target and off_target must have " + std::to_string(m) +
                 " entries (one per state)"};
  }
  if (Status s = ValidateColumnStochastic(interior, kStochasticTolerance, m, where + ".interior");
      !s.ok()) {
    return s;
  }
  for (int j = 0; j < m; ++j) {
    const int t = is_on[j] ? off_target[j] : on_target[j];
    const char* field = is_on[j] ? ".off_target" : ".on_target";
    if (t < 0 || t >= m) {
      return Error{where + field + "[" + std::to_string(j) + "] = " + std::to_string(t) +
                   " (state '" + ShortText(state_names[j]) + "', " + (is_on[j] ? "on" : "off") +
                   ") must be a state index in [0, " + std::to_string(m - 1) + "]"};
    }
  }
  if (!(std::isfinite(dt) && dt > 0.0)) {
    return Error{where + ".dt: must be a positive number of seconds, got " + std::to_string(dt)};
  }
  return Status::Ok();
}

Status BroadcastTransitionModel::ValidateInputs(double p_on, double p_off,
                                                const std::string& where) {
  if (!(std::isfinite(p_on) && p_on >= 0.0 && p_on <= 1.0)) {
    return Error{where + ": p_on = " + std::to_string(p_on) + " must be a probability in [0, 1]"};
  }
  if (!(std::isfinite(p_off) && p_off >= 0.0 && p_off <= 1.0)) {
    return Error{where + ": p_off = " + std::to_string(p_off) + " must be a probability in [0, 1]"};
  }
  return Status::Ok();
}

namespace {

// on_target / off_target: one state index for every state, or an array with one per state.
Status ReadTargets(const nlohmann::json& j, const std::string& key, const std::string& where, int m,
                   std::vector<int>* out) {
  const std::string allowed =
      "a state index, or an array of " + std::to_string(m) + " state indices (-1 where unused)";
  constexpr std::int64_t lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
  std::vector<std::int64_t> t;
  if (j.contains(key) && j.at(key).is_number()) {
    std::int64_t one = 0;
    RECRUIT_TRY(json_fields::Integer(j, key, where, &one, true, lo, hi, allowed));
    t.assign(m, one);
  } else {
    RECRUIT_TRY(json_fields::Integers(j, key, where, &t, true, m, lo, hi, allowed));
  }
  out->assign(t.begin(), t.end());
  return Status::Ok();
}

}  // namespace

Result<BroadcastTransitionModel> BroadcastTransitionModel::FromJsonValue(
    const nlohmann::json& j, const std::vector<std::string>& names, const std::string& where) {
  if (!j.is_object()) return Error{where + ": must be an object"};
  BroadcastTransitionModel b;
  b.state_names = names;
  const int m = static_cast<int>(names.size());
  RECRUIT_TRY(json_fields::Number(j, "dt", where, &b.dt, true, 0.0,
                                  std::numeric_limits<double>::max(), /*lo_open=*/true,
                                  "the sampling period in seconds, a number > 0"));
  RECRUIT_TRY(json_fields::Booleans(
      j, "is_on", where, &b.is_on, true, m,
      "an array of " + std::to_string(m) + " booleans (the heater command in each state)"));
  b.interior = Eigen::MatrixXd::Identity(m, m);  // when "interior" is omitted
  RECRUIT_TRY(json_fields::Matrix(j, "interior", where, &b.interior, false, m, m));
  RECRUIT_TRY(ReadTargets(j, "on_target", where, m, &b.on_target));
  RECRUIT_TRY(ReadTargets(j, "off_target", where, m, &b.off_target));
  // Entries that do not apply (on_target of an on state, ...) are normalised to -1.
  for (int i = 0; i < m; ++i) {
    if (b.is_on[i])
      b.on_target[i] = -1;
    else
      b.off_target[i] = -1;
  }
  RECRUIT_TRY(b.Validate(where));
  return b;
}

nlohmann::json BroadcastTransitionModel::ToJson() const {
  nlohmann::json j;
  j["type"] = "broadcast";
  j["dt"] = dt;
  j["is_on"] = is_on;
  j["interior"] = json_io::WriteMatrix(interior);
  j["on_target"] = on_target;
  j["off_target"] = off_target;
  return j;
}

}  // namespace recruit::estimation
