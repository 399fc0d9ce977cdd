// The recorded log that `recruit filter` runs an estimator over (docs/formats/filter.md), and
// the offline run itself.
//
// Row k holds the measurement y(k) of X(k) (empty cells: no measurement at step k) and the
// inputs that define A(k), the transition from X(k) to X(k+1): p_on, p_off for a broadcast
// model, A_i_j for an explicit one, none for a constant one. The inputs of the last row may be
// empty. The run: for k = 0, 1, ...: if k > 0 predict with A(k-1); if y(k) is given, update;
// write the estimate of X(k) and the diagonal of its covariance.
#pragma once

#include <Eigen/Dense>
#include <optional>
#include <string>
#include <vector>

#include "common/result.h"
#include "estimation/count_filter.h"
#include "estimation/filter_model.h"

namespace recruit {

struct FilterLog {
  bool has_time = false;
  std::vector<double> t;                          // the optional "t" column
  std::vector<std::optional<Eigen::MatrixXd>> A;  // A(k), validated; empty on the last row
  std::vector<std::optional<Eigen::VectorXd>> y;  // y(k), or none
  size_t num_steps() const { return y.size(); }
};

// Parses `text` (the contents of `path`, which only names it in messages) against the model:
// header, numbers, probabilities, column-stochastic A(k), measurements all-or-none per row.
Result<FilterLog> ParseFilterLog(const std::string& text, const FilterModel& model,
                                 const std::string& path);
Result<FilterLog> ReadFilterLog(const std::string& path, const FilterModel& model);

// Runs `filter` over the log; returns the output CSV text:
//   step[,t],updated,x_<state>...,var_<state>...
Result<std::string> RunFilterOverLog(const FilterModel& model, const FilterLog& log,
                                     CountFilter& filter);

}  // namespace recruit
