#include "plugin/joint_damping.h"

#include <algorithm>

namespace recruit::sma {
namespace {

// The squared entry of column `dof` in row r of a MuJoCo sparse matrix (0 when absent).
double SquaredEntry(const int* rownnz, const int* rowadr, const int* colind, const mjtNum* values,
                    int r, int dof) {
  for (int k = rowadr[r]; k < rowadr[r] + rownnz[r]; ++k) {
    if (colind[k] == dof) return values[k] * values[k];
  }
  return 0;
}

}  // namespace

double JointDamping(const mjModel* m, const mjData* d, int dof, const std::vector<int>& skip) {
  double b = m->dof_damping[dof];
  for (int t = 0; t < m->ntendon; ++t) {
    if (m->tendon_damping[t] == 0) continue;
    b += m->tendon_damping[t] *
         SquaredEntry(m->ten_J_rownnz, m->ten_J_rowadr, m->ten_J_colind, d->ten_J, t, dof);
  }
  for (int a = 0; a < m->nu; ++a) {
    if (m->actuator_damping[a] == 0 || std::find(skip.begin(), skip.end(), a) != skip.end()) {
      continue;
    }
    for (int r = m->actuator_outadr[a]; r < m->actuator_outadr[a] + m->actuator_outnum[a]; ++r) {
      b += m->actuator_damping[a] * SquaredEntry(d->moment_rownnz, d->moment_rowadr,
                                                 d->moment_colind, d->actuator_moment, r, dof);
    }
  }
  return b;
}

}  // namespace recruit::sma
