#include "estimation/exact_filter.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "estimation/population_chain.h"

namespace recruit::estimation {
namespace {

constexpr int64_t kMaxGrid = int64_t{1} << 24;

// Calls f(c) for every composition c of n into m parts, in lexicographic order.
void ForEachComposition(int n, int m, const std::function<void(const std::vector<int>&)>& f) {
  std::vector<int> c(m, 0);
  std::function<void(int, int)> rec = [&](int i, int rest) {
    if (i == m - 1) {
      c[i] = rest;
      f(c);
      return;
    }
    for (int v = 0; v <= rest; ++v) {
      c[i] = v;
      rec(i + 1, rest - v);
    }
  };
  rec(0, n);
}

}  // namespace

Result<ExactBayesFilter> ExactBayesFilter::Create(const FilterModel& model,
                                                  const ExactFilterOptions& options) {
  if (Status s = model.Validate(); !s.ok()) return Error{s.error(), s.code()};
  const int m = model.num_states();
  const int64_t N = model.N;
  const uint64_t S = CountStateVectors(N, m, options.max_states);
  if (S > options.max_states) {
    return Error{"exact filter: N = " + std::to_string(N) +
                 " agents over m = " + std::to_string(m) + " states give more than " +
                 std::to_string(options.max_states) +
                 " count vectors (C(N + m - 1, m - 1)); the exact filter refuses spaces this large "
                 "(use the Kalman or particle filter)"};
  }
  if (model.G.cols() > 0 && model.ProcessNoise().cwiseAbs().maxCoeff() > 0.0) {
    return Error{
        "exact filter: the model has process noise (G, Qw), which the exact filter "
        "over count vectors does not model"};
  }
  int64_t grid = 1;
  std::vector<int64_t> radix(m, 1);
  for (int i = 0; i < m - 1; ++i) {
    radix[i] = grid;
    grid *= (N + 1);
    if (grid > kMaxGrid) {
      return Error{"exact filter: (N + 1)^(m - 1) = too large a convolution grid (limit 2^24)"};
    }
  }
  ExactBayesFilter f;
  f.m_ = m;
  f.N_ = N;
  f.H_ = model.H;
  f.R_llt_.compute(model.R);
  f.options_ = options;
  f.radix_ = radix;
  f.grid_to_state_.assign(grid, -1);
  f.states_.reserve(S * m);
  ForEachComposition(static_cast<int>(N), m, [&](const std::vector<int>& c) {
    int64_t g = 0;
    for (int i = 0; i < m - 1; ++i) g += c[i] * radix[i];
    f.grid_to_state_[g] = static_cast<int32_t>(f.grid_index_.size());
    f.grid_index_.push_back(g);
    for (int v : c) f.states_.push_back(v);
  });
  f.scratch_.assign(grid, 0.0);
  f.HX_.resize(model.num_outputs(), static_cast<Eigen::Index>(S));
  for (size_t k = 0; k < S; ++k) f.HX_.col(k) = model.H * f.State(k);

  // Prior.
  f.p_.assign(S, 0.0);
  if (model.P0.cwiseAbs().maxCoeff() == 0.0) {
    const Eigen::VectorXd r = model.x0.array().round();
    if ((r - model.x0).cwiseAbs().maxCoeff() > 1e-9) {
      return Error{"exact filter: with P0 = 0 the initial state x0 must be integer counts"};
    }
    int64_t g = 0;
    for (int i = 0; i < m - 1; ++i) g += static_cast<int64_t>(r(i)) * radix[i];
    f.p_[f.grid_to_state_[g]] = 1.0;
  } else {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(model.P0);
    const double tol = 1e-9 * es.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::VectorXd inv = es.eigenvalues();
    for (Eigen::Index i = 0; i < inv.size(); ++i) inv(i) = inv(i) > tol ? 1.0 / inv(i) : 0.0;
    const Eigen::MatrixXd Pinv =
        es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
    std::vector<double> logw(S);
    double best = -INFINITY;
    for (size_t k = 0; k < S; ++k) {
      const Eigen::VectorXd d = f.State(k) - model.x0;
      logw[k] = -0.5 * d.dot(Pinv * d);
      best = std::max(best, logw[k]);
    }
    double sum = 0.0;
    for (size_t k = 0; k < S; ++k) sum += f.p_[k] = std::exp(logw[k] - best);
    for (double& p : f.p_) p /= sum;
  }
  return f;
}

Eigen::VectorXd ExactBayesFilter::State(size_t k) const {
  Eigen::VectorXd x(m_);
  for (int i = 0; i < m_; ++i) x(i) = states_[k * m_ + i];
  return x;
}

void ExactBayesFilter::PrepareColumnPmfs(const Eigen::MatrixXd& A) {
  if (pmf_A_.size() == A.size() && pmf_A_ == A) return;
  pmf_A_ = A;
  pmf_.assign(m_, {});
  for (int j = 0; j < m_; ++j) {
    pmf_[j].resize(N_ + 1);
    Eigen::VectorXd loga = A.col(j).array().log();
    for (int n = 0; n <= N_; ++n) {
      auto& list = pmf_[j][n];
      const double lfn = std::lgamma(n + 1.0);
      ForEachComposition(n, m_, [&](const std::vector<int>& c) {
        double lp = lfn;
        for (int i = 0; i < m_; ++i) {
          if (c[i] == 0) continue;
          if (A(i, j) <= 0.0) return;  // impossible outcome
          lp += c[i] * loga(i) - std::lgamma(c[i] + 1.0);
        }
        const double p = std::exp(lp);
        if (p == 0.0) return;
        int64_t g = 0;
        for (int i = 0; i < m_ - 1; ++i) g += c[i] * radix_[i];
        list.emplace_back(g, p);
      });
    }
  }
}

void ExactBayesFilter::AccumulateRow(size_t k, const Eigen::MatrixXd& A, double weight,
                                     double* out) {
  // Convolve the m columns' multinomials one after another; scratch_ is a dense grid, zero
  // outside the entries touched by the current convolution.
  std::vector<std::pair<int64_t, double>> cur = {{0, 1.0}}, next;
  for (int j = 0; j < m_; ++j) {
    const int n = states_[k * m_ + j];
    if (n == 0) continue;
    const auto& mult = pmf_[j][n];
    next.clear();
    for (const auto& [iu, pu] : cur) {
      for (const auto& [iv, pv] : mult) {
        double& acc = scratch_[iu + iv];
        if (acc == 0.0) next.emplace_back(iu + iv, 0.0);
        acc += pu * pv;
      }
    }
    for (auto& [idx, p] : next) {
      p = scratch_[idx];
      scratch_[idx] = 0.0;
    }
    std::swap(cur, next);
  }
  for (const auto& [idx, p] : cur) out[grid_to_state_[idx]] += weight * p;
}

void ExactBayesFilter::Predict(const Eigen::MatrixXd& A) {
  const size_t S = p_.size();
  std::vector<double> out(S, 0.0);
  const uint64_t table_bytes = static_cast<uint64_t>(S) * S * sizeof(double);
  if (table_bytes <= options_.cache_bytes) {
    auto it =
        std::find_if(cache_.begin(), cache_.end(), [&](const CachedTable& c) { return c.A == A; });
    if (it == cache_.end()) {
      const size_t capacity = std::max<uint64_t>(1, options_.cache_bytes / table_bytes);
      while (cache_.size() >= capacity) cache_.pop_back();
      PrepareColumnPmfs(A);
      CachedTable t{A, std::vector<double>(S * S, 0.0)};
      for (size_t k = 0; k < S; ++k) AccumulateRow(k, A, 1.0, t.T.data() + k * S);
      cache_.push_front(std::move(t));
      it = cache_.begin();
    } else {
      cache_.splice(cache_.begin(), cache_, it);  // most recently used first
      it = cache_.begin();
    }
    const double* T = it->T.data();
    for (size_t k = 0; k < S; ++k) {
      const double w = p_[k];
      if (w == 0.0) continue;
      const double* row = T + k * S;
      for (size_t i = 0; i < S; ++i) out[i] += w * row[i];
    }
  } else {
    PrepareColumnPmfs(A);
    for (size_t k = 0; k < S; ++k) {
      if (p_[k] != 0.0) AccumulateRow(k, A, p_[k], out.data());
    }
  }
  p_ = std::move(out);
}

void ExactBayesFilter::Update(const Eigen::VectorXd& y) {
  const size_t S = p_.size();
  Eigen::MatrixXd D = (-HX_).colwise() + y;
  R_llt_.matrixL().solveInPlace(D);
  const Eigen::VectorXd loglik = -0.5 * D.colwise().squaredNorm().transpose();
  double best = -INFINITY;
  for (size_t k = 0; k < S; ++k) {
    if (p_[k] > 0.0) best = std::max(best, loglik(k));
  }
  double sum = 0.0;
  for (size_t k = 0; k < S; ++k) {
    if (p_[k] > 0.0) sum += p_[k] *= std::exp(loglik(k) - best);
  }
  for (double& p : p_) p /= sum;
}

Status ExactBayesFilter::SetProbabilities(const std::vector<double>& p) {
  if (p.size() != p_.size()) return Error{"exact filter: belief has the wrong size"};
  double sum = 0.0;
  for (double v : p) {
    if (!(v >= 0.0) || !std::isfinite(v)) return Error{"exact filter: negative or NaN belief"};
    sum += v;
  }
  if (std::abs(sum - 1.0) > 1e-9) return Error{"exact filter: belief does not sum to 1"};
  p_ = p;
  return Status::Ok();
}

Eigen::VectorXd ExactBayesFilter::Mean() const {
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(m_);
  for (size_t k = 0; k < p_.size(); ++k) {
    if (p_[k] == 0.0) continue;
    for (int i = 0; i < m_; ++i) mean(i) += p_[k] * states_[k * m_ + i];
  }
  return mean;
}

Eigen::MatrixXd ExactBayesFilter::Covariance() const {
  const Eigen::VectorXd mean = Mean();
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(m_, m_);
  for (size_t k = 0; k < p_.size(); ++k) {
    if (p_[k] == 0.0) continue;
    const Eigen::VectorXd d = State(k) - mean;
    C.noalias() += p_[k] * d * d.transpose();
  }
  return C;
}

}  // namespace recruit::estimation
