#include "plugin/joint_damping.h"

#include <algorithm>

#include "plugin/tendon_range.h"

namespace recruit::sma {
namespace {

// Row r's entry in column `dof` of the actuators' sparse moment matrix in d (0 when absent).
double Moment(const mjData* d, int r, int dof) {
  for (int k = d->moment_rowadr[r]; k < d->moment_rowadr[r] + d->moment_rownnz[r]; ++k) {
    if (d->moment_colind[k] == dof) return d->actuator_moment[k];
  }
  return 0;
}

}  // namespace

double JointDamping(const mjModel* m, const mjData* d, int dof, const std::vector<int>& skip) {
  double b = m->dof_damping[dof];
  for (int t = 0; t < m->ntendon; ++t) {
    if (m->tendon_damping[t] == 0) continue;
    const double arm = TendonArm(m, d, t, dof);
    b += m->tendon_damping[t] * arm * arm;
  }
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_damping[a] == 0 || std::find(skip.begin(), skip.end(), a) != skip.end()) {
      continue;
    }
    for (int r = m->actuator_outadr[a]; r < m->actuator_outadr[a] + m->actuator_outnum[a]; ++r) {
      const double arm = Moment(d, r, dof);
      b += m->actuator_damping[a] * arm * arm;
    }
  }
  return b;
}

}  // namespace recruit::sma
