#include "control/loop_design_store.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "common/atomic_file.h"
#include "common/cache_folder.h"
#include "common/content_hash.h"

namespace recruit::control::design_store {
namespace {

namespace fs = std::filesystem;

// The entry's first line; raise its number when the layout below changes.
std::string Header() { return std::string("recruit loop design 1\n") + CodeVersion() + "\n"; }

class Writer {
 public:
  void Word(std::uint64_t w) { Bytes(&w, sizeof w); }
  void Real(double x) { Bytes(&x, sizeof x); }
  void Reals(const std::vector<double>& v) {
    Word(v.size());
    Bytes(v.data(), v.size() * sizeof(double));
  }
  void Text(const std::string& s) {
    Word(s.size());
    Bytes(s.data(), s.size());
  }
  void Bytes(const void* p, std::size_t n) {
    if (n > 0) out_.append(static_cast<const char*>(p), n);  // an empty vector's data() may be null
  }
  const std::string& bytes() const { return out_; }

 private:
  std::string out_;
};

// Reads what Writer wrote; any read past the end leaves ok() false.
class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}
  bool ok() const { return ok_; }
  bool AtEnd() const { return at_ == in_.size(); }
  std::uint64_t Word() {
    std::uint64_t w = 0;
    Bytes(&w, sizeof w);
    return w;
  }
  double Real() {
    double x = 0;
    Bytes(&x, sizeof x);
    return x;
  }
  std::vector<double> Reals() {
    const std::uint64_t n = Word();
    if (!ok_ || n > (in_.size() - at_) / sizeof(double)) return Fail<std::vector<double>>();
    std::vector<double> v(n);
    Bytes(v.data(), n * sizeof(double));
    return v;
  }
  std::string Text() {
    const std::uint64_t n = Word();
    if (!ok_ || n > in_.size() - at_) return Fail<std::string>();
    std::string s(in_, at_, n);
    at_ += n;
    return s;
  }

 private:
  template <typename T>
  T Fail() {
    ok_ = false;
    return T{};
  }
  void Bytes(void* p, std::size_t n) {
    if (!ok_ || n > in_.size() - at_) {
      ok_ = false;
      return;
    }
    if (n == 0) return;  // an empty vector's data() may be null: no memcpy from or to it
    std::memcpy(p, in_.data() + at_, n);
    at_ += n;
  }
  const std::string& in_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

void PutStep(Writer& w, const PredictedStep& p) {
  w.Real(p.overshoot);
  w.Real(p.settling_time);
  w.Word(p.settled);
  w.Real(p.final_error);
  w.Reals(p.time);
  w.Reals(p.angle);
}

PredictedStep GetStep(Reader& r) {
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
  Writer w;
  w.Text(Header());
  w.Word(key.size());
  w.Bytes(key.data(), key.size() * sizeof(std::uint64_t));
  return w.bytes();
}

std::string EntryPath(const std::string& folder, const std::string& identity) {
  return folder + "/" + ContentHash().Add(identity).Hex() + ".design";
}

}  // namespace

std::string Folder() {
  const std::string f = CacheFolder("RECRUIT_DESIGN_CACHE", "designs");
  return f == "off" ? "" : f;
}

std::optional<LoopDesign> Load(const std::vector<std::uint64_t>& key) {
  const std::string folder = Folder();
  if (folder.empty()) return std::nullopt;
  const std::string identity = Identity(key);
  std::ifstream in(EntryPath(folder, identity), std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.compare(0, identity.size(), identity) != 0) return std::nullopt;
  const std::string body = bytes.substr(identity.size());
  Reader r(body);
  LoopDesign d;
  d.gains.kp = r.Real();
  d.gains.ki = r.Real();
  d.gains.kd = r.Real();
  d.nominal = GetStep(r);
  d.robust = GetStep(r);
  d.offset = GetStep(r);
  d.meets = r.Word() != 0;
  d.note = r.Text();
  if (!r.ok() || !r.AtEnd()) return std::nullopt;
  return d;
}

void Save(const std::vector<std::uint64_t>& key, const LoopDesign& design) {
  const std::string folder = Folder();
  if (folder.empty()) return;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) return;
  Writer w;
  w.Real(design.gains.kp);
  w.Real(design.gains.ki);
  w.Real(design.gains.kd);
  PutStep(w, design.nominal);
  PutStep(w, design.robust);
  PutStep(w, design.offset);
  w.Word(design.meets);
  w.Text(design.note);
  const std::string identity = Identity(key);
  AtomicFile f(EntryPath(folder, identity), std::ios::out | std::ios::binary);
  if (!f.ok()) return;
  f.stream() << identity << w.bytes();
  (void)f.Commit();
}

}  // namespace recruit::control::design_store
