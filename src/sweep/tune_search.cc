#include "sweep/tune_search.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace recruit::sweep {

std::string CheckTuneSettings(const TuneSettings& s) {
  if (!(s.dT_min > 0 && s.dT_max > s.dT_min)) {
    return fmt::format("--dT-range {},{}: need 0 < min < max", s.dT_min, s.dT_max);
  }
  if (!(s.tolerance >= 0.01 && s.tolerance <= 1)) {
    return fmt::format("--tolerance {}: must be in [0.01, 1]", s.tolerance);
  }
  if (!(s.level > 0 && s.level < 1)) return fmt::format("--level {}: must be in (0, 1)", s.level);
  if (!(s.confidence >= 0.5 && s.confidence < 1)) {
    return fmt::format("--confidence {}: must be in [0.5, 1)", s.confidence);
  }
  if (s.initial_points < 2) return "--initial-points must be >= 2";
  if (!(s.dT_quantum >= 0) || s.dT_quantum > s.dT_min) {
    return fmt::format(
        "--dT-range min {} is below the dT quantum {} s (periods are its whole multiples; by "
        "default the physics timestep; --dT-quantum)",
        s.dT_min, s.dT_quantum);
  }
  if (s.initial_seeds < 1 || s.max_seeds < s.initial_seeds) {
    return fmt::format("--seeds {} / --max-seeds {}: need 1 <= seeds <= max-seeds", s.initial_seeds,
                       s.max_seeds);
  }
  return "";
}

double BinomialCdf(int k, int n, double p) {
  if (k < 0) return 0;
  if (k >= n) return 1;
  // Terms by the ratio of neighbours, in logs for large n.
  double sum = 0;
  for (int i = 0; i <= k; ++i) {
    const double log_term = std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) +
                            (i ? i * std::log(p) : 0.0) + (n - i ? (n - i) * std::log1p(-p) : 0.0);
    sum += std::exp(log_term);
  }
  return std::min(1.0, sum);
}

Interval WilsonInterval(int k, int n, double z) {
  if (n <= 0) return {0, 1};
  const double p = static_cast<double>(k) / n, z2 = z * z;
  const double centre = (p + z2 / (2 * n)) / (1 + z2 / n);
  const double half = z / (1 + z2 / n) * std::sqrt(p * (1 - p) / n + z2 / (4.0 * n * n));
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

double NormalQuantile(double confidence) {
  // Bisection on the upper tail 0.5 erfc(z / sqrt 2) = (1 - c) / 2: plenty for a threshold.
  const double tail = (1 - confidence) / 2;
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > tail ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

namespace {
double ThreeDigits(double x) {
  const double scale = std::pow(10.0, 2 - std::floor(std::log10(x)));
  return std::round(x * scale) / scale;
}
}  // namespace

DtLattice::DtLattice(const TuneSettings& s) {
  const double span = std::log(s.dT_max / s.dT_min);
  const int steps = std::max(1, static_cast<int>(std::ceil(span / std::log1p(s.tolerance) - 1e-9)));
  q_ = std::exp(span / steps);
  auto quantize = [&s](double x) {
    if (!(s.dT_quantum > 0)) return x;
    const double m = std::max(1.0, std::round(x / s.dT_quantum));
    return ThreeDigits(m * s.dT_quantum);  // the multiple, without binary residue
  };
  for (int k = 0; k <= steps; ++k) {
    double x = k == 0       ? s.dT_min
               : k == steps ? s.dT_max
                            : ThreeDigits(s.dT_min * std::exp(span * k / steps));
    x = quantize(x);
    if (dts_.empty() || x > dts_.back()) dts_.push_back(x);
  }
}

const char* VerdictName(Verdict v) {
  switch (v) {
    case Verdict::kMeets:
      return "meets";
    case Verdict::kFails:
      return "fails";
    case Verdict::kOpen:
      return "open";
    case Verdict::kMarginal:
      return "marginal";
  }
  return "?";
}

Verdict Judge(const Tally& t, const TuneSettings& s) {
  const Interval w = WilsonInterval(t.meeting, t.seeds, NormalQuantile(s.confidence));
  if (t.seeds > 0 && w.lo >= s.level) return Verdict::kMeets;
  if (t.seeds > 0 && w.hi < s.level) return Verdict::kFails;
  return t.seeds >= s.max_seeds ? Verdict::kMarginal : Verdict::kOpen;
}

Window FindWindow(const Tallies& t, const TuneSettings& s, const DtLattice& lattice) {
  std::vector<int> idx;
  std::vector<bool> meets;
  for (const auto& [k, tally] : t) {
    idx.push_back(k);
    meets.push_back(Judge(tally, s) == Verdict::kMeets);
  }
  // The longest run of consecutive meeting periods tried (by lattice span, then count).
  int best_a = -1, best_b = -1;
  for (size_t a = 0; a < idx.size(); ++a) {
    if (!meets[a] || (a > 0 && meets[a - 1])) continue;
    size_t b = a;
    while (b + 1 < idx.size() && meets[b + 1]) ++b;
    if (best_a < 0 || idx[b] - idx[a] > idx[best_b] - idx[best_a]) {
      best_a = static_cast<int>(a);
      best_b = static_cast<int>(b);
    }
  }
  Window w;
  if (best_a < 0) return w;
  w.found = true;
  w.lower.meets = idx[best_a];
  w.lower.censored = idx[best_a] == 0;
  w.lower.fails = best_a > 0 ? idx[best_a - 1] : -1;
  w.lower.resolved = w.lower.censored || w.lower.meets - w.lower.fails == 1;
  w.upper.meets = idx[best_b];
  w.upper.censored = idx[best_b] == lattice.size() - 1;
  w.upper.fails = best_b + 1 < static_cast<int>(idx.size()) ? idx[best_b + 1] : -1;
  w.upper.resolved = w.upper.censored || w.upper.fails - w.upper.meets == 1;
  // Edges in lattice index (log dT): the bracket's middle; a censored edge at the lattice's end.
  const double lo = w.lower.censored ? 0 : 0.5 * (w.lower.meets + w.lower.fails);
  const double hi = w.upper.censored ? lattice.size() - 1 : 0.5 * (w.upper.meets + w.upper.fails);
  double best = -1;
  for (int i = best_a; i <= best_b; ++i) {
    const double room = std::min(idx[i] - lo, hi - idx[i]);
    if (room > best) {
      best = room;
      w.recommended = idx[i];
    }
  }
  return w;
}

double EdgeEstimate(const Edge& e, const DtLattice& lattice) {
  if (e.meets < 0) return std::nan("");
  if (e.fails < 0) return lattice.dT(e.meets);
  return std::sqrt(lattice.dT(e.meets) * lattice.dT(e.fails));
}

namespace {

// No period meets yet: look between the most promising period (the largest fraction meeting
// among those whose Wilson upper bound still reaches the level) and its tried neighbours, until
// they are lattice neighbours. Nothing when every period tried fails outright.
std::vector<Request> Explore(const Tallies& t, const TuneSettings& s) {
  const double z = NormalQuantile(s.confidence);
  auto best = t.end();
  double best_fraction = -1;
  for (auto it = t.begin(); it != t.end(); ++it) {
    const Tally& c = it->second;
    const double f = static_cast<double>(c.meeting) / std::max(1, c.seeds);
    if (WilsonInterval(c.meeting, c.seeds, z).hi >= s.level && f > best_fraction) {
      best_fraction = f;
      best = it;
    }
  }
  std::vector<Request> out;
  if (best == t.end()) return out;
  const int k = best->first;
  if (best != t.begin() && k - std::prev(best)->first > 1) {
    out.push_back({(std::prev(best)->first + k) / 2, s.initial_seeds});
  }
  if (std::next(best) != t.end() && std::next(best)->first - k > 1) {
    out.push_back({(k + std::next(best)->first + 1) / 2, s.initial_seeds});
  }
  return out;
}

}  // namespace

std::vector<Request> NextBatch(const Tallies& t, const TuneSettings& s, const DtLattice& lattice) {
  std::vector<Request> out;
  const int n = lattice.size();
  if (t.empty()) {
    const int m = std::min(s.initial_points, n);
    for (int i = 0; i < m; ++i) {
      const int k = static_cast<int>(std::lround(static_cast<double>(i) * (n - 1) / (m - 1)));
      if (out.empty() || out.back().index != k) out.push_back({k, s.initial_seeds});
    }
    return out;
  }
  // Open periods first: more seeds (doubling, up to the cap).
  for (const auto& [k, tally] : t) {
    if (Judge(tally, s) == Verdict::kOpen) {
      out.push_back({k, std::min(s.max_seeds, std::max(tally.seeds * 2, s.initial_seeds))});
    }
  }
  if (!out.empty()) return out;
  const Window w = FindWindow(t, s, lattice);
  if (!w.found) return Explore(t, s);
  if (!w.lower.resolved) out.push_back({(w.lower.fails + w.lower.meets) / 2, s.initial_seeds});
  if (!w.upper.resolved) out.push_back({(w.upper.meets + w.upper.fails + 1) / 2, s.initial_seeds});
  if (!out.empty()) return out;
  // Edges known: try the window's middle (in log dT) if no period there was, so the
  // recommendation has room on both sides.
  const double lo = w.lower.censored ? 0 : 0.5 * (w.lower.meets + w.lower.fails);
  const double hi = w.upper.censored ? n - 1 : 0.5 * (w.upper.meets + w.upper.fails);
  const int mid = static_cast<int>(std::floor(0.5 * (lo + hi)));
  if (mid > w.lower.meets && mid < w.upper.meets && !t.count(mid)) {
    out.push_back({mid, s.initial_seeds});
    return out;
  }
  // Last, the recommended period on max_seeds seeds: the first period of a near-level plateau to
  // reach 16 of 16 would otherwise be recommended on its luck. If it no longer meets, the window
  // is found again without it.
  if (t.at(w.recommended).seeds < s.max_seeds) out.push_back({w.recommended, s.max_seeds});
  return out;
}

}  // namespace recruit::sweep
