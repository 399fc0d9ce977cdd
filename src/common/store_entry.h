// Entries of the stores kept between processes (control/loop_design_store.h,
// sim/response_store.h): a file whose bytes are an identity (a header with the code version, then
// every input in full) followed by a body. An entry is named by the FNV-1a 64 hash of its
// identity (common/content_hash.h) and read back only when its identity matches byte for byte (no
// hash is trusted); it is written to a temporary sibling and renamed into place, so concurrent
// runs see a whole entry or none. ByteWriter and ByteReader lay out identities and bodies.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace recruit {

class ByteWriter {
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

// Reads what ByteWriter wrote; any read past the end leaves ok() false.
class ByteReader {
 public:
  explicit ByteReader(const std::string& in) : in_(in) {}
  bool ok() const { return ok_; }
  bool AtEnd() const { return at_ == in_.size(); }
  std::uint64_t Word();
  double Real();
  std::vector<double> Reals();
  std::string Text();

 private:
  void Bytes(void* p, std::size_t n);
  const std::string& in_;
  std::size_t at_ = 0;
  bool ok_ = true;
};

// The body of the entry `folder`/<hash of identity>`extension` when its identity matches.
std::optional<std::string> LoadEntry(const std::string& folder, const std::string& identity,
                                     const std::string& extension);

// Writes identity + body there (best effort: a folder that cannot be written only costs the
// next process the work the entry saves).
void SaveEntry(const std::string& folder, const std::string& identity, const std::string& extension,
               const std::string& body);

}  // namespace recruit
