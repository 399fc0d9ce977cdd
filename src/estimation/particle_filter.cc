#include "estimation/particle_filter.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "estimation/population_chain.h"

namespace recruit::estimation {

Eigen::VectorXd RoundToCounts(const Eigen::VectorXd& x, int64_t N) {
  const Eigen::VectorXd p = ProjectOntoSimplex(x, static_cast<double>(N));
  Eigen::VectorXd c = p.array().floor();
  int64_t missing = N - static_cast<int64_t>(std::llround(c.sum()));
  std::vector<int> order(p.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return p(a) - c(a) > p(b) - c(b); });
  for (int k = 0; missing > 0; k = (k + 1) % static_cast<int>(order.size()), --missing) {
    c(order[k]) += 1.0;
  }
  return c;
}

Result<ParticleFilter> ParticleFilter::Create(const FilterModel& model,
                                              const ParticleFilterOptions& options, Rng& rng) {
  if (Status s = model.Validate(); !s.ok()) return Error{s.error(), s.code()};
  if (options.num_particles < 1) return Error{"particle filter: needs at least one particle"};
  if (!(options.resample_threshold >= 0.0 && options.resample_threshold <= 1.0)) {
    return Error{"particle filter: resample_threshold must be in [0, 1]"};
  }
  if (model.G.cols() > 0 && model.ProcessNoise().cwiseAbs().maxCoeff() > 0.0) {
    return Error{
        "particle filter: the model has process noise (G, Qw), which the count-vector "
        "particles do not model"};
  }
  ParticleFilter f;
  f.m_ = model.num_states();
  f.N_ = model.N;
  f.H_ = model.H;
  f.R_llt_.compute(model.R);
  f.options_ = options;
  const int np = options.num_particles;
  const int m = f.m_;
  f.counts_.resize(static_cast<size_t>(np) * m);
  f.next_.resize(f.counts_.size());
  f.weights_.assign(np, 1.0 / np);
  f.logw_.resize(np);
  f.draw_.resize(m);
  const bool point = model.P0.cwiseAbs().maxCoeff() == 0.0;
  if (point && (model.x0.array().round() - model.x0.array()).abs().maxCoeff() > 1e-9) {
    return Error{"particle filter: with P0 = 0 the initial state x0 must be integer counts"};
  }
  Eigen::MatrixXd L = Eigen::MatrixXd::Zero(m, m);
  if (!point) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(model.P0);
    L = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  }
  for (int k = 0; k < np; ++k) {
    Eigen::VectorXd x = model.x0;
    if (!point) {
      Eigen::VectorXd g(m);
      for (int i = 0; i < m; ++i) {
        g(i) = rng.Gaussian();
      }
      x += L * g;
    }
    const Eigen::VectorXd c = RoundToCounts(x, f.N_);
    for (int i = 0; i < m; ++i) f.counts_[static_cast<size_t>(k) * m + i] = std::llround(c(i));
  }
  return f;
}

void ParticleFilter::Predict(const Eigen::MatrixXd& A, Rng& rng) {
  const int m = m_;
  const size_t np = weights_.size();
  std::fill(next_.begin(), next_.end(), 0);
  for (size_t k = 0; k < np; ++k) {
    const int64_t* x = &counts_[k * m];
    int64_t* out = &next_[k * m];
    for (int j = 0; j < m; ++j) {
      if (x[j] == 0) continue;
      SampleMultinomial(x[j], A.col(j).data(), m, rng, draw_.data());
      for (int i = 0; i < m; ++i) out[i] += draw_[i];
    }
  }
  std::swap(counts_, next_);
}

void ParticleFilter::Update(const Eigen::VectorXd& y, Rng& rng) {
  const int m = m_;
  const size_t np = weights_.size();
  const Eigen::Index r = H_.rows();
  Eigen::VectorXd x(m), d(r);
  double best = -INFINITY;
  for (size_t k = 0; k < np; ++k) {
    for (int i = 0; i < m; ++i) x(i) = static_cast<double>(counts_[k * m + i]);
    d.noalias() = y - H_ * x;
    R_llt_.matrixL().solveInPlace(d);
    logw_[k] = std::log(weights_[k]) - 0.5 * d.squaredNorm();
    best = std::max(best, logw_[k]);
  }
  double sum = 0.0;
  for (size_t k = 0; k < np; ++k) sum += weights_[k] = std::exp(logw_[k] - best);
  for (double& w : weights_) w /= sum;
  if (EffectiveSampleSize() < options_.resample_threshold * static_cast<double>(np)) {
    Resample(rng);
  }
}

void ParticleFilter::Resample(Rng& rng) {
  // Systematic resampling: one uniform, np evenly spaced pointers into the weights' CDF.
  const int m = m_;
  const size_t np = weights_.size();
  const double step = 1.0 / static_cast<double>(np);
  double u = rng.Uniform() * step;
  double cdf = weights_[0];
  size_t src = 0;
  for (size_t k = 0; k < np; ++k) {
    while (u > cdf && src + 1 < np) cdf += weights_[++src];
    std::copy_n(&counts_[src * m], m, &next_[k * m]);
    u += step;
  }
  std::swap(counts_, next_);
  std::fill(weights_.begin(), weights_.end(), step);
}

double ParticleFilter::EffectiveSampleSize() const {
  double s2 = 0.0;
  for (double w : weights_) s2 += w * w;
  return 1.0 / s2;
}

Eigen::VectorXd ParticleFilter::Particle(int k) const {
  Eigen::VectorXd x(m_);
  for (int i = 0; i < m_; ++i) x(i) = static_cast<double>(counts_[static_cast<size_t>(k) * m_ + i]);
  return x;
}

Eigen::VectorXd ParticleFilter::Mean() const {
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(m_);
  for (size_t k = 0; k < weights_.size(); ++k) {
    for (int i = 0; i < m_; ++i) mean(i) += weights_[k] * static_cast<double>(counts_[k * m_ + i]);
  }
  return mean;
}

Eigen::MatrixXd ParticleFilter::Covariance() const {
  const Eigen::VectorXd mean = Mean();
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(m_, m_);
  for (size_t k = 0; k < weights_.size(); ++k) {
    const Eigen::VectorXd d = Particle(static_cast<int>(k)) - mean;
    C.noalias() += weights_[k] * d * d.transpose();
  }
  return C;
}

}  // namespace recruit::estimation
