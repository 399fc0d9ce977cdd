#include "control/model_plant.h"

#include <cstdio>
#include <fstream>

namespace recruit::control {

nlohmann::json UnitRecord(const sma::UnitParams& u) {
  return {{"law", u.law == sma::ForceLaw::kWire ? "wire" : "spring"},
          {"wire_diameter", u.wire_diameter},
          {"wire_length", u.wire_length},
          {"coil_diameter", u.coil_diameter},
          {"turns", u.turns},
          {"prestretch", u.prestretch},
          {"series_spring", u.series_spring},
          {"series", u.series},
          {"parallel", u.parallel},
          {"current", u.current},
          {"ambient", u.ambient},
          {"h", u.h},
          {"emissivity", u.emissivity},
          {"density", u.density},
          {"specific_heat", u.specific_heat},
          {"latent_heat", u.latent_heat},
          {"resistivity_M", u.resistivity_M},
          {"resistivity_A", u.resistivity_A},
          {"As", u.As},
          {"Af", u.Af},
          {"Ms", u.Ms},
          {"Mf", u.Mf},
          {"C_A", u.C_A},
          {"C_M", u.C_M},
          {"E_A", u.E_A},
          {"E_M", u.E_M},
          {"G_A", u.G_A},
          {"G_M", u.G_M},
          {"eps_L", u.eps_L}};
}

std::string PlantHash(const nlohmann::json& unit) {
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64
  for (unsigned char c : unit.dump()) {     // keys sorted, doubles round-trip
    h ^= c;
    h *= 0x100000001b3ull;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

namespace {

std::string Describe(const nlohmann::json& p) {
  auto s = [&](const char* k) { return p.contains(k) ? p[k].dump() : std::string("?"); };
  return "model " + s("model") + ", actuator " + s("actuator") + ", N " + s("num_units") +
         ", unit hash " + s("hash");
}

}  // namespace

Status CheckModelPlant(const std::string& model_file, const nlohmann::json& plant) {
  std::ifstream in(model_file);
  if (!in) return Error{model_file + ": cannot open", ErrorCode::kIo};
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    return Error{model_file + ": not valid JSON: " + e.what()};
  }
  return CheckModelPlant(model_file, j, plant);
}

Status CheckModelPlant(const std::string& model_file, const nlohmann::json& j,
                       const nlohmann::json& plant) {
  if (!j.is_object() || !j.contains("identification") || !j["identification"].is_object() ||
      !j["identification"].contains("plant")) {
    return {};
  }
  const nlohmann::json& had = j["identification"]["plant"];
  if (had.value("hash", "") == plant.value("hash", "")) return {};
  std::string diff;
  if (had.contains("unit") && had["unit"].is_object()) {
    for (const auto& [key, value] : plant["unit"].items()) {
      if (!had["unit"].contains(key) || had["unit"][key] != value) {
        diff += (diff.empty() ? "" : ", ") + key + " " +
                (had["unit"].contains(key) ? had["unit"][key].dump() : "?") + " vs " + value.dump();
      }
    }
  }
  return Error{model_file + " was identified on another plant (" + Describe(had) +
               ") than this one (" + Describe(plant) + ")" +
               (diff.empty() ? "" : "; differing unit parameters (model vs plant): " + diff) +
               ". Identify a model on this plant: recruit identify --bench MODEL --actuator NAME "
               "--dt DT -o FILE"};
}

}  // namespace recruit::control
