#include "render/unit_counts.h"

#include <cmath>

namespace recruit::render {
namespace {

// The sensor block of actuator `a` that reports its counts: (sensor address + offset), or -1.
int CountsAddress(const mjModel* m, int a) {
  const int instance = m->actuator_plugin[a];
  if (instance < 0) return -1;
  // The bundle's place among its instance's actuators (the sensor's blocks follow their order).
  int k = 0, n = 0;
  for (int i = 0; i < m->nu; ++i) {
    if (m->actuator_plugin[i] != instance) continue;
    if (i < a) ++k;
    ++n;
  }
  for (int s = 0; s < m->nsensor; ++s) {
    if (m->sensor_type[s] != mjSENS_PLUGIN || m->sensor_plugin[s] != instance) continue;
    return m->sensor_dim[s] == 7 * n ? m->sensor_adr[s] + 7 * k : -1;  // 4 each: no counts
  }
  return -1;
}

}  // namespace

std::vector<std::optional<UnitCounts>> UnitCountReader::Read(const mjModel* m, const mjData* d,
                                                             const TelemetrySample& sample) {
  std::vector<int> adr;
  bool any = false;
  for (const BundleTelemetry& b : sample.bundles) {
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, b.actuator.c_str());
    adr.push_back(a < 0 ? -1 : CountsAddress(m, a));
    any |= adr.back() >= 0;
  }
  std::vector<std::optional<UnitCounts>> out(adr.size());
  if (!any) return out;
  // The sensors at the present state, on a copy: a run's plant computes none, and sensordata
  // after mj_step is that of the step's start.
  if (source_ != m) {
    model_.reset(mj_copyModel(nullptr, m));
    model_->opt.disableflags &= ~mjDSBL_SENSOR;
    data_.reset(mj_makeData(model_.get()));
    state_.resize(mj_stateSize(m, mjSTATE_INTEGRATION));
    source_ = m;
  }
  mj_getState(m, d, state_.data(), mjSTATE_INTEGRATION);
  mj_setState(model_.get(), data_.get(), state_.data(), mjSTATE_INTEGRATION);
  mj_forward(model_.get(), data_.get());
  const mjtNum* values = data_->sensordata;
  for (size_t b = 0; b < adr.size(); ++b) {
    if (adr[b] < 0) continue;
    const mjtNum* v = values + adr[b];
    out[b] = UnitCounts{static_cast<int>(std::lround(v[4])), static_cast<int>(std::lround(v[5])),
                        static_cast<int>(std::lround(v[6]))};
  }
  return out;
}

std::string WorkingText(const UnitCounts& c) {
  std::string s = std::to_string(c.working) + " of " + std::to_string(c.total()) + " working";
  std::string failed;
  if (c.open > 0) failed += std::to_string(c.open) + " open";
  if (c.stuck > 0) failed += (failed.empty() ? "" : ", ") + std::to_string(c.stuck) + " stuck";
  return failed.empty() ? s : s + " (" + failed + ")";
}

}  // namespace recruit::render
