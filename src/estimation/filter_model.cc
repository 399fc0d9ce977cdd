#include "estimation/filter_model.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>
#include <utility>

#include "common/atomic_file.h"
#include "common/json_fields.h"
#include "common/short_text.h"
#include "estimation/filter_model_cache.h"
#include "estimation/json_matrix.h"
#include "estimation/population_chain.h"
#include "estimation/transit_weights.h"

namespace recruit::estimation {

Eigen::MatrixXd FilterModel::ProcessNoise() const {
  const int m = num_states();
  if (G.cols() == 0) return Eigen::MatrixXd::Zero(m, m);
  return G * Qw * G.transpose();
}

Eigen::VectorXd FilterModel::TransitWeights() const {
  const int m = num_states();
  if (transition != TransitionSource::kBroadcast || broadcast.interior.rows() != m) {
    return Eigen::VectorXd::Zero(m);
  }
  return estimation::TransitWeights(broadcast.interior, H);
}

namespace {

// R_transit and R_transit2: each empty (none) or r x r, finite, symmetric PSD; only with a
// broadcast transition, whose interior defines the states in transit.
Status ValidateTransitNoise(const FilterModel& f, const std::string& where) {
  for (const auto& [name, T] :
       {std::pair<const char*, const Eigen::MatrixXd*>{"R_transit", &f.R_transit},
        {"R_transit2", &f.R_transit2}}) {
    if (T->size() == 0) continue;
    const int r = f.num_outputs();
    const std::string w = where + "." + name;
    if (T->rows() != r || T->cols() != r) {
      return Error{w + ": must be " + std::to_string(r) + " x " + std::to_string(r) +
                   " (as R), got " + std::to_string(T->rows()) + " x " + std::to_string(T->cols())};
    }
    if (!T->allFinite()) return Error{w + ": entries must be finite"};
    const double scale = 1.0 + T->cwiseAbs().maxCoeff();
    if ((*T - T->transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) {
      return Error{w + ": must be symmetric"};
    }
    if (Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(*T).eigenvalues().minCoeff() <
        -1e-12 * scale) {
      return Error{w + ": must be positive semi-definite (a variance >= 0)"};
    }
    if (FilterModel::NonZero(*T) && f.transition != TransitionSource::kBroadcast) {
      return Error{w +
                   ": needs a \"broadcast\" transition (its interior says which states are in "
                   "transit)"};
    }
  }
  return Status::Ok();
}

}  // namespace

Status FilterModel::Validate(const std::string& where) const {
  const int m = num_states();
  if (m < 1) return Error{where + ".states: needs at least one state name"};
  std::set<std::string> seen;
  for (const auto& s : state_names) {
    if (s.empty()) return Error{where + ".states: names must be non-empty"};
    if (!seen.insert(s).second)
      return Error{where + ".states: duplicate name '" + ShortText(s) + "'"};
  }
  if (N < 1)
    return Error{where + ".N: must be a positive number of agents, got " + std::to_string(N)};
  const int r = num_outputs();
  if (r < 1 || H.cols() != m) {
    return Error{where + ".H: must be r x " + std::to_string(m) + " with r >= 1, got " +
                 std::to_string(H.rows()) + " x " + std::to_string(H.cols())};
  }
  if (!H.allFinite()) return Error{where + ".H: entries must be finite"};
  if (R.rows() != r || R.cols() != r) {
    return Error{where + ".R: must be " + std::to_string(r) + " x " + std::to_string(r) +
                 " (one row and column per output), got " + std::to_string(R.rows()) + " x " +
                 std::to_string(R.cols())};
  }
  if (!R.allFinite()) return Error{where + ".R: entries must be finite"};
  if ((R - R.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + R.cwiseAbs().maxCoeff())) {
    return Error{where + ".R: must be symmetric"};
  }
  if (Eigen::LLT<Eigen::MatrixXd>(R).info() != Eigen::Success) {
    return Error{where + ".R: must be positive definite (measurement noise variance > 0)"};
  }
  if (Status s = ValidateTransitNoise(*this, where); !s.ok()) return s;
  if (G.rows() != m && !(G.rows() == 0 && G.cols() == 0)) {
    return Error{where + ".G: must have " + std::to_string(m) + " rows, got " +
                 std::to_string(G.rows())};
  }
  const Eigen::Index q = G.cols();
  if (Qw.rows() != q || Qw.cols() != q) {
    return Error{where + ".Qw: must be " + std::to_string(q) + " x " + std::to_string(q) +
                 " (G has " + std::to_string(q) + " columns), got " + std::to_string(Qw.rows()) +
                 " x " + std::to_string(Qw.cols())};
  }
  if (q > 0) {
    if (!G.allFinite() || !Qw.allFinite()) return Error{where + ".G, Qw: entries must be finite"};
    const double scale = 1.0 + Qw.cwiseAbs().maxCoeff();
    if ((Qw - Qw.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) {
      return Error{where + ".Qw: must be symmetric"};
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Qw);
    if (es.eigenvalues().minCoeff() < -1e-12 * scale) {
      return Error{where + ".Qw: must be positive semi-definite"};
    }
    const Eigen::MatrixXd GQG = ProcessNoise();
    const double colsum = GQG.colwise().sum().cwiseAbs().maxCoeff();
    if (colsum > 1e-9 * (1.0 + GQG.cwiseAbs().maxCoeff())) {
      return Error{where +
                   ".G, Qw: G Qw G^T must have zero column sums (process noise may move "
                   "agents between states but cannot change the total N); max |column "
                   "sum| = " +
                   GText(colsum)};
    }
  }
  switch (transition) {
    case TransitionSource::kBroadcast:
      if (broadcast.num_states() != m) {
        return Error{where + ".transition: the broadcast model has " +
                     std::to_string(broadcast.num_states()) + " states, the model " +
                     std::to_string(m)};
      }
      if (Status s = broadcast.Validate(where + ".transition"); !s.ok()) return s;
      break;
    case TransitionSource::kConstant:
      if (Status s = ValidateColumnStochastic(A, kStochasticTolerance, m, where + ".transition.A");
          !s.ok()) {
        return s;
      }
      break;
    case TransitionSource::kExplicit:
      break;
  }
  if (x0.size() != m) {
    return Error{where + ".initial.x0: must have " + std::to_string(m) + " entries"};
  }
  if (!x0.allFinite() || (x0.array() < 0).any()) {
    return Error{where + ".initial.x0: entries must be finite and >= 0 (expected counts)"};
  }
  if (std::abs(x0.sum() - static_cast<double>(N)) > 1e-9 * static_cast<double>(N)) {
    return Error{where + ".initial.x0: must sum to N = " + std::to_string(N) + ", sums to " +
                 GText(x0.sum())};
  }
  if (P0.rows() != m || P0.cols() != m || !P0.allFinite()) {
    return Error{where + ".initial.P0: must be a finite " + std::to_string(m) + " x " +
                 std::to_string(m) + " matrix"};
  }
  const double pscale = 1.0 + P0.cwiseAbs().maxCoeff();
  if ((P0 - P0.transpose()).cwiseAbs().maxCoeff() > 1e-9 * pscale) {
    return Error{where + ".initial.P0: must be symmetric"};
  }
  if (Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P0).eigenvalues().minCoeff() <
      -1e-9 * pscale) {
    return Error{where + ".initial.P0: must be positive semi-definite"};
  }
  return Status::Ok();
}

FilterModel FilterModel::WithPopulation(int64_t N_new) const {
  FilterModel f = *this;
  const double s = static_cast<double>(N_new) / static_cast<double>(N);
  f.N = N_new;
  f.x0 = x0 * s;
  f.P0 = P0 * s;
  return f;
}

Result<FilterModel> FilterModel::FromJson(const std::string& path) {
  auto parsed = ParseFilterModelFile(path);  // parsed once per process for each content
  if (!parsed.ok()) return parsed.failure();
  return (*parsed)->model;
}

namespace {

using json_fields::CheckKeys;

// The transition object of type `type`, read into f (its states known).
Status ReadTransition(const nlohmann::json& t, const std::string& type, const std::string& where,
                      FilterModel& f) {
  if (type == "broadcast") {
    RECRUIT_TRY(
        CheckKeys(t, {"type", "dt", "is_on", "interior", "on_target", "off_target"}, where));
    f.transition = TransitionSource::kBroadcast;
    auto b = BroadcastTransitionModel::FromJsonValue(t, f.state_names, where);
    if (!b.ok()) return b.failure();
    f.broadcast = *b;
  } else if (type == "explicit") {
    RECRUIT_TRY(CheckKeys(t, {"type"}, where));
    f.transition = TransitionSource::kExplicit;
  } else {
    RECRUIT_TRY(CheckKeys(t, {"type", "A"}, where));
    f.transition = TransitionSource::kConstant;
    const int m = f.num_states();
    RECRUIT_TRY(json_fields::Matrix(t, "A", where, &f.A, true, m, m));
  }
  return Status::Ok();
}

// identification.holdout.r2 when the file records it, else NaN.
double HoldoutR2(const nlohmann::json& j) {
  const nlohmann::json* r2 = &j;
  for (const char* key : {"identification", "holdout", "r2"}) {
    r2 = r2->is_object() && r2->contains(key) ? &(*r2)[key] : nullptr;
    if (r2 == nullptr) break;
  }
  return r2 != nullptr && r2->is_number() ? r2->get<double>()
                                          : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

Result<FilterModel> FilterModel::FromJsonValue(const nlohmann::json& j, const std::string& where) {
  using namespace json_fields;
  if (!j.is_object()) return Error{where + ": must be a JSON object"};
  RECRUIT_TRY(CheckKeys(j,
                        {"format", "version", "states", "N", "H", "R", "R_transit", "R_transit2",
                         "G", "Qw", "transition", "initial", "identification"},
                        where));
  std::string format;
  RECRUIT_TRY(OneOf(j, "format", where, &format, false, {"recruit.filter_model"}));
  std::int64_t version = 1;
  RECRUIT_TRY(Integer(j, "version", where, &version, false, 1, 1, "1 (the only version)"));
  FilterModel f;
  RECRUIT_TRY(Strings(j, "states", where, &f.state_names, true));
  const int m = f.num_states();
  RECRUIT_TRY(Integer(j, "N", where, &f.N, true, 1, std::numeric_limits<std::int64_t>::max(),
                      "a whole number of agents >= 1"));
  RECRUIT_TRY(Matrix(j, "H", where, &f.H, true, -1, m));
  const int r = static_cast<int>(f.H.rows());
  if (r < 1) return Error{where + ".H: must have at least one row (one per output), got none"};
  RECRUIT_TRY(Matrix(j, "R", where, &f.R, true, r, r));
  f.R_transit = Eigen::MatrixXd::Zero(r, r);
  RECRUIT_TRY(Matrix(j, "R_transit", where, &f.R_transit, false, r, r));
  f.R_transit2 = Eigen::MatrixXd::Zero(r, r);
  RECRUIT_TRY(Matrix(j, "R_transit2", where, &f.R_transit2, false, r, r));
  if (j.contains("G") != j.contains("Qw")) {
    return Error{where + ": missing field '" + (j.contains("G") ? "Qw" : "G") +
                 "' (G and Qw come together; neither: no process noise)"};
  }
  f.G = Eigen::MatrixXd::Zero(m, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  if (j.contains("G")) {
    RECRUIT_TRY(Matrix(j, "G", where, &f.G, true, m, -1));
    const int q = static_cast<int>(f.G.cols());
    RECRUIT_TRY(Matrix(j, "Qw", where, &f.Qw, true, q, q));
  }
  RECRUIT_TRY(Object(j, "transition", where, true,
                     "an object with \"type\": \"broadcast\", \"explicit\" or \"constant\""));
  const std::string tw = where + ".transition";
  std::string type;
  RECRUIT_TRY(
      OneOf(j["transition"], "type", tw, &type, true, {"broadcast", "explicit", "constant"}));
  RECRUIT_TRY(ReadTransition(j["transition"], type, tw, f));
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = static_cast<double>(f.N);
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  RECRUIT_TRY(Object(j, "initial", where, false, "{\"x0\", \"P0\"}"));
  if (j.contains("initial")) {
    const nlohmann::json& in = j["initial"];
    const std::string iw = where + ".initial";
    RECRUIT_TRY(CheckKeys(in, {"x0", "P0"}, iw));
    RECRUIT_TRY(Vector(in, "x0", iw, &f.x0, false, m));
    RECRUIT_TRY(Matrix(in, "P0", iw, &f.P0, false, m, m));
  }
  RECRUIT_TRY(Object(j, "identification", where, false, "what the model was identified from"));
  RECRUIT_TRY(f.Validate(where));
  f.holdout_r2 = HoldoutR2(j);
  return f;
}

nlohmann::json FilterModel::ToJson() const {
  nlohmann::json j;
  j["format"] = "recruit.filter_model";
  j["version"] = 1;
  j["states"] = state_names;
  j["N"] = N;
  j["H"] = json_io::WriteMatrix(H);
  j["R"] = json_io::WriteMatrix(R);
  if (NonZero(R_transit)) j["R_transit"] = json_io::WriteMatrix(R_transit);
  if (NonZero(R_transit2)) j["R_transit2"] = json_io::WriteMatrix(R_transit2);
  if (G.cols() > 0) {
    j["G"] = json_io::WriteMatrix(G);
    j["Qw"] = json_io::WriteMatrix(Qw);
  }
  switch (transition) {
    case TransitionSource::kBroadcast:
      j["transition"] = broadcast.ToJson();
      break;
    case TransitionSource::kExplicit:
      j["transition"] = {{"type", "explicit"}};
      break;
    case TransitionSource::kConstant:
      j["transition"] = {{"type", "constant"}, {"A", json_io::WriteMatrix(A)}};
      break;
  }
  j["initial"] = {{"x0", json_io::WriteVector(x0)}, {"P0", json_io::WriteMatrix(P0)}};
  return j;
}

namespace {

// Human-readable JSON: objects one key per line in a fixed order, matrices one row per line,
// everything else compact.
void WriteReadable(const nlohmann::json& v, int indent, std::string& out) {
  const std::string pad(indent, ' ');
  if (v.is_object()) {
    static const std::vector<std::string> order = {
        "format",     "version",    "states", "N",          "H",       "R",     "R_transit",
        "R_transit2", "G",          "Qw",     "type",       "dt",      "is_on", "interior",
        "on_target",  "off_target", "A",      "transition", "initial", "x0",    "P0"};
    std::vector<std::string> keys;
    for (const auto& k : order) {
      if (v.contains(k)) keys.push_back(k);
    }
    for (const auto& [k, _] : v.items()) {
      if (std::find(keys.begin(), keys.end(), k) == keys.end()) keys.push_back(k);
    }
    out += "{\n";
    for (size_t i = 0; i < keys.size(); ++i) {
      out += pad + "  " + nlohmann::json(keys[i]).dump() + ": ";
      WriteReadable(v[keys[i]], indent + 2, out);
      out += i + 1 < keys.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (v.is_array() && !v.empty() && v[0].is_array()) {
    out += "[\n";
    for (size_t i = 0; i < v.size(); ++i) {
      out += pad + "  " + v[i].dump() + (i + 1 < v.size() ? ",\n" : "\n");
    }
    out += pad + "]";
  } else {
    out += v.dump();
  }
}

}  // namespace

Status FilterModel::Save(const std::string& path) const {
  if (Status s = Validate(path); !s.ok()) return s;
  std::string text;
  WriteReadable(ToJson(), 0, text);
  return WriteFileAtomically(path, text + "\n");
}

FilterModel FilterModel::TwoState(int64_t N, double dt, double unit_force, double noise_std) {
  FilterModel f;
  f.broadcast = BroadcastTransitionModel::TwoState(dt);
  f.state_names = f.broadcast.state_names;
  f.N = N;
  f.H = Eigen::MatrixXd(1, 2);
  f.H << 0.0, unit_force;
  f.R = Eigen::MatrixXd::Constant(1, 1, noise_std * noise_std);
  f.R_transit = Eigen::MatrixXd::Zero(1, 1);
  f.R_transit2 = Eigen::MatrixXd::Zero(1, 1);
  f.G = Eigen::MatrixXd::Zero(2, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = TransitionSource::kBroadcast;
  f.x0 = Eigen::Vector2d(static_cast<double>(N), 0.0);
  f.P0 = Eigen::MatrixXd::Zero(2, 2);
  return f;
}

}  // namespace recruit::estimation
