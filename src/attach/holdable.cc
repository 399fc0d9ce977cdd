#include "attach/holdable.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "attach/attach.h"
#include "control/torque_allocation.h"
#include "plugin/tendon_range.h"
#include "plugin/unit_model.h"

namespace recruit::attach {
namespace {

struct Bundle {
  const BundleReport* report = nullptr;
  std::unique_ptr<sma::UnitModel> unit;  // its design's
};

// Whether the bundles hold joint `j` (index into `dofs`) at the pose in d (positions set).
bool Holds(mjModel* m, mjData* d, const std::vector<int>& dofs, std::size_t j,
           const std::vector<Bundle>& bundles, double co_contraction) {
  const int saved = m->opt.disableflags;
  m->opt.disableflags |= mjDSBL_CONSTRAINT;  // a limit or lock would take part of the load
  mju_zero(d->qvel, m->nv);
  mju_zero(d->qacc, m->nv);
  mj_inverse(m, d);
  m->opt.disableflags = saved;
  const int nj = static_cast<int>(dofs.size()), nb = static_cast<int>(bundles.size());
  control::AllocationProblem p;
  p.arms = Eigen::MatrixXd::Zero(nj, nb);
  p.torque.resize(nj);
  p.cap.resize(nb);
  p.floor.resize(nb);
  for (int k = 0; k < nj; ++k) p.torque[k] = d->qfrc_inverse[dofs[k]];
  for (int i = 0; i < nb; ++i) {
    const BundleReport& b = *bundles[i].report;
    const BundleDesign& design = b.design;
    for (int k = 0; k < nj; ++k) p.arms(k, i) = -sma::TendonArm(m, d, b.tendon_id, dofs[k]);
    const double s = design.Stretch(d->ten_length[b.tendon_id], b.ref_length);
    p.cap[i] = std::max(design.gear * design.units * bundles[i].unit->Tension(0.0, s), 1e-9);
    p.floor[i] = co_contraction * p.cap[i];
  }
  const Eigen::VectorXd tensions = control::AllocateTensions(p);
  const double span = p.arms.row(j).cwiseAbs().dot(p.cap);
  return std::abs((p.arms * tensions)[j] - p.torque[j]) <= 1e-3 * span;
}

}  // namespace

void FindHoldableRanges(mjModel* m, const std::vector<BundleReport>& bundles, double co_contraction,
                        std::vector<HoldableRange>& ranges) {
  std::vector<Bundle> bs;
  for (const BundleReport& r : bundles) {
    auto unit = sma::UnitModel::Create(r.design.unit);
    if (!unit.ok()) continue;  // sizing made it: cannot happen
    bs.push_back({&r, std::make_unique<sma::UnitModel>(std::move(unit).value())});
  }
  std::vector<int> dofs, qadr;
  for (HoldableRange& h : ranges) {
    const int j = mj_name2id(m, mjOBJ_JOINT, h.joint.c_str());
    dofs.push_back(j >= 0 ? m->jnt_dofadr[j] : -1);
    qadr.push_back(j >= 0 ? m->jnt_qposadr[j] : -1);
    h.hold_lo = h.lo;
    h.hold_hi = h.hi;
  }
  if (std::find(dofs.begin(), dofs.end(), -1) != dofs.end() || bs.empty()) return;
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  for (std::size_t j = 0; j < ranges.size(); ++j) {
    std::vector<bool> held(kHoldSamples);
    std::vector<double> q(kHoldSamples);
    for (int s = 0; s < kHoldSamples; ++s) {
      mju_copy(d->qpos, m->qpos0, m->nq);
      for (std::size_t k = 0; k < ranges.size(); ++k) {
        d->qpos[qadr[k]] = 0.5 * (ranges[k].lo + ranges[k].hi);
      }
      q[s] = ranges[j].lo + (ranges[j].hi - ranges[j].lo) * s / (kHoldSamples - 1);
      d->qpos[qadr[j]] = q[s];
      held[s] = Holds(m, d.get(), dofs, j, bs, co_contraction);
    }
    // The run of held samples around the middle, else the longest (the first of equals).
    int best_lo = -1, best_hi = -1;
    for (int s = 0; s < kHoldSamples; ++s) {
      if (!held[s] || (s > 0 && held[s - 1])) continue;  // s starts a run
      int e = s;
      while (e + 1 < kHoldSamples && held[e + 1]) ++e;
      if (s <= kHoldSamples / 2 && kHoldSamples / 2 <= e) {
        best_lo = s, best_hi = e;
        break;
      }
      if (best_lo < 0 || e - s > best_hi - best_lo) best_lo = s, best_hi = e;
    }
    if (best_lo < 0) continue;  // none held: the whole range (the run names its poses)
    ranges[j].hold_lo = q[best_lo];
    ranges[j].hold_hi = q[best_hi];
  }
}

}  // namespace recruit::attach
