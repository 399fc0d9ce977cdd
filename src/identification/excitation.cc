#include "identification/excitation.h"

#include <algorithm>

#include "common/rng.h"

namespace recruit::identification {

Excitation MakeExcitation(int settle, int total, std::uint64_t seed) {
  settle = std::max(settle, 2);
  Excitation e;
  auto hold = [&](double on, double off, int n) {
    // The broadcast is sent once; the following instants broadcast nothing.
    for (int i = 0; i < n; ++i) {
      e.p_on.push_back(i == 0 ? on : 0.0);
      e.p_off.push_back(i == 0 ? off : 0.0);
    }
  };
  hold(1, 0, settle);
  hold(0, 1, settle);
  for (int w = 1; w <= settle / 2; ++w) {
    hold(1, 0, w);
    hold(0, 1, settle);
  }
  hold(1, 0, settle);
  for (int w = 1; w <= settle / 2; ++w) {
    hold(0, 1, w);
    hold(1, 0, settle);
  }
  hold(0, 1, settle);
  hold(0.5, 0, settle);
  hold(0.5, 0, settle);
  hold(0, 0.25, settle);
  hold(0, 1, settle);
  Rng rng(seed);
  while (e.size() < total) {
    const int n = 1 + static_cast<int>(rng.Uniform() * (settle / 2));
    const double on = rng.Uniform() < 0.75 ? 0.5 * rng.Uniform() : 0.0;
    const double off = rng.Uniform() < 0.75 ? 0.5 * rng.Uniform() : 0.0;
    hold(on, off, n);
  }
  e.p_on.resize(total);
  e.p_off.resize(total);
  return e;
}

}  // namespace recruit::identification
