#include "identification/plant_record.h"

#include <mujoco/mujoco.h>

#include <cstdio>
#include <fstream>

namespace recruit::control {

nlohmann::json PlantRecord(const sma::SmaHost& host, int b, const std::string& model_path) {
  const nlohmann::json unit = UnitRecord(host.bundle(b).config().unit);
  const mjModel* m = host.model();
  const int tendon = host.tendon_id(b);
  const char* tendon_name = tendon >= 0 ? mj_id2name(m, mjOBJ_TENDON, tendon) : nullptr;
  return {{"model", model_path},
          {"actuator", host.bundle_name(b)},
          {"tendon", tendon_name ? tendon_name : ""},
          {"num_units", host.num_units(b)},
          {"settled_unit_force_N", host.SettledUnitForce(b)},
          {"unit", unit},
          {"hash", PlantHash(unit)}};
}

}  // namespace recruit::control
