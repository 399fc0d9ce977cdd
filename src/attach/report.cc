#include "attach/report.h"

#include <cstdio>

namespace recruit::attach {
namespace {

std::string F(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

double Deg(const JointUse& j, double v) { return j.hinge ? v * 180 / M_PI : v; }

std::string Usable(const BundleReport& b) {
  std::string s;
  for (const JointUse& j : b.joints) {
    s += (s.empty() ? "" : ", ") + j.joint + " " + F("%.4g", Deg(j, j.usable_lo)) + ".." +
         F("%.4g", Deg(j, j.usable_hi)) + (j.hinge ? " deg" : " m");
  }
  return s.empty() ? "(no limited joint moves it)" : s;
}

}  // namespace

std::vector<std::string> ChangeLines(const AttachReport& r, const mjSpec* spec) {
  std::vector<std::string> lines;
  for (const BundleReport& b : r.bundles) {
    lines.push_back("actuator '" + b.name + "' (" + b.replaced + " on tendon '" + b.tendon +
                    "') -> recruit.sma bundle, instance '" + b.instance + "', class '" +
                    kBundleClass + "', gear " + F("%g", b.design.gear) + ", damping " +
                    F("%.4g", b.design.damper) + ", ctrlrange -1 1");
    lines.push_back("sensor '" + b.sensor + "' added (count, tension, mean T, mean xi)");
  }
  lines.push_back(std::string("default class '") + kBundleClass +
                  "' added: MuJoCo's built-in actuator defaults (dyntype none, gaintype fixed, "
                  "biastype none), so no inherited muscle default reaches the bundles");
  for (const JointLock& l : r.locks) {
    lines.push_back("joint '" + l.joint + "' locked at " + F("%g", l.value) +
                    " (its reference value; a joint equality, --lock)");
  }
  for (const LengthRangeFix& f : r.lengthranges) {
    lines.push_back("lengthrange of '" + f.actuator + "' set from the joint ranges: " +
                    F("%.4f", f.lo) + " " + F("%.4f", f.hi) + " m");
  }
  for (const LengthRangeFix& f : r.lengthranges_unlocked) {
    lines.push_back("lengthrange of '" + f.actuator +
                    "' written as MuJoCo computes it without the "
                    "locks: " +
                    F("%.4f", f.lo) + " " + F("%.4f", f.hi) + " m");
  }
  const char* meshdir = mjs_getString(spec->compiler.meshdir);
  if (meshdir != nullptr && meshdir[0] != '\0') {
    lines.push_back(std::string("compiler meshdir/texturedir now relative to the output: ") +
                    meshdir + " / " + mjs_getString(spec->compiler.texturedir));
  }
  return lines;
}

std::string DesignTable(const AttachReport& r) {
  std::string t;
  for (const BundleReport& b : r.bundles) {
    const BundleDesign& d = b.design;
    const sma::UnitParams& u = d.unit;
    t += "bundle '" + b.name + "' (was " + b.replaced + " on tendon '" + b.tendon + "')\n";
    t += "  peak force " + F("%.4g", b.peak_force) + " N (" + b.force_source + "); tendon " +
         F("%.1f", 1000 * b.length_min) + ".." + F("%.1f", 1000 * b.length_max) +
         " mm (excursion " + F("%.1f", 1000 * (b.length_max - b.length_min)) + " mm) over " +
         Usable(b) + "\n";
    for (const std::string& j : b.jumps) t += "  tendon path jumps: " + j + "\n";
    t += "  units " + std::to_string(d.units) + " x parallel " + std::to_string(u.parallel) +
         " x series " + std::to_string(u.series) + " wires of " +
         F("%.3g", 1000 * u.wire_diameter) + " mm x " + F("%.3g", 1000 * u.wire_length) +
         " mm, current " + F("%.3g", 1000 * u.current) + " mA, spring " +
         F("%.4g", u.series_spring) + " N/m, prestretch " + F("%.4g", 1000 * u.prestretch) +
         " mm, gear " + F("%g", d.gear) + "\n";
    if (!d.transmission.empty()) t += "  transmission: " + d.transmission + "\n";
    if (d.damper > 0) {
      t += "  damper: " + F("%.4g", d.damper) +
           " N s/m beside the units, behind the same lever (actuator damping; " +
           F("%.4g", d.damper * d.gear * d.gear) + " N s/m at the tendon)\n";
    }
    if (b.holding.force() > 0) {
      t += "  resolution: one unit " + F("%.3g", d.force_mid / d.units) + " N, " +
           F("%.2g", 100 * d.force_mid / d.units / b.holding.force()) + " % of the " +
           F("%.4g", b.holding.force()) + " N that holds the limb's weight (" +
           F("%.3g", b.holding.torque) + " N m at " + F("%.3g", 1000 * b.holding.arm) + " mm)\n";
    } else {
      t += "  resolution: one unit " + F("%.3g", d.force_mid / d.units) + " N, " +
           F("%.2g", 100 * d.force_mid / d.units / b.peak_force) +
           " % of the peak force (no weight on the bundle: sized on the co-contraction that "
           "holds it)\n";
    }
    t += "  force all on: " + F("%.4g", d.force_short) + " / " + F("%.4g", d.force_mid) + " / " +
         F("%.4g", d.force_long) + " N (shortest / mid / longest tendon); stroke " +
         F("%.1f", 1000 * d.stroke) + " mm\n";
    t += "  limits: stress " + F("%.0f", d.peak_stress / 1e6) + " MPa (<= 172), steady " +
         F("%.1f", d.steady_temperature) + " C (<= 120), current " + F("%.3g", 1000 * u.current) +
         " mA (1 s datasheet " + F("%.3g", 1000 * d.max_current) + " mA)\n";
    t += "  cost: " + F("%.4g", d.wire_total) + " m of wire, " + F("%.4g", 1000 * d.mass) + " g, " +
         F("%.4g", d.power) + " W all on, thermal tau " + F("%.3g", d.time_constant) +
         " s, cooling " + F("%.3g", d.cooling_time) + " s (datasheet)\n";
  }
  for (const DampedJoint& j : r.damped_joints) {
    t += "joint '" + j.joint + "': inertia " + F("%.4g", j.inertia) +
         " kg m^2, the bundles' stiffness at rest " + F("%.4g", j.stiffness) +
         " N m/rad; damping " + F("%.4g", j.damping) + " -> " + F("%.4g", j.damping_after) +
         " N m s/rad (ratio " + F("%.3g", j.ratio_before) + " -> " + F("%.3g", j.ratio_after) +
         ")\n";
  }
  for (const HoldableRange& h : r.holdable) {
    if (!h.cut()) continue;
    t += "starter task: joint '" + h.joint + "' steps within " + F("%.4g", h.hold_lo * 180 / M_PI) +
         ".." + F("%.4g", h.hold_hi * 180 / M_PI) + " deg of its usable " +
         F("%.4g", h.lo * 180 / M_PI) + ".." + F("%.4g", h.hi * 180 / M_PI) +
         " deg: beyond, the bundles cannot hold the limb's static torque\n";
  }
  for (const std::string& w : r.warnings) t += "warning: " + w + "\n";
  return t;
}

nlohmann::json ReportJson(const AttachReport& r) {
  nlohmann::json j;
  j["model"] = r.model;
  j["output"] = r.output;
  j["task"] = r.task;
  j["changes"] = r.changes;
  j["warnings"] = r.warnings;
  j["lengthranges_from_joints"] = nlohmann::json::array();
  for (const LengthRangeFix& f : r.lengthranges) {
    j["lengthranges_from_joints"].push_back({{"actuator", f.actuator}, {"range", {f.lo, f.hi}}});
  }
  j["lengthranges_without_locks"] = nlohmann::json::array();
  for (const LengthRangeFix& f : r.lengthranges_unlocked) {
    j["lengthranges_without_locks"].push_back({{"actuator", f.actuator}, {"range", {f.lo, f.hi}}});
  }
  j["joints"] = nlohmann::json::array();
  for (const DampedJoint& d : r.damped_joints) {
    j["joints"].push_back({{"joint", d.joint},
                           {"inertia", d.inertia},
                           {"stiffness_at_rest", d.stiffness},
                           {"damping", {d.damping, d.damping_after}},
                           {"damping_ratio", {d.ratio_before, d.ratio_after}}});
  }
  j["holdable"] = nlohmann::json::array();
  for (const HoldableRange& h : r.holdable) {
    j["holdable"].push_back(
        {{"joint", h.joint}, {"usable", {h.lo, h.hi}}, {"held", {h.hold_lo, h.hold_hi}}});
  }
  j["bundles"] = nlohmann::json::array();
  for (const BundleReport& b : r.bundles) {
    const BundleDesign& d = b.design;
    nlohmann::json joints = nlohmann::json::array();
    for (const JointUse& u : b.joints) {
      joints.push_back({{"joint", u.joint},
                        {"type", u.hinge ? "hinge" : "slide"},
                        {"range", {u.lo, u.hi}},
                        {"usable", {u.usable_lo, u.usable_hi}}});
    }
    nlohmann::json config;
    for (const auto& [k, v] : d.ConfigPairs()) config[k] = v;
    j["bundles"].push_back({{"name", b.name},
                            {"replaced", b.replaced},
                            {"tendon", b.tendon},
                            {"instance", b.instance},
                            {"sensor", b.sensor},
                            {"peak_force", b.peak_force},
                            {"force_source", b.force_source},
                            {"joints", joints},
                            {"jumps", b.jumps},
                            {"tendon_length", {b.length_min, b.length_max}},
                            {"ref_length", b.ref_length},
                            {"holding_force", b.holding.force()},
                            {"gear", d.gear},
                            {"transmission", d.transmission},
                            {"damper", d.damper},
                            {"config", config},
                            {"force_all_on", {d.force_short, d.force_mid, d.force_long}},
                            {"stroke", d.stroke},
                            {"peak_stress", d.peak_stress},
                            {"steady_temperature", d.steady_temperature},
                            {"max_current_1s", d.max_current},
                            {"wire_total", d.wire_total},
                            {"mass", d.mass},
                            {"power", d.power},
                            {"time_constant", d.time_constant},
                            {"cooling_time", d.cooling_time},
                            {"notes", d.notes}});
  }
  return j;
}

}  // namespace recruit::attach
