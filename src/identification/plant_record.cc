#include "identification/plant_record.h"

#include <mujoco/mujoco.h>

#include <cstdio>
#include <fstream>
#include <iterator>

#include "common/content_hash.h"

namespace recruit::identification {

std::string LimbHash(const std::string& model_path) {
  std::ifstream in(model_path, std::ios::binary);
  if (!in) return "";
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return ContentHash().Add(bytes).Hex();
}

nlohmann::json PlantRecord(const sma::SmaHost& host, int b, const std::string& model_path) {
  const nlohmann::json unit = control::UnitRecord(host.bundle(b).config().unit);
  const mjModel* m = host.model();
  const int tendon = host.tendon_id(b);
  const char* tendon_name = tendon >= 0 ? mj_id2name(m, mjOBJ_TENDON, tendon) : nullptr;
  return {{"model", model_path},
          {"actuator", host.bundle_name(b)},
          {"tendon", tendon_name ? tendon_name : ""},
          {"num_units", host.num_units(b)},
          {"settled_unit_force_N", host.SettledUnitForce(b)},
          {"unit", unit},
          {"hash", control::PlantHash(unit)},
          {"limb", LimbHash(model_path)}};
}

Result<LoadedBundle> LoadBundle(const std::string& model_path, const std::string& actuator) {
  LoadedBundle out;
  char err[1000] = "";
  out.model.reset(mj_loadXML(model_path.c_str(), nullptr, err, sizeof err));
  if (!out.model) return Error{model_path + ": " + err};
  auto host = sma::SmaHost::Create(out.model.get());
  if (!host) return Error{model_path + ": " + host.error(), host.code()};
  out.host = std::move(host).value();
  const sma::SmaHost& h = *out.host;
  if (h.num_bundles() == 0) return Error{model_path + ": no SMA bundle (recruit.sma)"};
  out.bundle = actuator.empty() ? 0 : h.BundleIndex(actuator);
  if (out.bundle < 0) {
    std::string have;
    for (int i = 0; i < h.num_bundles(); ++i) have += (i ? ", " : "") + h.bundle_name(i);
    return Error{model_path + ": no SMA bundle on actuator '" + actuator + "'; bundles: " + have};
  }
  return out;
}

Result<nlohmann::json> PlantRecordOf(const std::string& model_path, const std::string& actuator) {
  auto loaded = LoadBundle(model_path, actuator);
  if (!loaded) return Error{loaded.error(), loaded.code()};
  return PlantRecord(*loaded->host, loaded->bundle, model_path);
}

}  // namespace recruit::identification
