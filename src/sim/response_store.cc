#include "sim/response_store.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>

#include "common/atomic_file.h"
#include "common/content_hash.h"
#include "control/loop_design_store.h"

namespace recruit::sim {
namespace {

void Put(std::string& out, const void* p, std::size_t n) {
  if (n > 0) out.append(static_cast<const char*>(p), n);  // an empty vector's data() may be null
}
void PutWord(std::string& out, std::uint64_t w) { Put(out, &w, sizeof w); }
void PutReals(std::string& out, const std::vector<double>& v) {
  PutWord(out, v.size());
  Put(out, v.data(), v.size() * sizeof(double));
}

// Reads what Put wrote; false past the end.
bool Get(const std::string& in, std::size_t& at, void* p, std::size_t n) {
  if (n > in.size() - at) return false;
  if (n > 0) std::memcpy(p, in.data() + at, n);
  at += n;
  return true;
}
bool GetReals(const std::string& in, std::size_t& at, std::vector<double>& v) {
  std::uint64_t n = 0;
  if (!Get(in, at, &n, sizeof n) || n > (in.size() - at) / sizeof(double)) return false;
  v.resize(n);
  return Get(in, at, v.data(), n * sizeof(double));
}

// The bytes that identify an entry: layout version, code version, then every input.
std::string Identity(const estimation::BroadcastTransitionModel& chain,
                     const std::vector<double>& force, double lambda) {
  std::string id = std::string("recruit bundle response 1\n") + CodeVersion() + "\n";
  PutWord(id, chain.state_names.size());
  for (const std::string& name : chain.state_names) {
    PutWord(id, name.size());
    id += name;
  }
  PutWord(id, chain.is_on.size());
  for (bool on : chain.is_on) PutWord(id, on);
  PutWord(id, chain.interior.rows());
  PutWord(id, chain.interior.cols());
  Put(id, chain.interior.data(), chain.interior.size() * sizeof(double));
  for (const std::vector<int>* t : {&chain.on_target, &chain.off_target}) {
    PutWord(id, t->size());
    Put(id, t->data(), t->size() * sizeof(int));
  }
  Put(id, &chain.dt, sizeof chain.dt);
  PutReals(id, force);
  Put(id, &lambda, sizeof lambda);
  return id;
}

}  // namespace

Result<control::ActuatorResponse> StoredBundleResponse(
    const estimation::BroadcastTransitionModel& chain, const std::vector<double>& force,
    double lambda) {
  const std::string folder = control::design_store::Folder();
  if (folder.empty()) return control::PredictBundleResponse(chain, force, lambda);
  const std::string identity = Identity(chain, force, lambda);
  const std::string path = folder + "/" + ContentHash().Add(identity).Hex() + ".response";
  if (std::ifstream in(path, std::ios::binary); in) {
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.compare(0, identity.size(), identity) == 0) {
      std::size_t at = identity.size();
      control::ActuatorResponse r;
      if (Get(bytes, at, &r.dT, sizeof r.dT) && GetReals(bytes, at, r.s) &&
          GetReals(bytes, at, r.release) && at == bytes.size()) {
        return r;
      }
    }
  }
  auto r = control::PredictBundleResponse(chain, force, lambda);
  if (!r) return r;
  // Best effort: a folder that cannot be written only costs the next process the prediction.
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return r;
  std::string body;
  Put(body, &r->dT, sizeof r->dT);
  PutReals(body, r->s);
  PutReals(body, r->release);
  AtomicFile f(path, std::ios::out | std::ios::binary);
  if (f.ok()) {
    f.stream() << identity << body;
    (void)f.Commit();
  }
  return r;
}

}  // namespace recruit::sim
