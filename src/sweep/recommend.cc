#include "sweep/recommend.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace recruit::sweep {

std::vector<Recommendation> Recommend(const std::vector<sweep::CellStats>& cells) {
  std::vector<Recommendation> out;
  std::vector<std::tuple<int, std::string, double>> order;
  for (const auto& c : cells) {
    auto key = std::make_tuple(c.plant, c.estimator, c.lambda);
    if (std::find(order.begin(), order.end(), key) == order.end()) order.push_back(key);
  }
  for (const auto& [plant, est, lambda] : order) {
    std::vector<const sweep::CellStats*> col;
    for (const auto& c : cells) {
      if (c.plant == plant && c.estimator == est && c.lambda == lambda) col.push_back(&c);
    }
    std::sort(col.begin(), col.end(), [](auto* a, auto* b) { return a->dT < b->dT; });
    Recommendation r;
    r.plant = plant;
    r.plant_values = col.front()->plant_values;
    r.estimator = est;
    r.lambda = lambda;
    r.critical_dT = std::nan("");
    for (size_t i = 0; i < col.size() && !r.found; ++i) {
      if (!col[i]->meets) continue;
      const sweep::CellStats& c = *col[i];
      r.found = true;
      r.dT = c.dT;
      r.margin = c.margin;
      r.margin_se = c.margin_se;
      // One seed has no spread to judge by: no confidence then.
      r.confidence = c.seeds < 2       ? std::nan("")
                     : c.margin_se > 0 ? 0.5 * std::erfc(-c.margin / (c.margin_se * std::sqrt(2.0)))
                                       : (c.margin >= 0 ? 1.0 : 0.0);
      r.seeds_meeting = c.seeds_meeting;
      r.seeds = c.seeds;
      if (i == 0) {
        r.critical_dT = c.dT;
        r.censored = true;
      } else if (col[i - 1]->margin >= 0) {
        r.critical_dT = c.dT;  // the shorter dT failed on its wires' limits, not the criterion
      } else {
        const sweep::CellStats& p = *col[i - 1];
        const double f = (0 - p.margin) / (c.margin - p.margin);  // p.margin < 0 <= c.margin
        r.critical_dT = std::exp(std::log(p.dT) + f * (std::log(c.dT) - std::log(p.dT)));
      }
    }
    out.push_back(r);
  }
  return out;
}

std::vector<Sensitivity> Sensitivities(const std::vector<Recommendation>& recs) {
  std::vector<Sensitivity> out;
  if (recs.empty() || recs.front().plant_values.empty()) return out;
  const size_t naxes = recs.front().plant_values.size();
  std::vector<std::pair<std::string, double>> groups;
  for (const auto& r : recs) {
    auto key = std::make_pair(r.estimator, r.lambda);
    if (std::find(groups.begin(), groups.end(), key) == groups.end()) groups.push_back(key);
  }
  for (const auto& [est, lambda] : groups) {
    std::vector<const Recommendation*> pts;
    std::vector<bool> positive(naxes, true);
    for (const auto& r : recs) {
      if (r.estimator != est || r.lambda != lambda) continue;
      for (size_t k = 0; k < naxes; ++k) positive[k] = positive[k] && r.plant_values[k].second > 0;
      if (r.found && !r.censored) pts.push_back(&r);
    }
    // Axes that vary among the fitted points; the fit is ln dT* = b0 + sum_k b_k t_k.
    auto t_of = [&](const Recommendation* r, size_t k) {
      const double x = r->plant_values[k].second;
      return positive[k] ? std::log(x) : x;
    };
    std::vector<size_t> varying;
    std::vector<double> span(naxes, 0);
    for (size_t k = 0; k < naxes && !pts.empty(); ++k) {
      double lo = t_of(pts[0], k), hi = lo;
      for (auto* r : pts) {
        lo = std::min(lo, t_of(r, k));
        hi = std::max(hi, t_of(r, k));
      }
      span[k] = hi - lo;
      if (span[k] > 0) varying.push_back(k);
    }
    std::vector<Sensitivity> rows(naxes);
    for (size_t k = 0; k < naxes; ++k) {
      rows[k].estimator = est;
      rows[k].lambda = lambda;
      rows[k].axis = recs.front().plant_values[k].first;
      rows[k].log_axis = positive[k];
      rows[k].points = static_cast<int>(pts.size());
    }
    if (!varying.empty() && pts.size() > varying.size()) {
      Eigen::MatrixXd A(pts.size(), varying.size() + 1);
      Eigen::VectorXd y(pts.size());
      for (size_t i = 0; i < pts.size(); ++i) {
        A(i, 0) = 1;
        for (size_t j = 0; j < varying.size(); ++j) A(i, j + 1) = t_of(pts[i], varying[j]);
        y(i) = std::log(pts[i]->critical_dT);
      }
      const Eigen::VectorXd b = A.colPivHouseholderQr().solve(y);
      for (size_t j = 0; j < varying.size(); ++j) {
        Sensitivity& s = rows[varying[j]];
        s.slope = b(j + 1);
        s.effect = std::exp(std::abs(s.slope) * span[varying[j]]);
        s.fitted = true;
      }
    }
    std::stable_sort(rows.begin(), rows.end(), [](const Sensitivity& a, const Sensitivity& b) {
      return (a.fitted ? a.effect : 0) > (b.fitted ? b.effect : 0);
    });
    out.insert(out.end(), rows.begin(), rows.end());
  }
  return out;
}

}  // namespace recruit::sweep
