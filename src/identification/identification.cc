#include "identification/identification.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <utility>

#include "estimation/transit_weights.h"
#include "identification/nelder_mead.h"
#include "identification/nonnegative_qp.h"

namespace recruit::identification {
namespace {

// Mean state trajectory: row k is x_k^T (counts), from all units cold.
Eigen::MatrixXd MeanTrajectory(const TransientChain& chain, const SwitchingLog& log, int rows) {
  const int m = chain.num_states();
  Eigen::MatrixXd X(rows, m);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  x[chain.cold()] = log.num_units;
  for (int k = 0; k < rows; ++k) {
    X.row(k) = x.transpose();
    chain.PropagateMean(log.InputOn(k), log.InputOff(k), x);
  }
  return X;
}

// Neighbour differences along the heating chain (heat1..heatK, hot) and the cooling chain
// (cool1..coolK, cold). The entry edges (cold -> heat1, hot -> cool1) are left out: the force
// may jump there within one period (at long dT especially), and tying hot to cool1 would drag
// the settled force down.
Eigen::MatrixXd ChainDifferences(const TransientChain& c) {
  const int K = c.chain_length, m = c.num_states();
  std::vector<int> heat_path, cool_path;
  for (int i = 1; i <= K; ++i) heat_path.push_back(c.heat(i));
  for (int i = 1; i <= K; ++i) cool_path.push_back(c.cool(i));
  heat_path.push_back(c.hot());
  cool_path.push_back(c.cold());
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(2 * K, m);
  int r = 0;
  for (const auto* path : {&heat_path, &cool_path}) {
    for (size_t i = 0; i + 1 < path->size(); ++i, ++r) {
      d(r, (*path)[i]) = -1;
      d(r, (*path)[i + 1]) = 1;
    }
  }
  return d;
}

// H = B z in the transient's order: z = (cold force, the K + 1 rises along cold, heat1.., hot,
// the K + 1 falls along hot, cool1.., cold), every rise and fall >= 0. Cooling states sit above
// cold by the falls still to come; the loop closes (rises sum to falls) by a penalty.
Eigen::MatrixXd OrderedBasis(const TransientChain& c) {
  const int K = c.chain_length;
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(c.num_states(), 2 * K + 3);
  B.col(0).setOnes();
  for (int j = 0; j <= K; ++j) {
    for (int i = j + 1; i <= K; ++i) B(c.heat(i), 1 + j) = 1;
    B(c.hot(), 1 + j) = 1;
    for (int i = 1; i <= j; ++i) B(c.cool(i), K + 2 + j) = 1;
  }
  return B;
}

// min h^T N h / 2 - b^T h over the ordered forces (OrderedBasis).
Eigen::VectorXd OrderedSolve(const Eigen::MatrixXd& B, const Eigen::MatrixXd& normal,
                             const Eigen::VectorXd& b) {
  const int K1 = (static_cast<int>(B.cols()) - 1) / 2;  // K + 1
  Eigen::MatrixXd Q = B.transpose() * normal * B;
  Eigen::VectorXd closure = Eigen::VectorXd::Zero(B.cols());
  closure.segment(1, K1).setOnes();
  closure.tail(K1).setConstant(-1);
  Q += 1e6 * std::max(Q.trace() / Q.rows(), 1e-300) * closure * closure.transpose();
  std::vector<bool> free(B.cols(), false);
  free[0] = true;
  return B * NonNegativeQp(Q, B.transpose() * b, free);
}

class Problem {
 public:
  Problem(const SwitchingLog& log, int train, const FitOptions& opt, TransientChain shape,
          bool ordered)
      : log_(log), train_(train), opt_(opt), shape_(std::move(shape)), ordered_(ordered) {
    D_ = ChainDifferences(shape_);
    if (ordered_) B_ = OrderedBasis(shape_);
    y_ = Eigen::Map<const Eigen::VectorXd>(log.force.data(), train_);
    advance_weight_ = std::sqrt(opt.advance_prior * y_.squaredNorm() / train_);
  }
  int num_params() const { return 2 * shape_.chain_length; }

  TransientChain WithParams(const Eigen::VectorXd& a) const {
    TransientChain c = shape_;
    const int K = c.chain_length;
    c.heat_advance = a.head(K);
    c.cool_advance = a.tail(K);
    return c;
  }

  const TransientChain& shape() const { return shape_; }
  void set_shape(const TransientChain& c) { shape_ = c; }

  // Solves for H given the advance probabilities; returns the stacked residual
  // [y - X H; sqrt(mu) D H] and H.
  Eigen::VectorXd Residual(const Eigen::VectorXd& a, Eigen::VectorXd* h_out = nullptr) const {
    return ResidualOf(WithParams(a), h_out);
  }
  Eigen::VectorXd ResidualOf(const TransientChain& c, Eigen::VectorXd* h_out = nullptr) const {
    const Eigen::MatrixXd X = MeanTrajectory(c, log_, train_);
    Eigen::MatrixXd normal = X.transpose() * X;
    const double mu = opt_.smoothness * std::max(normal.trace() / normal.rows(), 1e-300);
    normal += mu * D_.transpose() * D_;
    // A tiny ridge keeps states the data never reach (and the regularisation does not pin)
    // well-defined.
    normal.diagonal().array() += 1e-12 * std::max(normal.trace() / normal.rows(), 1e-300);
    const Eigen::VectorXd b = X.transpose() * y_;
    const Eigen::VectorXd h = ordered_ ? OrderedSolve(B_, normal, b) : normal.ldlt().solve(b);
    const int K = c.chain_length;
    Eigen::VectorXd r(train_ + D_.rows() + 2 * K);
    r.head(train_) = y_ - X * h;
    r.segment(train_, D_.rows()) = std::sqrt(mu) * (D_ * h);
    // Prior towards progress (a = 1): an edge the data do not constrain lets units move on to
    // the settled state instead of stalling in a state whose force nothing pins down.
    r.segment(train_ + D_.rows(), K) = advance_weight_ * (1.0 - c.heat_advance.array()).matrix();
    r.tail(K) = advance_weight_ * (1.0 - c.cool_advance.array()).matrix();
    if (h_out) *h_out = h;
    return r;
  }

 private:
  const SwitchingLog& log_;
  int train_;
  FitOptions opt_;
  TransientChain shape_;
  bool ordered_;
  Eigen::MatrixXd D_, B_;
  Eigen::VectorXd y_;
  double advance_weight_ = 0;
};

// Bounded Levenberg-Marquardt with forward-difference Jacobian. Returns the final parameters;
// `cost` and `iterations` report the run.
Eigen::VectorXd FitAdvance(const Problem& p, Eigen::VectorXd a, double lo, int max_iter,
                           double* cost, int* iterations) {
  const int n = p.num_params();
  Eigen::VectorXd r = p.Residual(a);
  double f = r.squaredNorm();
  double damping = 1e-3;
  int it = 0;
  for (; it < max_iter; ++it) {
    Eigen::MatrixXd J(r.size(), n);
    for (int i = 0; i < n; ++i) {
      double h = 1e-6 + 1e-4 * std::abs(a[i]);
      Eigen::VectorXd ap = a;
      if (ap[i] + h > 1) h = -h;  // stay inside the box
      ap[i] += h;
      J.col(i) = (p.Residual(ap) - r) / h;
    }
    const Eigen::VectorXd g = J.transpose() * r;
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    // Parameters held at a bound by the gradient do not move (projected step).
    std::vector<bool> free(n, true);
    for (int i = 0; i < n; ++i) {
      if ((a[i] >= 1 && g[i] < 0) || (a[i] <= lo && g[i] > 0)) free[i] = false;
    }
    bool improved = false;
    for (int tries = 0; tries < 12 && !improved; ++tries) {
      Eigen::MatrixXd M = JtJ;
      for (int i = 0; i < n; ++i) {
        M(i, i) += damping * (JtJ(i, i) + 1e-12 * JtJ.trace() / n + 1e-300);
        if (!free[i]) {
          M.row(i).setZero();
          M.col(i).setZero();
          M(i, i) = 1;
        }
      }
      Eigen::VectorXd rhs = -g;
      for (int i = 0; i < n; ++i) {
        if (!free[i]) rhs[i] = 0;
      }
      const Eigen::VectorXd step = M.ldlt().solve(rhs);
      const Eigen::VectorXd an = (a + step).cwiseMax(lo).cwiseMin(1.0);
      const Eigen::VectorXd rn = p.Residual(an);
      const double fn = rn.squaredNorm();
      if (fn < f) {
        const double rel = (f - fn) / std::max(f, 1e-300);
        a = an;
        r = rn;
        f = fn;
        damping = std::max(damping / 3, 1e-9);
        improved = true;
        if (rel < 1e-10) {
          *cost = f;
          *iterations = it + 1;
          return a;
        }
      } else {
        damping *= 4;
      }
    }
    if (!improved) break;
  }
  *cost = f;
  *iterations = it;
  return a;
}

// Greedy least-squares choice of the mid-transient switching targets: for every source state
// (heat<i>, cool<i>), try each state of the other chain as its target, keep the one with the
// smallest cost (H re-solved each time, advance probabilities fixed). Returns true if any
// target changed.
bool RefineTargets(Problem& p, const Eigen::VectorXd& a) {
  TransientChain c = p.WithParams(a);
  double best = p.ResidualOf(c).squaredNorm();
  bool changed = false;
  const int K = c.chain_length;
  for (int s = 1; s < c.num_states(); ++s) {
    if (s == c.hot()) continue;
    const bool on = s < c.hot();
    std::vector<int> candidates;
    if (on) {
      candidates.push_back(c.cold());
      for (int i = 1; i <= K; ++i) candidates.push_back(c.cool(i));
    } else {
      for (int i = 1; i <= K; ++i) candidates.push_back(c.heat(i));
      candidates.push_back(c.hot());
    }
    std::vector<int>& target = on ? c.switch_off : c.switch_on;
    const int original = target[s];
    int chosen = original;
    for (int t : candidates) {
      if (t == original) continue;
      target[s] = t;
      const double f = p.ResidualOf(c).squaredNorm();
      if (f < best * (1 - 1e-9)) {
        best = f;
        chosen = t;
      }
    }
    target[s] = chosen;
    changed |= chosen != original;
  }
  p.set_shape(c);
  return changed;
}

}  // namespace

Eigen::VectorXd TransitWeights(const TransientChain& c) {
  return estimation::TransitWeights(c.Interior(), c.force.transpose());
}

// The population Kalman filter of eqs. 15-27 (extended covariance), dense and written out here:
// the reference the fast filter (src/estimation) is tested against is not used to fit.
double NoiseNegLogLikelihood(const TransientChain& c, const SwitchingLog& log, int rows,
                             const NoiseModel& noise) {
  const int m = c.num_states();
  const Eigen::VectorXd weights = TransitWeights(c);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  x[c.cold()] = log.num_units;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(m, m);
  const Eigen::VectorXd& h = c.force;
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(m, m);
  double nll = 0;
  for (int k = 0; k < rows; ++k) {
    const double R = noise.At(weights.dot(x.cwiseMax(0.0)));
    const Eigen::VectorXd ph = P * h;
    const double S = h.dot(ph) + R;
    const double nu = log.force[k] - h.dot(x);
    nll += std::log(S) + nu * nu / S;
    const Eigen::VectorXd gain = ph / S;
    x += gain * nu;
    const Eigen::MatrixXd ikh = I - gain * h.transpose();
    P = ikh * P * ikh.transpose() + R * gain * gain.transpose();  // Joseph form
    const Eigen::MatrixXd A = c.Matrix(log.p_on[k], log.p_off[k]);
    const Eigen::VectorXd xp = x.cwiseMax(0.0);  // Qz stays PSD on the feasible counts
    Eigen::MatrixXd Q = -A * xp.asDiagonal() * A.transpose();
    Q.diagonal() += A * xp;
    P = A * P * A.transpose() + Q;
    x = A * x;
  }
  return nll;
}

namespace {

// The minimiser of a unimodal f on [a, b]: golden-section search to an interval below `tol` (at
// most 40 steps), its midpoint.
double GoldenMinimum(const std::function<double(double)>& f, double a, double b, double tol) {
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 40 && b - a > tol; ++it) {
    if (f1 < f2) {
      b = x2;
      x2 = x1;
      f2 = f1;
      x1 = b - g * (b - a);
      f1 = f(x1);
    } else {
      a = x1;
      x1 = x2;
      f1 = f2;
      x2 = a + g * (b - a);
      f2 = f(x2);
    }
  }
  return (a + b) / 2;
}

}  // namespace

// R by maximum likelihood: golden-section search on log R in [lo, hi].
double MaxLikelihoodNoise(const TransientChain& c, const SwitchingLog& log, int rows, double lo,
                          double hi) {
  auto nll = [&](double log_r) {
    return NoiseNegLogLikelihood(c, log, rows, {std::exp(log_r), 0.0});
  };
  return std::exp(GoldenMinimum(nll, std::log(lo), std::log(hi), 1e-3));
}

NoiseModel MaxLikelihoodNoiseModel(const TransientChain& c, const SwitchingLog& log, int rows,
                                   double constant, double lo, double hi) {
  const NoiseModel flat{constant, 0.0};
  // The mean units in transit along the mean trajectory: the scale of r_transit's start.
  const double transit = (MeanTrajectory(c, log, rows) * TransitWeights(c)).mean();
  if (!(transit > 1e-9)) return flat;
  const double log_lo = std::log(lo), log_hi = std::log(hi);
  // r_transit is searched down to 1e-6 of the floor per unit: below that its term is nothing.
  const double log_rlo = std::log(lo * 1e-6), log_rhi = std::log(hi / transit);
  auto model_at = [&](const Eigen::VectorXd& p) {
    return NoiseModel{std::exp(std::clamp(p[0], log_lo, log_hi)),
                      std::exp(std::clamp(p[1], log_rlo, log_rhi))};
  };
  auto nll = [&](const Eigen::VectorXd& p) {
    return NoiseNegLogLikelihood(c, log, rows, model_at(p));
  };
  // Start with a tenth of the constant R left at every state and the rest per unit in transit.
  const Eigen::Vector2d start(std::log(std::max(0.1 * constant, lo)),
                              std::log(std::max(0.9 * constant / transit, lo * 1e-6)));
  const NelderMeadResult best =
      NelderMead(nll, start, Eigen::Vector2d::Constant(std::log(10.0)), 1e-4, 1e-3, 200);
  return best.value < NoiseNegLogLikelihood(c, log, rows, flat) ? model_at(best.x) : flat;
}

namespace {

// The median of |v - median(v)| (v not empty; reordered).
double MedianAbsoluteDeviation(std::vector<double>& v) {
  auto median = [](std::vector<double>& w) {
    const size_t mid = w.size() / 2;
    std::nth_element(w.begin(), w.begin() + mid, w.end());
    const double upper = w[mid];
    if (w.size() % 2 == 1) return upper;
    return 0.5 * (upper + *std::max_element(w.begin(), w.begin() + mid));
  };
  const double center = median(v);
  for (double& x : v) x = std::abs(x - center);
  return median(v);
}

}  // namespace

std::vector<int> ForceSettledSamples(const TransientChain& c, const SwitchingLog& log, int rows) {
  const Eigen::VectorXd& h = c.force;
  const double cold = h[c.cold()], hot = h[c.hot()], tol = 0.01 * std::abs(hot - cold);
  Eigen::VectorXd moving(c.num_states());
  for (int j = 0; j < c.num_states(); ++j) {
    moving[j] = std::min(std::abs(h[j] - cold), std::abs(h[j] - hot)) > tol ? 1.0 : 0.0;
  }
  const Eigen::VectorXd in_moving = MeanTrajectory(c, log, rows) * moving;
  std::vector<int> settled;
  for (int k = 0; k < rows; ++k) {
    if (in_moving[k] < 0.5) settled.push_back(k);
  }
  return settled;
}

NoiseModel SettledNoiseModel(const TransientChain& c, const SwitchingLog& log, int rows,
                             double constant, double lo, double hi) {
  const std::vector<int> settled =
      log.has_realized() ? ForceSettledSamples(c, log, rows) : std::vector<int>();
  if (settled.size() < 20) return MaxLikelihoodNoiseModel(c, log, rows, constant, lo, hi);
  // A robust scale (1.4826 x the median absolute deviation: the standard deviation of Gaussian
  // noise): a settled sample now and then follows a pulse the chain takes for settled (a unit
  // switched back on after one period is at the hot state's force in the chain, tens of N short
  // of it on the plant), whose error is the transit's, not the sensor's.
  const Eigen::VectorXd predicted = PredictMeanForce(c, log);
  std::vector<double> residual;
  for (int k : settled) residual.push_back(log.force[k] - predicted[k]);
  const double sd = 1.4826 * MedianAbsoluteDeviation(residual);
  const double r0 = std::clamp(sd * sd, lo, hi);
  const double transit = (MeanTrajectory(c, log, rows) * TransitWeights(c)).mean();
  if (!(transit > 1e-9)) return {r0, 0.0};
  // r_transit2 from 1e-6 of the floor over the mean units in transit (below that its term is
  // nothing) to the whole force variance over their square.
  auto nll = [&](double log_rt2) {
    return NoiseNegLogLikelihood(c, log, rows, {r0, 0.0, std::exp(log_rt2)});
  };
  const double rt2 = std::exp(
      GoldenMinimum(nll, std::log(lo * 1e-6 / transit), std::log(hi / (transit * transit)), 1e-3));
  return {r0, 0.0, rt2};
}

namespace {

// The two-state model's mean force prediction: on-count from the broadcasts, H = [h0, h1]
// fitted on the training samples.
Eigen::VectorXd TwoStatePrediction(const SwitchingLog& log, int train) {
  const int n = log.size();
  Eigen::MatrixXd X(n, 2);
  double on = 0;
  for (int k = 0; k < n; ++k) {
    X(k, 0) = log.num_units - on;
    X(k, 1) = on;
    on = on + log.InputOn(k) * (log.num_units - on) - log.InputOff(k) * on;
  }
  const Eigen::MatrixXd Xt = X.topRows(train);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(log.force.data(), train);
  Eigen::Matrix2d normal = Xt.transpose() * Xt;
  normal.diagonal().array() += 1e-12 * normal.trace();
  const Eigen::Vector2d h = normal.ldlt().solve(Xt.transpose() * y);
  return X * h;
}

// Start from the deterministic chain (each state = k periods since the switch) with the
// heat-level targets; alternate the switching targets (greedy) and the advance probabilities
// (Levenberg-Marquardt) until the targets settle. Two schedules, the better kept: targets
// first (when the heat-level targets are far off, fitting the advance probabilities to them
// would bend the chains) and advance probabilities first (when they are right, a greedy step
// taken with all a = 1 can move a target to compensate for the wrong a).
IdentificationResult FitChain(const SwitchingLog& log, int train, const FitOptions& opt,
                              bool ordered) {
  IdentificationResult best;
  best.cost = std::numeric_limits<double>::infinity();
  for (bool targets_first : {true, false}) {
    Problem problem(log, train, opt, TransientChain::Uniform(opt.num_states, 1.0), ordered);
    Eigen::VectorXd a = Eigen::VectorXd::Ones(problem.num_params());
    int total_iters = 0;
    for (int round = 0; round < opt.max_rounds; ++round) {
      bool changed = false;
      if (targets_first || round > 0) {
        for (int sweep = 0; sweep < 3 && RefineTargets(problem, a); ++sweep) changed = true;
        if (round > 0 && !changed) break;
      }
      double cost = 0;
      int iters = 0;
      a = FitAdvance(problem, a, opt.min_advance, opt.max_iterations, &cost, &iters);
      total_iters += iters;
    }
    Eigen::VectorXd h;
    const double cost = problem.Residual(a, &h).squaredNorm();
    if (cost < best.cost) {
      best.cost = cost;
      best.iterations = total_iters;
      best.chain = problem.WithParams(a);
      best.chain.force = h;
    }
  }
  return best;
}

// `loose`'s targets kept, its advance probabilities refitted with H in order.
IdentificationResult Reorder(const SwitchingLog& log, int train, const FitOptions& opt,
                             const IdentificationResult& loose) {
  Problem problem(log, train, opt, loose.chain, true);
  Eigen::VectorXd a(problem.num_params());
  a << loose.chain.heat_advance, loose.chain.cool_advance;
  IdentificationResult fit;
  int iters = 0;
  a = FitAdvance(problem, a, opt.min_advance, opt.max_iterations, &fit.cost, &iters);
  Eigen::VectorXd h;
  fit.cost = problem.Residual(a, &h).squaredNorm();
  fit.iterations = loose.iterations + iters;
  fit.chain = problem.WithParams(a);
  fit.chain.force = h;
  return fit;
}

}  // namespace

double OrderViolation(const TransientChain& c) {
  const int K = c.chain_length;
  const Eigen::VectorXd& h = c.force;
  double worst = 0;
  int prev_heat = c.cold(), prev_cool = c.hot();
  for (int i = 1; i <= K + 1; ++i) {
    const int heat = i <= K ? c.heat(i) : c.hot();
    const int cool = i <= K ? c.cool(i) : c.cold();
    worst = std::max({worst, h[prev_heat] - h[heat], h[cool] - h[prev_cool]});
    prev_heat = heat;
    prev_cool = cool;
  }
  return worst;
}

Eigen::VectorXd PredictMeanForce(const TransientChain& chain, const SwitchingLog& log) {
  return MeanTrajectory(chain, log, log.size()) * chain.force;
}

FitMetrics Score(const Eigen::VectorXd& predicted, const SwitchingLog& log, int begin, int end) {
  FitMetrics m;
  m.samples = end - begin;
  if (m.samples <= 0) return m;
  double mean = 0;
  for (int k = begin; k < end; ++k) mean += log.force[k];
  mean /= m.samples;
  double ss_res = 0, ss_tot = 0;
  for (int k = begin; k < end; ++k) {
    ss_res += std::pow(log.force[k] - predicted[k], 2);
    ss_tot += std::pow(log.force[k] - mean, 2);
  }
  m.rmse = std::sqrt(ss_res / m.samples);
  m.r2 = ss_tot > 0 ? 1 - ss_res / ss_tot : std::numeric_limits<double>::quiet_NaN();
  return m;
}

namespace {

// The search range of R: [noise_floor * (settled unit force)^2, the force's variance] (at least
// 100 floors wide).
std::pair<double, double> NoiseRange(const TransientChain& c, const SwitchingLog& log, int rows,
                                     const FitOptions& opt) {
  const double unit = c.force[c.hot()] - c.force[c.cold()];
  const double floor = std::max(opt.noise_floor * unit * unit, 1e-12);
  const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(log.force.data(), rows);
  const double var_y = (y.array() - y.mean()).square().mean();
  return {floor, std::max(var_y, 100 * floor)};
}

}  // namespace

double ConstantNoise(const TransientChain& c, const SwitchingLog& log, int rows,
                     const FitOptions& opt) {
  const auto [lo, hi] = NoiseRange(c, log, rows, opt);
  return MaxLikelihoodNoise(c, log, rows, lo, hi);
}

NoiseModel FitNoiseModel(const TransientChain& c, const SwitchingLog& log, int rows,
                         double constant, const FitOptions& opt) {
  const auto [lo, hi] = NoiseRange(c, log, rows, opt);
  return SettledNoiseModel(c, log, rows, constant, lo, hi);
}

Result<IdentificationResult> IdentifyTransientModel(const SwitchingLog& log,
                                                    const FitOptions& opt) {
  if (Status s = log.Validate("switching log"); !s) return Error{s.error(), s.code()};
  if (opt.num_states < 4 || opt.num_states % 2 != 0) {
    return Error{"identify: num_states = " + std::to_string(opt.num_states) +
                 " must be even and >= 4"};
  }
  if (!(opt.holdout_fraction >= 0 && opt.holdout_fraction < 1)) {
    return Error{"identify: holdout fraction must be in [0, 1)"};
  }
  if (!(opt.min_advance > 0 && opt.min_advance <= 1)) {
    return Error{"identify: min_advance must be in (0, 1]"};
  }
  if (!(opt.smoothness >= 0)) return Error{"identify: smoothness must be >= 0"};
  const int n = log.size();
  const int train = static_cast<int>(std::lround(n * (1 - opt.holdout_fraction)));
  if (train < opt.num_states * 3) {
    return Error{"identify: " + std::to_string(train) + " training samples are too few for " +
                 std::to_string(opt.num_states) + " states (need at least 3 per state)"};
  }
  IdentificationResult best = FitChain(log, train, opt, opt.monotone);
  if (opt.monotone) {
    // The loose fit sometimes finds advance probabilities and targets the ordered schedules
    // miss; refitted in order from there, it competes on the same cost.
    IdentificationResult loose = FitChain(log, train, opt, false);
    if (OrderViolation(loose.chain) > 0) loose = Reorder(log, train, opt, loose);
    if (loose.cost < best.cost) best = loose;
  }

  const Eigen::VectorXd pred = PredictMeanForce(best.chain, log);
  best.train = Score(pred, log, 0, train);
  best.holdout = Score(pred, log, train, n);
  best.two_state_holdout = Score(TwoStatePrediction(log, train), log, train, n);

  if (!opt.fit_noise) return best;
  best.force_noise_var = ConstantNoise(best.chain, log, train, opt);
  best.noise = FitNoiseModel(best.chain, log, train, best.force_noise_var, opt);
  return best;
}

}  // namespace recruit::identification
