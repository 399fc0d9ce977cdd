#include "control/transient_chain.h"

#include <algorithm>

namespace recruit::control {

TransientChain TransientChain::Uniform(int num_states, double advance) {
  TransientChain c;
  c.chain_length = num_states / 2 - 1;
  c.heat_advance = Eigen::VectorXd::Constant(c.chain_length, advance);
  c.cool_advance = Eigen::VectorXd::Constant(c.chain_length, advance);
  c.force = Eigen::VectorXd::Zero(c.num_states());
  return c;
}

std::vector<std::string> TransientChain::StateNames() const {
  std::vector<std::string> names(num_states());
  names[cold()] = "cold";
  names[hot()] = "hot";
  for (int i = 1; i <= chain_length; ++i) {
    names[heat(i)] = "heat" + std::to_string(i);
    names[cool(i)] = "cool" + std::to_string(i);
  }
  return names;
}

std::vector<bool> TransientChain::IsOn() const {
  std::vector<bool> on(num_states(), false);
  for (int s = heat(1); s <= hot(); ++s) on[s] = true;
  return on;
}

int TransientChain::Level(int s) const {
  if (s == cold()) return 0;
  if (s <= hot()) return s;  // heat<i> = i, hot = K + 1
  return chain_length + 1 - (s - hot());
}

std::vector<int> TransientChain::OnTarget() const {
  const int m = num_states();
  const auto on = IsOn();
  std::vector<int> t(m);
  for (int s = 0; s < m; ++s) {
    if (on[s]) {
      t[s] = s;
      continue;
    }
    const int level = std::min(Level(s) + 1, chain_length + 1);
    t[s] = level == chain_length + 1 ? hot() : heat(level);
  }
  return t;
}

std::vector<int> TransientChain::OffTarget() const {
  const int m = num_states();
  const auto on = IsOn();
  std::vector<int> t(m);
  for (int s = 0; s < m; ++s) {
    if (!on[s]) {
      t[s] = s;
      continue;
    }
    const int level = std::max(Level(s) - 1, 0);
    t[s] = level == 0 ? cold() : cool(chain_length + 1 - level);
  }
  return t;
}

Eigen::MatrixXd TransientChain::Interior() const {
  const int m = num_states();
  Eigen::MatrixXd a = Eigen::MatrixXd::Identity(m, m);
  for (int i = 1; i <= chain_length; ++i) {
    const int h = heat(i), hn = i == chain_length ? hot() : heat(i + 1);
    a(h, h) = 1 - heat_advance[i - 1];
    a(hn, h) += heat_advance[i - 1];
    const int c = cool(i), cn = i == chain_length ? cold() : cool(i + 1);
    a(c, c) = 1 - cool_advance[i - 1];
    a(cn, c) += cool_advance[i - 1];
  }
  return a;
}

Eigen::MatrixXd TransientChain::Matrix(double p_on, double p_off) const {
  Eigen::MatrixXd a = Interior();
  const auto on = IsOn();
  const auto ton = OnTarget(), toff = OffTarget();
  for (int j = 0; j < num_states(); ++j) {
    const double p = on[j] ? p_off : p_on;
    a.col(j) *= 1 - p;
    a(on[j] ? toff[j] : ton[j], j) += p;
  }
  return a;
}

void TransientChain::PropagateMean(double p_on, double p_off, Eigen::VectorXd& x) const {
  const int K = chain_length;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(num_states());
  // Switching: an off state's units move with p_on, an on state's with p_off.
  // Off states: cold (level 0) -> heat1; cool<i> (level K + 1 - i) -> heat<K + 2 - i> or hot.
  y[heat(1)] += p_on * x[cold()];
  y[cold()] += (1 - p_on) * x[cold()];
  for (int i = 1; i <= K; ++i) {
    const int to = i == 1 ? hot() : heat(K + 2 - i);
    y[to] += p_on * x[cool(i)];
  }
  // On states: heat<i> (level i) -> cool<K + 2 - i> or cold; hot (level K + 1) -> cool1.
  for (int i = 1; i <= K; ++i) {
    const int to = i == 1 ? cold() : cool(K + 2 - i);
    y[to] += p_off * x[heat(i)];
  }
  y[cool(1)] += p_off * x[hot()];
  y[hot()] += (1 - p_off) * x[hot()];
  // Interior moves of the units that did not switch.
  for (int i = 1; i <= K; ++i) {
    const double h = (1 - p_off) * x[heat(i)];
    const double a = heat_advance[i - 1];
    y[heat(i)] += (1 - a) * h;
    y[i == K ? hot() : heat(i + 1)] += a * h;
    const double c = (1 - p_on) * x[cool(i)];
    const double b = cool_advance[i - 1];
    y[cool(i)] += (1 - b) * c;
    y[i == K ? cold() : cool(i + 1)] += b * c;
  }
  x = y;
}

Eigen::MatrixXd TransientChain::TransitionCovariance(double p_on, double p_off,
                                                     const Eigen::VectorXd& x) const {
  const Eigen::MatrixXd a = Matrix(p_on, p_off);
  Eigen::MatrixXd q = -a * x.asDiagonal() * a.transpose();
  q.diagonal() += a * x;
  return q;
}

}  // namespace recruit::control
