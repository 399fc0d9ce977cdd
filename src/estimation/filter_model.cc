#include "estimation/filter_model.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "common/atomic_file.h"
#include "common/short_text.h"
#include "estimation/json_matrix.h"
#include "estimation/population_chain.h"

namespace recruit {

Eigen::MatrixXd FilterModel::ProcessNoise() const {
  const int m = num_states();
  if (G.cols() == 0) return Eigen::MatrixXd::Zero(m, m);
  return G * Qw * G.transpose();
}

Status FilterModel::Validate(const std::string& where) const {
  const int m = num_states();
  if (m < 1) return Error{where + ": states: needs at least one state name"};
  std::set<std::string> seen;
  for (const auto& s : state_names) {
    if (s.empty()) return Error{where + ": states: names must be non-empty"};
    if (!seen.insert(s).second)
      return Error{where + ": states: duplicate name '" + ShortText(s) + "'"};
  }
  if (N < 1)
    return Error{where + ": N: must be a positive number of agents, got " + std::to_string(N)};
  const int r = num_outputs();
  if (r < 1 || H.cols() != m) {
    return Error{where + ": H: must be r x " + std::to_string(m) + " with r >= 1, got " +
                 std::to_string(H.rows()) + " x " + std::to_string(H.cols())};
  }
  if (!H.allFinite()) return Error{where + ": H: entries must be finite"};
  if (R.rows() != r || R.cols() != r) {
    return Error{where + ": R: must be " + std::to_string(r) + " x " + std::to_string(r) +
                 " (one row and column per output), got " + std::to_string(R.rows()) + " x " +
                 std::to_string(R.cols())};
  }
  if (!R.allFinite()) return Error{where + ": R: entries must be finite"};
  if ((R - R.transpose()).cwiseAbs().maxCoeff() > 1e-12 * (1.0 + R.cwiseAbs().maxCoeff())) {
    return Error{where + ": R: must be symmetric"};
  }
  if (Eigen::LLT<Eigen::MatrixXd>(R).info() != Eigen::Success) {
    return Error{where + ": R: must be positive definite (measurement noise variance > 0)"};
  }
  if (G.rows() != m && !(G.rows() == 0 && G.cols() == 0)) {
    return Error{where + ": G: must have " + std::to_string(m) + " rows, got " +
                 std::to_string(G.rows())};
  }
  const Eigen::Index q = G.cols();
  if (Qw.rows() != q || Qw.cols() != q) {
    return Error{where + ": Qw: must be " + std::to_string(q) + " x " + std::to_string(q) +
                 " (G has " + std::to_string(q) + " columns), got " + std::to_string(Qw.rows()) +
                 " x " + std::to_string(Qw.cols())};
  }
  if (q > 0) {
    if (!G.allFinite() || !Qw.allFinite()) return Error{where + ": G, Qw: entries must be finite"};
    const double scale = 1.0 + Qw.cwiseAbs().maxCoeff();
    if ((Qw - Qw.transpose()).cwiseAbs().maxCoeff() > 1e-12 * scale) {
      return Error{where + ": Qw: must be symmetric"};
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Qw);
    if (es.eigenvalues().minCoeff() < -1e-12 * scale) {
      return Error{where + ": Qw: must be positive semi-definite"};
    }
    const Eigen::MatrixXd GQG = ProcessNoise();
    const double colsum = GQG.colwise().sum().cwiseAbs().maxCoeff();
    if (colsum > 1e-9 * (1.0 + GQG.cwiseAbs().maxCoeff())) {
      return Error{where +
                   ": G, Qw: G Qw G^T must have zero column sums (process noise may move "
                   "agents between states but cannot change the total N); max |column "
                   "sum| = " +
                   std::to_string(colsum)};
    }
  }
  switch (transition) {
    case TransitionSource::kBroadcast:
      if (broadcast.num_states() != m) {
        return Error{where + ": transition: broadcast model has " +
                     std::to_string(broadcast.num_states()) + " states, the model " +
                     std::to_string(m)};
      }
      if (Status s = broadcast.Validate(where + ": transition"); !s.ok()) return s;
      break;
    case TransitionSource::kConstant:
      if (Status s = ValidateColumnStochastic(A, kStochasticTolerance, m, where + ": transition.A");
          !s.ok()) {
        return s;
      }
      break;
    case TransitionSource::kExplicit:
      break;
  }
  if (x0.size() != m) {
    return Error{where + ": initial.x0: must have " + std::to_string(m) + " entries"};
  }
  if (!x0.allFinite() || (x0.array() < 0).any()) {
    return Error{where + ": initial.x0: entries must be finite and >= 0 (expected counts)"};
  }
  if (std::abs(x0.sum() - static_cast<double>(N)) > 1e-9 * static_cast<double>(N)) {
    return Error{where + ": initial.x0: must sum to N = " + std::to_string(N) + ", sums to " +
                 std::to_string(x0.sum())};
  }
  if (P0.rows() != m || P0.cols() != m || !P0.allFinite()) {
    return Error{where + ": initial.P0: must be a finite " + std::to_string(m) + " x " +
                 std::to_string(m) + " matrix"};
  }
  const double pscale = 1.0 + P0.cwiseAbs().maxCoeff();
  if ((P0 - P0.transpose()).cwiseAbs().maxCoeff() > 1e-9 * pscale) {
    return Error{where + ": initial.P0: must be symmetric"};
  }
  if (Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P0).eigenvalues().minCoeff() <
      -1e-9 * pscale) {
    return Error{where + ": initial.P0: must be positive semi-definite"};
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
  auto text = ReadFile(path);
  if (!text.ok()) return Error{text.error(), text.code()};
  auto j = json_io::ParseJson(*text, path);
  if (!j.ok()) return Error{j.error(), j.code()};
  return FromJsonValue(*j, path);
}

Result<FilterModel> FilterModel::FromJsonValue(const nlohmann::json& j, const std::string& where) {
  if (!j.is_object()) return Error{where + ": must be a JSON object"};
  FilterModel f;
  if (j.contains("format") &&
      !(j["format"].is_string() && j["format"].get<std::string>() == "recruit.filter_model")) {
    return Error{where + ": format: must be \"recruit.filter_model\""};
  }
  if (!j.contains("states") || !j["states"].is_array() || j["states"].empty()) {
    return Error{where + ": states: required, a non-empty array of state names"};
  }
  for (const auto& s : j["states"]) {
    if (!s.is_string()) return Error{where + ": states: every entry must be a string"};
    f.state_names.push_back(s.get<std::string>());
  }
  const int m = f.num_states();
  if (!j.contains("N") || !j["N"].is_number_integer() || j["N"].get<int64_t>() < 1) {
    return Error{where + ": N: required, a positive integer (number of agents)"};
  }
  f.N = j["N"].get<int64_t>();
  if (!j.contains("H")) return Error{where + ": H: required, r x " + std::to_string(m) + " matrix"};
  auto H = json_io::ReadMatrix(j["H"], where + ": H", -1, m);
  if (!H.ok()) return Error{H.error(), H.code()};
  f.H = *H;
  const int r = static_cast<int>(f.H.rows());
  if (r < 1) return Error{where + ": H: needs at least one row (output)"};
  if (!j.contains("R"))
    return Error{where + ": R: required, " + std::to_string(r) + " x " + std::to_string(r) +
                 " measurement noise covariance"};
  auto R = json_io::ReadMatrix(j["R"], where + ": R", r, r);
  if (!R.ok()) return Error{R.error(), R.code()};
  f.R = *R;
  if (j.contains("G") != j.contains("Qw")) {
    return Error{where + ": G and Qw: give both or neither (no process noise)"};
  }
  if (j.contains("G")) {
    auto G = json_io::ReadMatrix(j["G"], where + ": G", m, -1);
    if (!G.ok()) return Error{G.error(), G.code()};
    f.G = *G;
    const int q = static_cast<int>(f.G.cols());
    auto Qw = json_io::ReadMatrix(j["Qw"], where + ": Qw", q, q);
    if (!Qw.ok()) return Error{Qw.error(), Qw.code()};
    f.Qw = *Qw;
  } else {
    f.G = Eigen::MatrixXd::Zero(m, 0);
    f.Qw = Eigen::MatrixXd::Zero(0, 0);
  }
  if (!j.contains("transition") || !j["transition"].is_object() ||
      !j["transition"].contains("type") || !j["transition"]["type"].is_string()) {
    return Error{where +
                 ": transition: required, an object with \"type\": \"broadcast\", "
                 "\"explicit\" or \"constant\""};
  }
  const auto& t = j["transition"];
  const std::string type = t["type"].get<std::string>();
  if (type == "broadcast") {
    f.transition = TransitionSource::kBroadcast;
    auto b = BroadcastTransitionModel::FromJsonValue(t, f.state_names, where + ": transition");
    if (!b.ok()) return Error{b.error(), b.code()};
    f.broadcast = *b;
  } else if (type == "explicit") {
    f.transition = TransitionSource::kExplicit;
  } else if (type == "constant") {
    f.transition = TransitionSource::kConstant;
    if (!t.contains("A")) return Error{where + ": transition.A: required for type \"constant\""};
    auto A = json_io::ReadMatrix(t["A"], where + ": transition.A", m, m);
    if (!A.ok()) return Error{A.error(), A.code()};
    f.A = *A;
  } else {
    return Error{where + ": transition.type: \"" + ShortText(type) +
                 "\" is not one of \"broadcast\", \"explicit\", \"constant\""};
  }
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0(0) = static_cast<double>(f.N);
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  if (j.contains("initial")) {
    const auto& in = j["initial"];
    if (!in.is_object()) return Error{where + ": initial: must be an object {x0, P0}"};
    if (in.contains("x0")) {
      auto x0 = json_io::ReadVector(in["x0"], where + ": initial.x0", m);
      if (!x0.ok()) return Error{x0.error(), x0.code()};
      f.x0 = *x0;
    }
    if (in.contains("P0")) {
      auto P0 = json_io::ReadMatrix(in["P0"], where + ": initial.P0", m, m);
      if (!P0.ok()) return Error{P0.error(), P0.code()};
      f.P0 = *P0;
    }
  }
  if (Status s = f.Validate(where); !s.ok()) return Error{s.error(), s.code()};
  const nlohmann::json* r2 = &j;
  for (const char* key : {"identification", "holdout", "r2"}) {
    r2 = r2->is_object() && r2->contains(key) ? &(*r2)[key] : nullptr;
    if (r2 == nullptr) break;
  }
  if (r2 != nullptr && r2->is_number()) f.holdout_r2 = r2->get<double>();
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
        "format", "version",    "states",  "N",     "H",        "R",         "G",
        "Qw",     "type",       "dt",      "is_on", "interior", "on_target", "off_target",
        "A",      "transition", "initial", "x0",    "P0"};
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
  f.G = Eigen::MatrixXd::Zero(2, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = TransitionSource::kBroadcast;
  f.x0 = Eigen::Vector2d(static_cast<double>(N), 0.0);
  f.P0 = Eigen::MatrixXd::Zero(2, 2);
  return f;
}

}  // namespace recruit
