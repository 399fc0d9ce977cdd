#include "control/bench_recorder.h"

#include <mujoco/mujoco.h>

#include <cmath>
#include <memory>
#include <vector>

#include "common/mujoco_ptr.h"
#include "control/plant_record.h"
#include "plugin/sma_host.h"

namespace recruit::control {
namespace {}  // namespace

Result<BenchRecording> RecordBench(const std::string& model_path, const std::string& actuator,
                                   const Excitation& excitation, double dT, std::uint64_t seed) {
  char err[1000] = "";
  ModelPtr m(mj_loadXML(model_path.c_str(), nullptr, err, sizeof err));
  if (!m) return Error{model_path + ": " + err};
  auto plugin = sma::SmaHost::Create(m.get());
  if (!plugin) return Error{model_path + ": " + plugin.error()};
  const sma::SmaHost& p = **plugin;
  if (p.num_bundles() == 0) return Error{model_path + ": no SMA bundle (recruit.sma.* text)"};
  const int b = actuator.empty() ? 0 : p.BundleIndex(actuator);
  if (b < 0) return Error{model_path + ": no SMA bundle on actuator \"" + actuator + "\""};
  const double h = m->opt.timestep;
  const double ratio = dT / h;
  const int steps = static_cast<int>(std::lround(ratio));
  if (!(dT > 0) || steps < 1 || std::abs(ratio - steps) > 1e-6 * ratio) {
    return Error{"identify: dT = " + std::to_string(dT) + " s must be a positive whole number of " +
                 model_path + "'s timesteps (" + std::to_string(h) + " s)"};
  }
  DataPtr d(mj_makeData(m.get()));
  p.Reset(d.get(), seed);
  BenchRecording rec;
  rec.unit_force = p.SettledUnitForce(b);
  rec.timestep = h;
  rec.plant = PlantRecord(p, b, model_path);
  SwitchingLog& log = rec.log;
  log.num_units = p.num_units(b);
  log.dT = dT;
  // Forces and sensors at t = 0 (nothing is on yet).
  mj_forward(m.get(), d.get());
  std::vector<char> was_on(p.num_units(b));
  for (int k = 0; k < excitation.size(); ++k) {
    log.time.push_back(k * dT);
    log.force.push_back(p.Force(d.get(), b));
    log.true_on.push_back(p.OnCount(d.get(), b));
    log.p_on.push_back(excitation.p_on[k]);
    log.p_off.push_back(excitation.p_off[k]);
    // Which units switched, from the per-unit debug state (the fit's realized inputs).
    const int n = p.num_units(b);
    for (int i = 0; i < n; ++i) was_on[i] = p.UnitOn(d.get(), b, i);
    if (Status s = p.Broadcast(d.get(), b, excitation.p_on[k], excitation.p_off[k]); !s) {
      return Error{"identify: broadcast " + std::to_string(k) + ": " + s.error()};
    }
    int on_before = 0, turned_on = 0, turned_off = 0;
    for (int i = 0; i < n; ++i) {
      const bool now = p.UnitOn(d.get(), b, i);
      on_before += was_on[i];
      turned_on += !was_on[i] && now;
      turned_off += was_on[i] && !now;
    }
    log.realized_on.push_back(on_before < n ? double(turned_on) / (n - on_before) : 0.0);
    log.realized_off.push_back(on_before > 0 ? double(turned_off) / on_before : 0.0);
    for (int i = 0; i < steps; ++i) mj_step(m.get(), d.get());
  }
  return rec;
}

}  // namespace recruit::control
