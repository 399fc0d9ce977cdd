#include "export/controller_export.h"

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <vector>

#include "common/version.h"
#include "control/kalman_estimator.h"
#include "control/output_estimator.h"
#include "control/unit_force_map.h"
#include "export/auto_loop_export.h"
#include "export/c_writer.h"
#include "export/templates.h"

namespace recruit::exporter {
namespace {

// One bundle's constants, in double (rounded to float when written for a float package).
struct BundleConstants {
  std::string actuator;
  int m = 0;  // 0: output estimator
  double N = 0, lambda = 0, unit_force = 0;
  bool length_aware = false;
  double prestretch = 0, ref_length = 0, on_k = 0, on_c = 0;
  std::vector<int> ptr, col, target, is_on;
  std::vector<double> base, k, c, h, x0, P0, gqg;  // P0, gqg packed; empty = none
  std::vector<double> transit;                     // FilterModel::TransitWeights; empty: none
  double R = 0, relative_noise = 0, R_transit = 0, R_transit2 = 0;
};

// The unit's stiffness at fraction xi: sma::UnitModel's arithmetic (wire in series with the
// coupling spring when it has one).
double Stiffness(const sma::UnitModel& u, double xi) {
  const double ka = u.stiffness_austenite(), km = u.stiffness_martensite();
  const double ks = u.series_stiffness();
  const double kw = ka + xi * (km - ka);
  if (ks <= 0) return kw;
  const double inv = 1.0 / (kw + ks);
  return kw * ks * inv;
}

// The upper triangle of a symmetric matrix packed by columns; empty when it is all zero.
std::vector<double> Packed(const Eigen::MatrixXd& P) {
  std::vector<double> out;
  bool zero = true;
  for (int j = 0; j < P.cols(); ++j) {
    for (int i = 0; i <= j; ++i) {
      out.push_back(P(i, j));
      zero &= P(i, j) == 0.0;
    }
  }
  if (zero) out.clear();
  return out;
}

// The filter's compressed rows of the broadcast A (PopulationKalmanFilterT::Create's layout:
// rows in order, columns ascending within a row).
void SparseRows(const estimation::BroadcastTransitionModel& b, BundleConstants& out) {
  const int m = b.num_states();
  const Eigen::SparseMatrix<double> A = b.SparsePattern();
  out.ptr.assign(m + 1, 0);
  for (int l = 0; l < m; ++l) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) ++out.ptr[it.row() + 1];
  }
  for (int i = 0; i < m; ++i) out.ptr[i + 1] += out.ptr[i];
  const int nnz = out.ptr[m];
  out.col.assign(nnz, 0);
  out.base.assign(nnz, 0.0);
  out.target.assign(nnz, 0);
  std::vector<int> next(out.ptr.begin(), out.ptr.end() - 1);
  for (int l = 0; l < m; ++l) {
    const int target = b.is_on[l] ? b.off_target[l] : b.on_target[l];
    for (Eigen::SparseMatrix<double>::InnerIterator it(A, l); it; ++it) {
      const int i = static_cast<int>(it.row());
      const int e = next[i]++;
      out.col[e] = l;
      out.base[e] = b.interior(i, l);
      out.target[e] = i == target ? 1 : 0;
    }
  }
  out.is_on.assign(m, 0);
  for (int l = 0; l < m; ++l) out.is_on[l] = b.is_on[l] ? 1 : 0;
}

Result<BundleConstants> Constants(const sim::BundleController& bc, const std::string& where) {
  const control::RecruitmentController& c = bc.controller;
  const control::ControllerParams& p = c.params();
  BundleConstants out;
  out.actuator = bc.actuator;
  out.N = p.num_units;
  out.lambda = p.lambda;
  out.unit_force = p.unit_force;
  if (p.geometry) {
    out.length_aware = true;
    out.prestretch = p.geometry->unit.prestretch;
    out.ref_length = p.geometry->ref_length;
    // The controller's own map of the settled on unit (RecruitmentController::Create).
    auto on = control::UnitForceMap::FromForces(*p.geometry, p.geometry->unit.prestretch,
                                                Eigen::VectorXd::Constant(1, p.unit_force));
    if (!on) return on.failure().In(where + ": ");
    out.on_k = Stiffness(on->unit(), on->fractions()[0]);
    out.on_c = on->fractions()[0] * on->unit().recoverable_stretch();
  }
  if (dynamic_cast<const control::OutputOnlyEstimator*>(&c.estimator()) != nullptr) return out;
  const auto* k = dynamic_cast<const control::KalmanOnCountEstimator*>(&c.estimator());
  if (k == nullptr) return Error{where + ": this estimator cannot be exported"};
  if (k->filter().mode() != estimation::CovarianceMode::kExtended) {
    return Error{where + ": only the extended covariance mode is exported"};
  }
  const estimation::FilterModel& model = k->model();
  out.m = model.num_states();
  if (out.m > 255 || model.num_outputs() != 1) {
    return Error{where + ": the C package holds models of at most 255 states and one output, " +
                 "this one has " + std::to_string(out.m) + " states"};
  }
  out.N = static_cast<double>(model.N);
  SparseRows(model.broadcast, out);
  out.h.assign(model.H.data(), model.H.data() + out.m);
  out.R = model.R(0, 0);
  out.relative_noise = k->relative_noise();
  if (model.has_transit_noise()) {
    std::tie(out.R_transit, out.R_transit2) = model.ScalarTransitNoise();
    const Eigen::VectorXd weights = model.TransitWeights();
    out.transit.assign(weights.data(), weights.data() + out.m);
  }
  out.x0.assign(model.x0.data(), model.x0.data() + out.m);
  out.P0 = Packed(model.P0);
  if (model.G.cols() > 0) {
    out.gqg = Packed(model.ProcessNoise());
  }
  out.length_aware = k->output().has_value() && p.geometry.has_value();
  if (k->output()) {
    const control::UnitForceMap& map = *k->output();
    for (int i = 0; i < out.m; ++i) {
      const double xi = map.fractions()[i];
      out.k.push_back(Stiffness(map.unit(), xi));
      out.c.push_back(xi * map.unit().recoverable_stretch());
    }
  }
  return out;
}

std::string BundleBlock(const BundleConstants& b, int i, const Writer& w) {
  const std::string n = "b" + std::to_string(i) + "_";
  std::string s = "/* Bundle " + std::to_string(i) + ": \"" + b.actuator + "\", " +
                  (b.m > 0 ? std::to_string(b.m) + "-state population Kalman filter"
                           : std::string("output estimator")) +
                  ". */\n";
  if (b.m > 0) {
    s += w.Array("uint16_t", n + "ptr", b.ptr, false);
    s += w.Array("uint8_t", n + "col", b.col, false);
    s += w.Array("uint8_t", n + "target", b.target, false);
    s += w.Array("uint8_t", n + "is_on", b.is_on, false);
    s += w.Array("recruit_real", n + "base", b.base, true);
    s += w.Array("recruit_real", n + "h", b.h, true);
    s += w.Array("recruit_real", n + "x0", b.x0, true);
    if (!b.k.empty()) s += w.Array("recruit_real", n + "k", b.k, true);
    if (!b.c.empty()) s += w.Array("recruit_real", n + "c", b.c, true);
    if (!b.P0.empty()) s += w.Array("recruit_real", n + "P0", b.P0, true);
    if (!b.gqg.empty()) s += w.Array("recruit_real", n + "gqg", b.gqg, true);
    if (!b.transit.empty()) s += w.Array("recruit_real", n + "transit", b.transit, true);
  }
  const bool kf = b.m > 0;
  auto field = [](const std::string& name, const std::string& value) {
    return "    ." + name + " = " + value + ",\n";
  };
  s += "static const recruit_bundle_params " + n + "params = {\n";
  s += field("m", std::to_string(b.m)) + field("N", w.Num(b.N)) + field("lambda", w.Num(b.lambda)) +
       field("unit_force", w.Num(b.unit_force));
  s += field("length_aware", b.length_aware ? "1" : "0") +
       field("prestretch", w.Num(b.prestretch)) + field("ref_length", w.Num(b.ref_length)) +
       field("on_k", w.Num(b.on_k)) + field("on_c", w.Num(b.on_c));
  if (kf) {
    s += field("ptr", n + "ptr") + field("col", n + "col") + field("target", n + "target") +
         field("is_on", n + "is_on") + field("base", n + "base");
    if (!b.k.empty()) s += field("k", n + "k") + field("c", n + "c");
    s += field("h", n + "h") + field("R", w.Num(b.R)) +
         field("relative_noise", w.Num(b.relative_noise)) + field("x0", n + "x0");
    if (!b.transit.empty()) {
      s += field("R_transit", w.Num(b.R_transit)) + field("R_transit2", w.Num(b.R_transit2)) +
           field("transit", n + "transit");
    }
    if (!b.P0.empty()) s += field("P0", n + "P0");
    if (!b.gqg.empty()) s += field("gqg", n + "gqg");
  }
  s += "};\n\n";
  return s;
}

std::string OuterLoopBlock(const sim::Task& task, int nb, double dT, const Writer& w) {
  std::string s =
      "/* The force references (src/sim/run_task.cc, ForceReferences): " +
      std::string(task.tracked == sim::Tracked::kForce
                      ? "the force task's reference goes to the first bundle. */\n"
                      : "PI(D) on the joint angle with anti-windup and gravity feedforward; its "
                        "net force goes to the agonist (> 0) or the antagonist (< 0) on top of "
                        "the tone, clamped to [0, max_force]. */\n");
  if (task.tracked == sim::Tracked::kForce) {
    s += "static void force_references(recruit_controller *c, const recruit_input *in,\n"
         "                             recruit_real *fr) {\n"
         "  int i;\n  (void)c;\n"
         "  for (i = 0; i < RECRUIT_NUM_BUNDLES; ++i) fr[i] = RK(0);\n"
         "  fr[0] = in->reference;\n}\n";
    return s;
  }
  const sim::OuterLoop& g = *task.outer;
  s += "static const recruit_real kp = " + w.Num(g.kp) + ", ki = " + w.Num(g.ki) +
       ", kd = " + w.Num(g.kd) + ";\n";
  s += "static const recruit_real feedforward = " + w.Num(g.feedforward) +
       ", tone = " + w.Num(g.tone) + ", max_force = " + w.Num(g.max_force) + ";\n";
  s += "static const recruit_real dT = " + w.Num(dT) + ";\n";
  s += "static void force_references(recruit_controller *c, const recruit_input *in,\n"
       "                             recruit_real *fr) {\n"
       "  const recruit_real e = in->reference - in->angle;\n"
       "  const recruit_real ff = feedforward * SIN(in->reference);\n"
       "  const recruit_real unsat =\n"
       "      kp * e + ki * (c->integral + e * dT) - kd * in->angular_velocity + ff;\n"
       "  recruit_real u;\n"
       "  /* Integrate only while the command is not saturated the same way (anti-windup). */\n"
       "  if (FABS(unsat) < max_force || unsat * e < 0) c->integral += e * dT;\n"
       "  u = kp * e + ki * c->integral - kd * in->angular_velocity + ff;\n";
  if (nb == 1) {
    s += "  fr[0] = clampr(tone + u, RK(0), max_force);\n}\n";
  } else {
    s += "  fr[0] = clampr(tone + (u < 0 ? RK(0) : u), RK(0), max_force);\n"
         "  fr[1] = clampr(tone + (-u < 0 ? RK(0) : -u), RK(0), max_force);\n}\n";
  }
  return s;
}

void ReplaceAll(std::string& s, const std::string& key, const std::string& value) {
  for (size_t at = 0; (at = s.find(key, at)) != std::string::npos; at += value.size()) {
    s.replace(at, key.size(), value);
  }
}

}  // namespace

Result<Precision> ParsePrecision(const std::string& name) {
  if (name == "double") return Precision::kDouble;
  if (name == "float") return Precision::kFloat;
  return Error{"precision \"" + name + "\" is not one of \"double\", \"float\""};
}

std::vector<ExportedFile> UnitPackage() {
  return {{"recruit_unit.h", templates::kUnitH}, {"recruit_unit.c", templates::kUnitC}};
}

Result<ExportedPackage> ExportController(const sim::Task& task, const sim::RunOptions& options,
                                         Precision precision) {
  const std::string where = task.source.empty() ? task.name : task.source;
  if (task.tracked == sim::Tracked::kAngle && !task.outer && !task.auto_loop) {
    return Error{where + ": an angle task needs its outer_loop gains to be exported"};
  }
  const sim::ControllerSettings settings = sim::EffectiveSettings(task, options);
  if (!(settings.dT > 0) || !std::isfinite(settings.dT)) {
    return Error{where + ": controller.dT must be finite and > 0 s"};
  }
  if (task.controller.census_period > 0) {
    char period[32];
    std::snprintf(period, sizeof period, "%g", task.controller.census_period);
    return Error{where + ": controller.census_period: " + period +
                 "; the exported controller has no census (docs/failures.md): export the task "
                 "with census_period 0"};
  }
  auto controllers = sim::TaskControllers(task, options);
  if (!controllers) return controllers.failure();
  std::vector<BundleConstants> bundles;
  for (const sim::BundleController& bc : *controllers) {
    auto b = Constants(bc, where + ": bundle '" + bc.actuator + "'");
    if (!b) return b.failure();
    bundles.push_back(std::move(b).value());
  }
  const int nb = static_cast<int>(bundles.size());
  const Writer w(precision);
  LoopCode loop;
  std::vector<std::string> notes;
  nlohmann::json poses = nlohmann::json::array();
  if (task.auto_loop) {
    auto frozen = FreezeAutoLoop(task, options, *controllers);
    if (!frozen) return Error{frozen.error(), frozen.code()};
    loop = AutoLoopCode(*frozen, w);
    notes = frozen->notes;
    for (const FrozenPose& p : frozen->poses) {
      nlohmann::json gains = nlohmann::json::array();
      for (const FrozenJointSetting& g : p.joint) {
        gains.push_back({{"kp", g.kp}, {"ki", g.ki}, {"kd", g.kd}, {"holds", g.holds}});
      }
      poses.push_back({{"reference_rad", p.reference},
                       {"first_time", p.first_time},
                       {"feedforward", p.feedforward},
                       {"gains", gains}});
    }
  } else {
    loop.state = "  recruit_real integral; /* rad s */";
    loop.input =
        "  recruit_real reference;        /* the task's reference: N (force task) or rad (angle "
        "task) */\n"
        "  recruit_real angle;            /* rad, the joint encoder (angle tasks) */\n"
        "  recruit_real angular_velocity; /* rad/s (angle tasks) */";
    loop.init = "  c->integral = RK(0);";
    loop.outer = OuterLoopBlock(task, nb, settings.dT, w);
  }
  // At least a 2-state filter's room: an output-estimator package's (unused) filter code
  // then indexes no array of length 1 (which compilers warn of).
  int mmax = 2, nnzmax = 4;
  for (const BundleConstants& b : bundles) {
    mmax = std::max(mmax, b.m);
    if (b.m > 0) nnzmax = std::max(nnzmax, b.ptr.back());
  }
  const bool f = precision == Precision::kFloat;
  char settings_line[300];
  std::snprintf(settings_line, sizeof settings_line,
                "estimator %s, dT %g s, lambda %g, %d bundle(s), %s", settings.estimator.c_str(),
                settings.dT, settings.lambda, nb, f ? "float" : "double");
  std::string constants;
  for (int i = 0; i < nb; ++i) constants += BundleBlock(bundles[i], i, w);
  constants +=
      "static const recruit_bundle_params *const recruit_bundles[" + std::to_string(nb) + "] = {";
  for (int i = 0; i < nb; ++i) constants += (i ? ", &b" : "&b") + std::to_string(i) + "_params";
  constants += "};\n";

  char dt_text[40];
  std::snprintf(dt_text, sizeof dt_text, "%g", settings.dT);
  std::string h = templates::kControllerH, c = templates::kControllerC;
  for (std::string* s : {&h, &c}) {
    ReplaceAll(*s, "@TASK@", task.name);
    ReplaceAll(*s, "@VERSION@", std::string(ProjectVersion()) + " (" + CodeVersion() + ")");
    ReplaceAll(*s, "@SETTINGS@", settings_line);
    ReplaceAll(*s, "@MATH@",
               task.auto_loop ? (f ? "sqrtf, fabsf, floorf, ceilf" : "sqrt, fabs, floor, ceil")
                              : (f ? "sqrtf, sinf, fabsf" : "sqrt, sin, fabs"));
    ReplaceAll(*s, "@LOOP_DEFINES@", loop.defines);
    ReplaceAll(*s, "@LOOP_STATE@", loop.state);
    ReplaceAll(*s, "@LOOP_INPUT@", loop.input);
    ReplaceAll(*s, "@LOOP_INIT@", loop.init);
    ReplaceAll(*s, "@REAL@", f ? "float" : "double");
    ReplaceAll(*s, "@NB@", std::to_string(nb));
    ReplaceAll(*s, "@MMAX@", std::to_string(mmax));
    ReplaceAll(*s, "@NNZMAX@", std::to_string(nnzmax));
    ReplaceAll(*s, "@ANGLE@", task.tracked == sim::Tracked::kAngle ? "1" : "0");
    ReplaceAll(*s, "@DT@", dt_text);
    ReplaceAll(*s, "@SQRT@", f ? "sqrtf" : "sqrt");
    ReplaceAll(*s, "@SIN@", f ? "sinf" : "sin");
    ReplaceAll(*s, "@FABS@", f ? "fabsf" : "fabs");
  }
  ReplaceAll(c, "@CONSTANTS@", constants);
  ReplaceAll(c, "@OUTER@", loop.outer);

  ExportedPackage pkg;
  pkg.summary = "task " + task.name + ": " + settings_line;
  nlohmann::json manifest = {{"task", task.name},
                             {"task_file", task.source},
                             {"estimator", settings.estimator},
                             {"dT", settings.dT},
                             {"lambda", settings.lambda},
                             {"precision", f ? "float" : "double"},
                             {"tracked", task.tracked == sim::Tracked::kAngle ? "angle" : "force"},
                             {"recruit_version", ProjectVersion()},
                             {"code_version", CodeVersion()}};
  nlohmann::json jb = nlohmann::json::array();
  for (const BundleConstants& b : bundles) {
    jb.push_back({{"actuator", b.actuator},
                  {"states", b.m},
                  {"units", static_cast<long>(b.N)},
                  {"length_aware", b.length_aware}});
  }
  manifest["bundles"] = jb;
  if (task.auto_loop) {
    manifest["outer_loop"] = "auto";
    manifest["poses"] = poses;
    manifest["notes"] = notes;
  }
  pkg.files = {{"recruit_controller.h", h}, {"recruit_controller.c", c}};
  for (ExportedFile& u : UnitPackage()) pkg.files.push_back(std::move(u));
  pkg.files.push_back({"export.json", manifest.dump(2) + "\n"});
  return pkg;
}

}  // namespace recruit::exporter
