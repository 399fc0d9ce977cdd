#include "sweep/sampling.h"

#include <algorithm>
#include <numeric>
#include <string>

#include "common/rng.h"

namespace recruit::sweep {
namespace {

// Joe and Kuo's new-joe-kuo-6.21201 table, dimensions 2..12: degree s, coefficients a, and
// the initial direction numbers m_1..m_s. Dimension 1 is the van der Corput sequence.
struct Direction {
  int s;
  unsigned a;
  unsigned m[6];
};
constexpr Direction kDirections[] = {{1, 0, {1}},
                                     {2, 1, {1, 3}},
                                     {3, 1, {1, 3, 1}},
                                     {3, 2, {1, 1, 1}},
                                     {4, 1, {1, 1, 3, 3}},
                                     {4, 4, {1, 3, 5, 13}},
                                     {5, 2, {1, 1, 5, 5, 17}},
                                     {5, 4, {1, 1, 5, 5, 5}},
                                     {5, 7, {1, 1, 7, 11, 19}},
                                     {5, 11, {1, 1, 5, 1, 1}},
                                     {5, 13, {1, 1, 1, 3, 11}}};
constexpr int kBits = 32;

std::vector<std::uint32_t> DirectionNumbers(int dim) {
  std::vector<std::uint32_t> v(kBits);
  if (dim == 0) {
    for (int i = 0; i < kBits; ++i) v[i] = 1u << (kBits - 1 - i);
    return v;
  }
  const Direction& d = kDirections[dim - 1];
  for (int i = 0; i < d.s; ++i) v[i] = d.m[i] << (kBits - 1 - i);
  for (int i = d.s; i < kBits; ++i) {
    std::uint32_t x = v[i - d.s] ^ (v[i - d.s] >> d.s);
    for (int k = 1; k < d.s; ++k) {
      if ((d.a >> (d.s - 1 - k)) & 1u) x ^= v[i - k];
    }
    v[i] = x;
  }
  return v;
}

}  // namespace

int MaxSobolDims() { return 1 + static_cast<int>(std::size(kDirections)); }

UnitPoints LatinHypercube(int n, int dims, std::uint64_t seed) {
  UnitPoints pts(n, std::vector<double>(dims));
  Rng rng(seed);
  for (int d = 0; d < dims; ++d) {
    std::vector<int> perm(n);
    std::iota(perm.begin(), perm.end(), 0);
    for (int i = n - 1; i > 0; --i) {  // Fisher-Yates with our own Rng (std::shuffle varies)
      const int j = static_cast<int>(rng() % static_cast<std::uint64_t>(i + 1));
      std::swap(perm[i], perm[j]);
    }
    for (int i = 0; i < n; ++i) pts[i][d] = (perm[i] + rng.Uniform()) / n;
  }
  return pts;
}

Result<UnitPoints> Sobol(int n, int dims, std::uint64_t seed) {
  if (dims < 1 || dims > MaxSobolDims()) {
    return Error{"Sobol sample: " + std::to_string(dims) + " dimensions; allowed 1.." +
                 std::to_string(MaxSobolDims())};
  }
  if (n < 1 || n > (1 << 30)) return Error{"Sobol sample: n must be in 1..2^30"};
  UnitPoints pts(n, std::vector<double>(dims));
  Rng rng(seed);
  for (int d = 0; d < dims; ++d) {
    const auto v = DirectionNumbers(d);
    const std::uint32_t shift = seed == 0 ? 0u : static_cast<std::uint32_t>(rng() >> 32);
    std::uint32_t x = 0;
    for (int i = 0; i < n; ++i) {
      if (i > 0) {  // Gray-code order: flip the direction number of i-1's lowest zero bit
        int c = 0;
        for (unsigned k = static_cast<unsigned>(i - 1); k & 1u; k >>= 1) ++c;
        x ^= v[c];
      }
      pts[i][d] = static_cast<double>(x ^ shift) * 0x1.0p-32;
    }
  }
  return pts;
}

}  // namespace recruit::sweep
