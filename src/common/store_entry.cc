#include "common/store_entry.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "common/atomic_file.h"
#include "common/content_hash.h"

namespace recruit {
namespace {

std::string EntryPath(const std::string& folder, const std::string& identity,
                      const std::string& extension) {
  return folder + "/" + ContentHash().Add(identity).Hex() + extension;
}

}  // namespace

std::uint64_t ByteReader::Word() {
  std::uint64_t w = 0;
  Bytes(&w, sizeof w);
  return w;
}

double ByteReader::Real() {
  double x = 0;
  Bytes(&x, sizeof x);
  return x;
}

std::vector<double> ByteReader::Reals() {
  const std::uint64_t n = Word();
  if (!ok_ || n > (in_.size() - at_) / sizeof(double)) {
    ok_ = false;
    return {};
  }
  std::vector<double> v(n);
  Bytes(v.data(), n * sizeof(double));
  return v;
}

std::string ByteReader::Text() {
  const std::uint64_t n = Word();
  if (!ok_ || n > in_.size() - at_) {
    ok_ = false;
    return {};
  }
  std::string s(in_, at_, n);
  at_ += n;
  return s;
}

void ByteReader::Bytes(void* p, std::size_t n) {
  if (!ok_ || n > in_.size() - at_) {
    ok_ = false;
    return;
  }
  if (n == 0) return;  // an empty vector's data() may be null: no memcpy from or to it
  std::memcpy(p, in_.data() + at_, n);
  at_ += n;
}

std::optional<std::string> LoadEntry(const std::string& folder, const std::string& identity,
                                     const std::string& extension) {
  std::ifstream in(EntryPath(folder, identity, extension), std::ios::binary);
  if (!in) return std::nullopt;
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.compare(0, identity.size(), identity) != 0) return std::nullopt;
  return bytes.substr(identity.size());
}

void SaveEntry(const std::string& folder, const std::string& identity, const std::string& extension,
               const std::string& body) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) return;
  AtomicFile f(EntryPath(folder, identity, extension), std::ios::out | std::ios::binary);
  if (!f.ok()) return;
  f.stream() << identity << body;
  (void)f.Commit();
}

}  // namespace recruit
