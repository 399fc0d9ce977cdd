// The decision part of `recruit tune` (no simulation): given how many seeds met the tracking
// criterion at each sampling period tried, which periods and how many seeds to run next, and the
// window of periods that meets the criterion with its edges.
//
// The periods lie on a log lattice over [dT_min, dT_max] whose neighbours differ by a factor
// q <= 1 + tolerance (the grid a sweep would need for the same resolution). A period *meets* when
// the Wilson lower bound of the fraction of seeds meeting the criterion is >= `level`, *fails*
// when the upper bound is below it, and is *open* otherwise: it gets more seeds (doubling) up to
// `max_seeds`, where it is *marginal* (the window leaves it out). The search starts on a few
// periods spread over the lattice, decides them, then bisects (in lattice index, i.e. log dT)
// between the meeting periods at the window's ends and the failing ones beyond, until each edge
// lies between lattice neighbours (known to the factor q) or the window reaches the lattice's end
// (a censored edge). Then the lattice period in the window's middle is tried, so the recommended
// period (the meeting one farthest from both edges) has room on both sides; last, the recommended
// period is run on max_seeds seeds and judged again (if it no longer meets, the search goes on
// with the window found without it).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace recruit::sweep {

struct TuneSettings {
  double dT_min = 0.0625, dT_max = 4;  // s, the range searched
  double tolerance = 0.10;             // edges known to a factor 1 + tolerance
  double level = 0.8;                  // fraction of seeds that must meet the criterion
  double confidence = 0.95;            // of the two-sided Wilson interval on that fraction
  int initial_points = 7;              // periods spread over the range to start from
  int initial_seeds = 4;               // seeds of a new period; doubled while open
  int max_seeds = 64;
  // Lattice periods are whole multiples of this (s; 0: none), e.g. the physics timestep: a
  // filter model is identified only for whole multiples of the model's timestep.
  double dT_quantum = 0;
};

// Checks the settings; "" when valid, else what is wrong (option names as `recruit tune` has them).
std::string CheckTuneSettings(const TuneSettings& s);

struct Interval {
  double lo = 0, hi = 1;
};
// P(X <= k) for X ~ Binomial(n, p): how likely k or fewer of n new seeds meet when a fraction p
// of all seeds does (a claim "p >= level" is refuted at 5 % when this is below 0.05 at p = level).
double BinomialCdf(int k, int n, double p);
// Wilson score interval of a binomial fraction: k of n at normal quantile z (n = 0: [0, 1]).
Interval WilsonInterval(int k, int n, double z);
// The two-sided normal quantile of a confidence c in (0, 1): Phi^-1((1 + c) / 2).
double NormalQuantile(double confidence);

// The dT lattice: dT_k = dT_min q^k, k = 0 .. size-1, dT_{size-1} = dT_max, each rounded to three
// significant digits (a period a lab can set; records are keyed by it) and then to a whole
// multiple of dT_quantum (periods that round to the same value are kept once).
class DtLattice {
 public:
  explicit DtLattice(const TuneSettings& s);
  int size() const { return static_cast<int>(dts_.size()); }
  double dT(int k) const { return dts_.at(k); }
  double ratio() const { return q_; }  // q, neighbours' factor before rounding

 private:
  std::vector<double> dts_;
  double q_ = 1;
};

enum class Verdict { kMeets, kFails, kOpen, kMarginal };
const char* VerdictName(Verdict v);

struct Tally {
  int seeds = 0, meeting = 0;
};
using Tallies = std::map<int, Tally>;  // by lattice index

Verdict Judge(const Tally& t, const TuneSettings& s);

// One edge of the window.
struct Edge {
  bool censored = false;  // the window reaches the lattice's end: the edge lies beyond it
  int meets = -1;         // lattice index of the meeting period nearest the edge
  int fails = -1;         // the failing (or marginal) period beyond it; -1 when censored
  bool resolved = false;  // censored, or fails and meets are lattice neighbours
};

struct Window {
  bool found = false;  // some period meets
  Edge lower, upper;
  int recommended = -1;  // a meeting period with the largest log distance to both edges
};

// The window from the periods decided so far: the longest run of meeting periods (consecutive
// among those tried); ties go to the shorter periods.
Window FindWindow(const Tallies& t, const TuneSettings& s, const DtLattice& lattice);

// The edge's estimate in s: the geometric mean of its bracket (censored: the lattice's end).
double EdgeEstimate(const Edge& e, const DtLattice& lattice);

struct Request {
  int index = 0;  // lattice index
  int seeds = 0;  // seed indices 0 .. seeds-1 should have been run there
};

// What to run next; empty when the search is done: every period tried decided (or marginal),
// both edges resolved, the window's middle tried and the recommended period run on max_seeds
// seeds; or no period meets and none is left to try
// next to the most promising marginal one (the periods between it and its tried neighbours).
std::vector<Request> NextBatch(const Tallies& t, const TuneSettings& s, const DtLattice& lattice);

}  // namespace recruit::sweep
