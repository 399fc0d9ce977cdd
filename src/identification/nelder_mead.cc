#include "identification/nelder_mead.h"

#include <algorithm>
#include <numeric>
#include <vector>

namespace recruit::identification {

NelderMeadResult NelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                            const Eigen::VectorXd& x0, const Eigen::VectorXd& step, double tol,
                            double size, int max_evals) {
  const int n = static_cast<int>(x0.size());
  std::vector<Eigen::VectorXd> v(n + 1, x0);
  std::vector<double> fv(n + 1);
  for (int i = 0; i < n; ++i) v[i + 1][i] += step[i];
  int evals = 0;
  auto eval = [&](const Eigen::VectorXd& x) {
    ++evals;
    return f(x);
  };
  for (int i = 0; i <= n; ++i) fv[i] = eval(v[i]);
  std::vector<int> o(n + 1);
  while (evals < max_evals) {
    std::iota(o.begin(), o.end(), 0);
    std::sort(o.begin(), o.end(), [&](int a, int b) { return fv[a] < fv[b]; });
    const int best = o[0], worst = o[n], second = o[n - 1];
    double spread = 0;
    for (int i = 1; i <= n; ++i) {
      spread = std::max(spread, (v[o[i]] - v[best]).cwiseAbs().maxCoeff());
    }
    if (fv[worst] - fv[best] < tol && spread < size) break;
    Eigen::VectorXd centre = Eigen::VectorXd::Zero(n);
    for (int i = 0; i < n; ++i) centre += v[o[i]];
    centre /= n;
    const Eigen::VectorXd r = centre + (centre - v[worst]);
    const double fr = eval(r);
    if (fr < fv[best]) {
      const Eigen::VectorXd e = centre + 2 * (centre - v[worst]);
      const double fe = eval(e);
      v[worst] = fe < fr ? e : r;
      fv[worst] = std::min(fe, fr);
    } else if (fr < fv[second]) {
      v[worst] = r, fv[worst] = fr;
    } else {
      const bool outside = fr < fv[worst];
      const Eigen::VectorXd c = outside ? Eigen::VectorXd(centre + 0.5 * (r - centre))
                                        : Eigen::VectorXd(centre + 0.5 * (v[worst] - centre));
      const double fc = eval(c);
      if (fc < std::min(fr, fv[worst])) {
        v[worst] = c, fv[worst] = fc;
      } else {
        for (int i = 1; i <= n; ++i) {
          v[o[i]] = v[best] + 0.5 * (v[o[i]] - v[best]);
          fv[o[i]] = eval(v[o[i]]);
        }
      }
    }
  }
  const int best = static_cast<int>(std::min_element(fv.begin(), fv.end()) - fv.begin());
  return {v[best], fv[best], evals};
}

}  // namespace recruit::identification
