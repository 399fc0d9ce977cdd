#include "estimation/population_chain.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

namespace recruit::estimation {
namespace {

std::string Num(double v) {
  std::ostringstream s;
  s.precision(6);  // enough to name the value; 1.0499999999999998 reads as 1.05
  s << v;
  return s.str();
}

}  // namespace

Status ValidateColumnStochastic(const Eigen::MatrixXd& A, double tol, int expected_m,
                                const std::string& what) {
  if (A.rows() != A.cols()) {
    return Error{what + ": must be square (m x m), got " + std::to_string(A.rows()) + " x " +
                 std::to_string(A.cols())};
  }
  if (expected_m >= 0 && A.rows() != expected_m) {
    return Error{what + ": must be " + std::to_string(expected_m) + " x " +
                 std::to_string(expected_m) + " (one row and column per state), got " +
                 std::to_string(A.rows()) + " x " + std::to_string(A.cols())};
  }
  if (A.rows() == 0) return Error{what + ": is empty"};
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < A.rows(); ++i) {
      const double a = A(i, j);
      if (!std::isfinite(a)) {
        return Error{what + ": entry (" + std::to_string(i) + ", " + std::to_string(j) +
                     ") is not finite (" + Num(a) + ")"};
      }
      if (a < -tol || a > 1.0 + tol) {
        return Error{what + ": entry (" + std::to_string(i) + ", " + std::to_string(j) +
                     ") = " + Num(a) + " is outside [0, 1] (tolerance " + Num(tol) +
                     "); A_ij is the probability of moving from state j to state i"};
      }
      sum += a;
    }
    if (std::abs(sum - 1.0) > tol) {
      return Error{what + ": column " + std::to_string(j) + " sums to " + Num(sum) +
                   ", not 1 (tolerance " + Num(tol) +
                   "); A must be column-stochastic, A_ij = Pr(next = i | now = j)"};
    }
  }
  return Status::Ok();
}

Status ValidateCounts(const Eigen::VectorXd& x, int m, int64_t N, const std::string& what) {
  if (x.size() != m) {
    return Error{what + ": must have " + std::to_string(m) + " entries (one per state), got " +
                 std::to_string(x.size())};
  }
  double sum = 0.0;
  for (int i = 0; i < m; ++i) {
    const double v = x(i);
    if (!std::isfinite(v)) return Error{what + ": entry " + std::to_string(i) + " is not finite"};
    if (v < 0) {
      return Error{what + ": entry " + std::to_string(i) + " = " + Num(v) +
                   " is negative; counts must be >= 0"};
    }
    if (v != std::floor(v)) {
      return Error{what + ": entry " + std::to_string(i) + " = " + Num(v) +
                   " is not an integer count"};
    }
    sum += v;
  }
  if (sum != static_cast<double>(N)) {
    return Error{what + ": counts sum to " + Num(sum) + ", not N = " + std::to_string(N)};
  }
  return Status::Ok();
}

int64_t SampleBinomial(int64_t n, double p, Rng& rng) {
  if (n <= 0 || p <= 0.0) return 0;
  if (p >= 1.0) return n;
  const bool flip = p > 0.5;
  const double q = flip ? 1.0 - p : p;
  int64_t k;
  if (static_cast<double>(n) * q < 15.0) {
    // Inversion by the pmf recurrence f(k+1) = f(k) (n - k) / (k + 1) * q / (1 - q).
    const double r = q / (1.0 - q);
    double f = std::exp(static_cast<double>(n) * std::log1p(-q));
    double u = rng.Uniform();
    k = 0;
    while (u > f && k < n) {
      u -= f;
      f *= r * static_cast<double>(n - k) / static_cast<double>(k + 1);
      ++k;
    }
  } else {
    std::binomial_distribution<int64_t> d(n, q);
    k = d(rng);
  }
  return flip ? n - k : k;
}

void SampleMultinomial(int64_t n, const double* p, int m, Rng& rng, int64_t* out) {
  double rest = 1.0;
  for (int i = 0; i < m - 1; ++i) {
    int64_t c = 0;
    if (n > 0 && rest > 0.0) {
      const double q = std::clamp(p[i] / rest, 0.0, 1.0);
      c = SampleBinomial(n, q, rng);
    }
    out[i] = c;
    n -= c;
    rest -= p[i];
  }
  out[m - 1] = n;
}

Eigen::VectorXd SimulateStepAggregate(const Eigen::MatrixXd& A, const Eigen::VectorXd& x,
                                      Rng& rng) {
  const int m = static_cast<int>(A.rows());
  Eigen::VectorXd next = Eigen::VectorXd::Zero(m);
  std::vector<int64_t> c(m);
  for (int j = 0; j < m; ++j) {
    const auto nj = static_cast<int64_t>(std::llround(x(j)));
    if (nj == 0) continue;
    SampleMultinomial(nj, A.col(j).data(), m, rng, c.data());
    for (int i = 0; i < m; ++i) next(i) += static_cast<double>(c[i]);
  }
  return next;
}

Eigen::VectorXd SimulateStepAgents(const Eigen::MatrixXd& A, std::vector<int>& states, Rng& rng) {
  const int m = static_cast<int>(A.rows());
  for (int& s : states) {
    const double u = rng.Uniform();
    double cdf = 0.0;
    int i = 0;
    for (; i < m - 1; ++i) {
      cdf += A(i, s);
      if (u < cdf) break;
    }
    s = i;
  }
  return CountStates(states, m);
}

Eigen::VectorXd CountStates(const std::vector<int>& states, int m) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(m);
  for (int s : states) x(s) += 1.0;
  return x;
}

Eigen::MatrixXd ProcessCovarianceQz(const Eigen::MatrixXd& A, const Eigen::VectorXd& x) {
  Eigen::MatrixXd Q = -(A * x.asDiagonal() * A.transpose());
  Q.diagonal() += A * x;
  return Q;
}

Eigen::MatrixXd ConservativeQz(const Eigen::MatrixXd& A, double N) {
  return ProcessCovarianceQz(A, Eigen::VectorXd::Constant(A.cols(), N));
}

Eigen::VectorXd ProjectOntoSimplex(const Eigen::VectorXd& x, double N) {
  const Eigen::Index m = x.size();
  // Fast path: already feasible.
  if ((x.array() >= 0.0).all() && std::abs(x.sum() - N) <= 1e-12 * std::abs(N)) return x;
  std::vector<double> u(x.data(), x.data() + m);
  std::sort(u.begin(), u.end(), std::greater<double>());
  double cumsum = 0.0, theta = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) {
    cumsum += u[k];
    const double t = (cumsum - N) / static_cast<double>(k + 1);
    if (u[k] - t > 0.0) theta = t;
  }
  return (x.array() - theta).max(0.0).matrix();
}

Result<Eigen::VectorXd> StationaryDistribution(const Eigen::MatrixXd& A) {
  if (Status s = ValidateColumnStochastic(A); !s.ok()) return Error{s.error(), s.code()};
  const Eigen::Index m = A.rows();
  Eigen::MatrixXd M = A - Eigen::MatrixXd::Identity(m, m);
  M.row(m - 1).setOnes();
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m);
  b(m - 1) = 1.0;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(M);
  if (!lu.isInvertible()) {
    return Error{"stationary distribution: not unique (the chain is reducible)"};
  }
  Eigen::VectorXd pi = lu.solve(b);
  if ((pi.array() < -1e-12).any()) {
    return Error{"stationary distribution: negative entries (chain not irreducible)"};
  }
  return Eigen::VectorXd(pi.cwiseMax(0.0));
}

Eigen::MatrixXd EquilibriumCovariance(const Eigen::VectorXd& pi, double N) {
  Eigen::MatrixXd C = -N * pi * pi.transpose();
  C.diagonal() += N * pi;
  return C;
}

Result<GammaBound> ComputeGammaBound(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Qmax) {
  if (Status s = ValidateColumnStochastic(A); !s.ok()) return Error{s.error(), s.code()};
  const Eigen::Index m = A.rows();
  Eigen::EigenSolver<Eigen::MatrixXd> es(A.transpose());
  if (es.info() != Eigen::Success) return Error{"Gamma bound: eigen-decomposition failed"};
  const Eigen::VectorXcd ev = es.eigenvalues();
  const Eigen::MatrixXcd evec = es.eigenvectors();
  if (ev.imag().cwiseAbs().maxCoeff() > 1e-12 || evec.imag().cwiseAbs().maxCoeff() > 1e-12) {
    return Error{
        "Gamma bound: A has complex eigenvalues; the eq. 36 bound here needs a real "
        "spectrum"};
  }
  std::vector<Eigen::Index> order(m);
  for (Eigen::Index i = 0; i < m; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](Eigen::Index a, Eigen::Index b) {
    return std::abs(ev(a).real()) > std::abs(ev(b).real());
  });
  GammaBound g;
  g.lambda.resize(m);
  g.V.resize(m, m);
  for (Eigen::Index k = 0; k < m; ++k) {
    g.lambda(k) = ev(order[k]).real();
    g.V.col(k) = evec.col(order[k]).real();
  }
  if (std::abs(g.lambda(0) - 1.0) > 1e-9) {
    return Error{"Gamma bound: the largest eigenvalue is not 1"};
  }
  g.V.col(0).setOnes();  // the left eigenvector of eigenvalue 1 is the all-ones vector
  for (Eigen::Index k = 1; k < m; ++k) {
    if (std::abs(g.lambda(k)) >= 1.0 - 1e-12) {
      return Error{"Gamma bound: a second eigenvalue has modulus 1 (periodic or reducible chain)"};
    }
  }
  const Eigen::MatrixXd VQV = g.V.transpose() * Qmax * g.V;
  g.bound.resize(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    for (Eigen::Index j = 0; j < m; ++j) {
      g.bound(i, j) = (i == 0 && j == 0) ? 0.0
                                         : std::sqrt(std::max(0.0, VQV(i, i) * VQV(j, j))) /
                                               (1.0 - std::abs(g.lambda(i) * g.lambda(j)));
    }
  }
  return g;
}

uint64_t CountStateVectors(int64_t N, int m, uint64_t cap) {
  // C(N + m - 1, m - 1) = prod_{k=1}^{m-1} (N + k) / k, exact at every step.
  unsigned __int128 c = 1;
  for (int k = 1; k <= m - 1; ++k) {
    c = c * static_cast<unsigned __int128>(N + k) / static_cast<unsigned __int128>(k);
    if (c > cap) return cap + 1;
  }
  return static_cast<uint64_t>(c);
}

}  // namespace recruit::estimation
