// Nelder-Mead minimisation for the few noise parameters identification fits by maximum
// likelihood, where the likelihood runs a filter over recordings and has no cheap gradient.
#pragma once

#include <Eigen/Core>
#include <functional>

namespace recruit::identification {

struct NelderMeadResult {
  Eigen::VectorXd x;  // the best vertex
  double value = 0;   // f there
  int evaluations = 0;
};

// Reflection 1, expansion 2, contraction 1/2, shrink 1/2, from the simplex {x0, x0 + step_i e_i}.
// Stops when the vertices' values agree within `tol` and the simplex is smaller than `size`
// (max-norm about the best vertex), or after `max_evals` evaluations.
NelderMeadResult NelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                            const Eigen::VectorXd& x0, const Eigen::VectorXd& step, double tol,
                            double size, int max_evals);

}  // namespace recruit::identification
