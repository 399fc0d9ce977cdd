#include "attach/holding_load.h"

#include <algorithm>
#include <cmath>

#include "plugin/tendon_range.h"

namespace recruit::attach {
HoldingLoad SampleHoldingLoad(const mjModel* m, mjData* d, int tendon,
                              const std::vector<int>& joints, const std::vector<double>& lo,
                              const std::vector<double>& hi) {
  constexpr int kPoints = 33;
  HoldingLoad best;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const int j = joints[i], dof = m->jnt_dofadr[j];
    HoldingLoad load;
    for (int k = 0; k < kPoints; ++k) {
      mju_copy(d->qpos, m->qpos0, m->nq);
      mju_zero(d->qvel, m->nv);
      d->qpos[m->jnt_qposadr[j]] = lo[i] + (hi[i] - lo[i]) * k / (kPoints - 1);
      mj_fwdPosition(m, d);
      mj_fwdVelocity(m, d);  // qfrc_bias (gravity at rest) and qfrc_passive (springs)
      load.torque = std::max(load.torque, std::abs(d->qfrc_bias[dof] - d->qfrc_passive[dof]));
      load.arm = std::max(load.arm, std::abs(sma::TendonArm(m, d, tendon, dof)));
    }
    if (load.force() > best.force()) best = load;
  }
  return best;
}

}  // namespace recruit::attach
