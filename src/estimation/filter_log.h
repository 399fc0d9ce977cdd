// The recorded log that `recruit filter` runs an estimator over (docs/formats/filter.md), and
// the offline run itself, streamed: rows are parsed, stepped and written one at a time, so
// memory stays flat in the number of rows.
//
// Row k holds the measurement y(k) of X(k) (empty cells: no measurement at step k) and the
// inputs that define A(k), the transition from X(k) to X(k+1): p_on, p_off for a broadcast
// model, A_i_j for an explicit one, none for a constant one. The inputs of the last row may be
// empty. The run: for k = 0, 1, ...: if k > 0 predict with A(k-1); if y(k) is given, update;
// write the estimate of X(k) and the diagonal of its covariance.
#pragma once

#include <Eigen/Dense>
#include <cstdio>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "common/result.h"
#include "estimation/count_filter.h"
#include "estimation/filter_model.h"

namespace recruit::estimation {

// One data row of a log, validated against the model.
struct FilterLogRow {
  int line = 0;                    // line number in the file
  double t = 0.0;                  // the optional "t" column
  bool has_y = false;              // a measurement is given
  Eigen::VectorXd y;               // r entries when has_y
  bool has_inputs = false;         // the inputs of A(k) are given (always for a constant model)
  double p_on = 0.0, p_off = 0.0;  // broadcast models
  Eigen::MatrixXd A;               // explicit models: A(k), column-stochastic
};

// Reads a log row by row from a file or an in-memory text: the header first (Open), then
// Next until it returns false. A UTF-8 byte-order mark before the header is skipped.
// A bench log (estimation/bench_log.h: `time`, `<bundle>.sensed_force`, ...) is read too, for a
// broadcast model with one output: its control instants are the steps, `time` is t, the bundle's
// p_on, p_off the inputs and its sensed_force y; other columns are ignored. `bundle` names the
// bundle (empty: the log's only one).
class FilterLogReader {
 public:
  static Result<std::unique_ptr<FilterLogReader>> OpenFile(const std::string& path,
                                                           const FilterModel& model,
                                                           const std::string& bundle = "");
  // `text` must outlive the reader; `path` only names it in messages.
  static Result<std::unique_ptr<FilterLogReader>> OpenText(const std::string& text,
                                                           const FilterModel& model,
                                                           const std::string& path,
                                                           const std::string& bundle = "");
  ~FilterLogReader();
  FilterLogReader(const FilterLogReader&) = delete;
  FilterLogReader& operator=(const FilterLogReader&) = delete;

  // The next data row into `row` (its vectors are reused: no allocation per row); false at the
  // end of the log; an error naming the file, line, column and the value (shortened).
  Result<bool> Next(FilterLogRow& row);
  bool has_time() const { return t_col_ >= 0; }
  const std::string& path() const { return path_; }

 private:
  FilterLogReader() = default;
  Status ReadHeader();
  Status ReadBenchHeader();  // the cells_ of a bench log's header
  // The next line without its end-of-line; false at the end of the input.
  bool NextLine(std::string_view* line);
  bool Refill();

  const FilterModel* model_ = nullptr;
  std::string path_;
  std::FILE* file_ = nullptr;
  std::string buf_;        // file mode: a window of the file
  std::string_view text_;  // the unread part of the buffer or text
  bool eof_ = false;
  int line_no_ = 0;
  // Column indices.
  size_t num_cols_ = 0;
  int t_col_ = -1;
  std::vector<int> y_cols_, input_cols_;
  std::vector<std::string> names_;  // by column
  std::vector<std::string_view> cells_;
  bool bench_ = false;    // a bench log
  int instant_col_ = -1;  // its control_instant column
  std::string bundle_;    // its bundle (empty: the only one)
  bool last_without_inputs_ = false;
  int last_data_line_ = 0;
};

// Runs `filter` over the log and writes the output CSV to `out` row by row:
//   step[,t],updated,x_<state>...,var_<state>...
// numbers in the shortest form that reads back to the same double (std::to_chars).
Status RunFilterStream(const FilterModel& model, FilterLogReader& log, CountFilter& filter,
                       std::ostream& out);

// The same over an in-memory log; returns the output CSV text.
Result<std::string> RunFilterOverText(const FilterModel& model, const std::string& text,
                                      const std::string& path, CountFilter& filter);

}  // namespace recruit::estimation
