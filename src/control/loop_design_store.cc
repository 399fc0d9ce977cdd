#include "control/loop_design_store.h"

#include "common/cache_folder.h"
#include "common/content_hash.h"
#include "common/store_entry.h"

namespace recruit::control::design_store {
namespace {

// The entry's first line; raise its number when the layout below changes.
std::string Header() { return std::string("recruit loop design 1\n") + CodeVersion() + "\n"; }

void PutStep(ByteWriter& w, const PredictedStep& p) {
  w.Real(p.overshoot);
  w.Real(p.settling_time);
  w.Word(p.settled);
  w.Real(p.final_error);
  w.Reals(p.time);
  w.Reals(p.angle);
}

PredictedStep GetStep(ByteReader& r) {
  PredictedStep p;
  p.overshoot = r.Real();
  p.settling_time = r.Real();
  p.settled = r.Word() != 0;
  p.final_error = r.Real();
  p.time = r.Reals();
  p.angle = r.Reals();
  return p;
}

// The bytes that identify an entry: the header and the key.
std::string Identity(const std::vector<std::uint64_t>& key) {
  ByteWriter w;
  w.Text(Header());
  w.Word(key.size());
  w.Bytes(key.data(), key.size() * sizeof(std::uint64_t));
  return w.bytes();
}

}  // namespace

std::string Folder() {
  const std::string f = CacheFolder("RECRUIT_DESIGN_CACHE", "designs");
  return f == "off" ? "" : f;
}

std::optional<LoopDesign> Load(const std::vector<std::uint64_t>& key) {
  const std::string folder = Folder();
  if (folder.empty()) return std::nullopt;
  const std::optional<std::string> body = LoadEntry(folder, Identity(key), ".design");
  if (!body) return std::nullopt;
  ByteReader r(*body);
  LoopDesign d;
  d.gains.kp = r.Real();
  d.gains.ki = r.Real();
  d.gains.kd = r.Real();
  d.nominal = GetStep(r);
  d.robust = GetStep(r);
  d.offset = GetStep(r);
  d.delayed = GetStep(r);
  d.meets = r.Word() != 0;
  d.note = r.Text();
  if (!r.ok() || !r.AtEnd()) return std::nullopt;
  return d;
}

void Save(const std::vector<std::uint64_t>& key, const LoopDesign& design) {
  const std::string folder = Folder();
  if (folder.empty()) return;
  ByteWriter w;
  w.Real(design.gains.kp);
  w.Real(design.gains.ki);
  w.Real(design.gains.kd);
  PutStep(w, design.nominal);
  PutStep(w, design.robust);
  PutStep(w, design.offset);
  PutStep(w, design.delayed);
  w.Word(design.meets);
  w.Text(design.note);
  SaveEntry(folder, Identity(key), ".design", w.bytes());
}

}  // namespace recruit::control::design_store
