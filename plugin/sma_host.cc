#include "plugin/sma_host.h"

#include <algorithm>

#include "common/rng.h"
#include "plugin/sma_plugin.h"

namespace recruit::sma {

Result<std::unique_ptr<SmaHost>> SmaHost::Create(const mjModel* m) {
  if (m == nullptr) return Error{"SmaHost::Create: model is null"};
  RegisterSmaPlugin();
  auto host = std::make_unique<SmaHost>();
  SmaHost& h = *host;
  h.m_ = m;
  for (int i = 0; i < m->nplugin; ++i) {
    if (!IsSmaInstance(m, i)) continue;
    auto inst = SmaInstance::Create(m, i);
    if (!inst.ok()) return Error{inst.error(), inst.code()};
    h.instances_.push_back(std::shared_ptr<const SmaInstance>(std::move(inst).value()));
  }
  // Bundles in actuator order, whatever the order of the instances.
  for (int a = 0; a < m->nactuator; ++a) {
    for (int j = 0; j < static_cast<int>(h.instances_.size()); ++j) {
      const auto& acts = h.instances_[j]->actuators();
      for (int k = 0; k < static_cast<int>(acts.size()); ++k) {
        if (acts[k].actuator == a) h.refs_.push_back({j, k});
      }
    }
  }
  if (h.refs_.empty()) {
    return Error{
        "the model has no SMA bundle: declare <extension><plugin plugin=\"recruit.sma\"/>"
        "</extension> and an <actuator><plugin plugin=\"recruit.sma\" tendon=\"...\"/>"};
  }
  return host;
}

int SmaHost::BundleIndex(std::string_view actuator_name) const {
  for (int b = 0; b < num_bundles(); ++b) {
    if (bundle_name(b) == actuator_name) return b;
  }
  return -1;
}

double SmaHost::Force(const mjData* d, int b) const {
  return bundle(b).Tension(State(d, b), Stretch(d, b));
}

void SmaHost::Reset(mjData* d, std::uint64_t seed) const {
  mj_forward(m_, d);  // tendon lengths for the rest states
  for (int b = 0; b < num_bundles(); ++b) {
    Inst(b).NextBroadcast(d, m_, refs_[b].k) = d->time;
    bundle(b).Reset(State(d, b), Rng::DeriveSeed(seed, b), Stretch(d, b));
  }
  mj_forward(m_, d);  // forces and sensors from the reset units
}

Status SmaHost::ResetKeyframe(mjData* d, int key, std::uint64_t seed) const {
  if (key < 0 || key >= m_->nkey) {
    return Error{"ResetKeyframe: keyframe " + std::to_string(key) + " does not exist (model has " +
                 std::to_string(m_->nkey) + ")"};
  }
  mj_resetDataKeyframe(m_, d, key);
  Reset(d, seed);
  return Status::Ok();
}

Status SmaHost::Broadcast(mjData* d, int b, double p_on, double p_off) const {
  if (b < 0 || b >= num_bundles()) {
    return Error{"Broadcast: bundle " + std::to_string(b) + " does not exist (model has " +
                 std::to_string(num_bundles()) + ")"};
  }
  return bundle(b).Broadcast(State(d, b), p_on, p_off, Stretch(d, b));
}

Status SmaHost::Census(mjData* d, int b) const {
  if (b < 0 || b >= num_bundles()) {
    return Error{"Census: bundle " + std::to_string(b) + " does not exist (model has " +
                 std::to_string(num_bundles()) + ")"};
  }
  return bundle(b).StartCensus(State(d, b), Stretch(d, b));
}

}  // namespace recruit::sma
