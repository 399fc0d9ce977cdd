// Rng: the project's only source of randomness. xoshiro256** (Blackman and Vigna, 2018), seeded
// by SplitMix64. Its whole state is four 64-bit words, so it can live inside mjData.plugin_state
// (the plugin stores them as eight exact 32-bit halves, plugin/bundle.cc) and be forked exactly by
// mj_copyData. It satisfies UniformRandomBitGenerator, so <random>
// distributions take it. Callers create it with an explicit seed and pass it in.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace recruit {

class Rng {
 public:
  using result_type = std::uint64_t;
  using State = std::array<std::uint64_t, 4>;

  explicit Rng(std::uint64_t seed) { Seed(seed); }
  static Rng FromState(const State& s) {
    Rng r(0);
    r.s_ = s;
    return r;
  }

  void Seed(std::uint64_t seed) {
    for (auto& w : s_) w = SplitMix64(seed);
  }

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<result_type>::max(); }

  result_type operator()() {
    const std::uint64_t result = Rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = Rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1) with 53 random bits.
  double Uniform() { return static_cast<double>((*this)() >> 11) * 0x1.0p-53; }

  // A standard normal draw: Box-Muller, the cosine branch, two uniforms per draw (written out
  // because std::normal_distribution's algorithm, and so its numbers, differ between libraries).
  double Gaussian() {
    const double u1 = 1.0 - Uniform();  // (0, 1]
    const double u2 = Uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

  const State& state() const { return s_; }

  // A seed for an independent sub-stream (run k of a sweep, bundle b of a model): mixing the
  // parent seed with the index keeps results independent of thread count and order.
  static std::uint64_t DeriveSeed(std::uint64_t seed, std::uint64_t index) {
    std::uint64_t x = seed ^ (0x9E3779B97F4A7C15ull * (index + 1));
    return SplitMix64(x);
  }

 private:
  static std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t SplitMix64(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }

  State s_{};
};

}  // namespace recruit
