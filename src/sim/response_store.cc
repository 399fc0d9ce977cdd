#include "sim/response_store.h"

#include <optional>
#include <string>

#include "common/content_hash.h"
#include "common/store_entry.h"
#include "control/loop_design_store.h"

namespace recruit::sim {
namespace {

// The bytes that identify an entry: layout version, code version, then every input.
std::string Identity(const estimation::BroadcastTransitionModel& chain,
                     const std::vector<double>& force, double lambda) {
  ByteWriter id;
  const std::string head = std::string("recruit bundle response 1\n") + CodeVersion() + "\n";
  id.Bytes(head.data(), head.size());
  id.Word(chain.state_names.size());
  for (const std::string& name : chain.state_names) id.Text(name);
  id.Word(chain.is_on.size());
  for (bool on : chain.is_on) id.Word(on);
  id.Word(chain.interior.rows());
  id.Word(chain.interior.cols());
  id.Bytes(chain.interior.data(), chain.interior.size() * sizeof(double));
  for (const std::vector<int>* t : {&chain.on_target, &chain.off_target}) {
    id.Word(t->size());
    id.Bytes(t->data(), t->size() * sizeof(int));
  }
  id.Real(chain.dt);
  id.Reals(force);
  id.Real(lambda);
  return id.bytes();
}

}  // namespace

Result<control::ActuatorResponse> StoredBundleResponse(
    const estimation::BroadcastTransitionModel& chain, const std::vector<double>& force,
    double lambda) {
  const std::string folder = control::design_store::Folder();
  if (folder.empty()) return control::PredictBundleResponse(chain, force, lambda);
  const std::string identity = Identity(chain, force, lambda);
  if (const std::optional<std::string> body = LoadEntry(folder, identity, ".response")) {
    ByteReader r(*body);
    control::ActuatorResponse out;
    out.dT = r.Real();
    out.s = r.Reals();
    out.release = r.Reals();
    if (r.ok() && r.AtEnd()) return out;
  }
  auto r = control::PredictBundleResponse(chain, force, lambda);
  if (!r) return r;
  ByteWriter body;
  body.Real(r->dT);
  body.Reals(r->s);
  body.Reals(r->release);
  SaveEntry(folder, identity, ".response", body.bytes());
  return r;
}

}  // namespace recruit::sim
