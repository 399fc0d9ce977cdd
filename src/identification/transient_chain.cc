#include "identification/transient_chain.h"

#include <algorithm>

namespace recruit::identification {

TransientChain TransientChain::Uniform(int num_states, double advance) {
  TransientChain c;
  c.chain_length = num_states / 2 - 1;
  c.heat_advance = Eigen::VectorXd::Constant(c.chain_length, advance);
  c.cool_advance = Eigen::VectorXd::Constant(c.chain_length, advance);
  c.force = Eigen::VectorXd::Zero(c.num_states());
  c.switch_on = c.LevelOnTarget();
  c.switch_off = c.LevelOffTarget();
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

int TransientChain::Next(int s) const {
  if (s == cold() || s == hot()) return -1;
  if (s < hot()) return s == heat(chain_length) ? hot() : s + 1;
  return s == cool(chain_length) ? cold() : s + 1;
}

std::vector<int> TransientChain::LevelOnTarget() const {
  const int m = num_states();
  const auto on = IsOn();
  std::vector<int> t(m, -1);
  for (int s = 0; s < m; ++s) {
    if (on[s]) continue;
    const int level = std::min(Level(s) + 1, chain_length + 1);
    t[s] = level == chain_length + 1 ? hot() : heat(level);
  }
  return t;
}

std::vector<int> TransientChain::LevelOffTarget() const {
  const int m = num_states();
  const auto on = IsOn();
  std::vector<int> t(m, -1);
  for (int s = 0; s < m; ++s) {
    if (!on[s]) continue;
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
  for (int j = 0; j < num_states(); ++j) {
    const double p = on[j] ? p_off : p_on;
    a.col(j) *= 1 - p;
    a(on[j] ? switch_off[j] : switch_on[j], j) += p;
  }
  return a;
}

void TransientChain::PropagateMean(double p_on, double p_off, Eigen::VectorXd& x) const {
  const int m = num_states();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(m);
  for (int s = 0; s < m; ++s) {
    const bool on = s >= heat(1) && s <= hot();
    const double p = on ? p_off : p_on;
    y[on ? switch_off[s] : switch_on[s]] += p * x[s];
    const double stay = (1 - p) * x[s];  // units the broadcast did not switch
    const int next = Next(s);
    if (next < 0) {
      y[s] += stay;
    } else {
      const double a = s < hot() ? heat_advance[s - 1] : cool_advance[s - hot() - 1];
      y[s] += (1 - a) * stay;
      y[next] += a * stay;
    }
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

}  // namespace recruit::identification
