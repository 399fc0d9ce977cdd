#include "estimation/filter_log.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>

#include "common/short_text.h"
#include "estimation/bench_log.h"
#include "estimation/json_matrix.h"
#include "estimation/population_chain.h"
#include "estimation/shortest_double.h"

namespace recruit::estimation {
namespace {

constexpr size_t kChunk = size_t{1} << 20;  // bytes read and written at a time

std::string_view Trim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Cells of a CSV line, trimmed; "a,,b" has 3 cells and a trailing comma an empty last cell.
void SplitCsv(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t start = 0;
  for (;;) {
    const size_t c = line.find(',', start);
    out.push_back(Trim(line.substr(start, c == std::string_view::npos ? c : c - start)));
    if (c == std::string_view::npos) break;
    start = c + 1;
  }
}

// A strict number: the whole cell, finite (an optional leading '+' is accepted, as strtod did).
bool ParseNumber(std::string_view s, double* v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(*v);
}

}  // namespace

FilterLogReader::~FilterLogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

Result<std::unique_ptr<FilterLogReader>> FilterLogReader::OpenFile(const std::string& path,
                                                                   const FilterModel& model,
                                                                   const std::string& bundle) {
  std::unique_ptr<FilterLogReader> r(new FilterLogReader);
  r->model_ = &model;
  r->bundle_ = bundle;
  r->path_ = path;
  r->file_ = std::fopen(path.c_str(), "rb");
  if (r->file_ == nullptr)
    return Error{"cannot open '" + path + "': " + std::strerror(errno), ErrorCode::kIo};
  r->buf_.resize(kChunk);
  if (Status s = r->ReadHeader(); !s.ok()) return Error{s.error(), s.code()};
  return r;
}

Result<std::unique_ptr<FilterLogReader>> FilterLogReader::OpenText(const std::string& text,
                                                                   const FilterModel& model,
                                                                   const std::string& path,
                                                                   const std::string& bundle) {
  std::unique_ptr<FilterLogReader> r(new FilterLogReader);
  r->model_ = &model;
  r->bundle_ = bundle;
  r->path_ = path;
  r->text_ = text;
  r->eof_ = true;
  if (Status s = r->ReadHeader(); !s.ok()) return Error{s.error(), s.code()};
  return r;
}

bool FilterLogReader::Refill() {
  if (file_ == nullptr || eof_) return false;
  // Keep the unread tail (a partial line) at the front; grow only for a line longer than a chunk.
  const size_t keep = text_.size();
  if (keep > 0) std::memmove(buf_.data(), text_.data(), keep);  // (an empty view may be null)
  if (buf_.size() < keep + kChunk) buf_.resize(keep + kChunk);
  const size_t n = std::fread(buf_.data() + keep, 1, buf_.size() - keep, file_);
  if (n == 0) eof_ = true;
  text_ = std::string_view(buf_.data(), keep + n);
  return n > 0;
}

bool FilterLogReader::NextLine(std::string_view* line) {
  for (;;) {
    const size_t nl = text_.find('\n');
    if (nl != std::string_view::npos) {
      *line = text_.substr(0, nl);
      text_.remove_prefix(nl + 1);
      ++line_no_;
      return true;
    }
    if (!Refill()) {
      if (text_.empty()) return false;
      *line = text_;
      text_ = {};
      ++line_no_;
      return true;
    }
  }
}

Status FilterLogReader::ReadHeader() {
  const FilterModel& model = *model_;
  const int m = model.num_states();
  const int r = model.num_outputs();
  std::string_view line;
  bool found = false;
  while (NextLine(&line)) {
    // A UTF-8 byte-order mark (spreadsheet exports) is not part of the first column's name.
    if (line_no_ == 1 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    SplitCsv(line, cells_);
    found = true;
    break;
  }
  if (file_ != nullptr && std::ferror(file_))
    return Error{"cannot read '" + path_ + "'", ErrorCode::kIo};
  if (!found) return Error{path_ + ": empty log (expected a CSV header line)"};
  if (IsBenchLogHeader(cells_)) return ReadBenchHeader();

  std::vector<std::string> y_names, input_names;
  if (r == 1) {
    y_names = {"y"};
  } else {
    for (int i = 0; i < r; ++i) y_names.push_back("y_" + std::to_string(i));
  }
  if (model.transition == TransitionSource::kBroadcast) {
    input_names = {"p_on", "p_off"};
  } else if (model.transition == TransitionSource::kExplicit) {
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        input_names.push_back("A_" + std::to_string(i) + "_" + std::to_string(j));
      }
    }
  }
  std::string expected = "t (optional)";
  for (const auto& n : input_names) expected += ", " + n;
  for (const auto& n : y_names) expected += ", " + n;
  const std::string where = path_ + ":" + std::to_string(line_no_);
  names_.assign(cells_.begin(), cells_.end());
  num_cols_ = names_.size();
  auto find = [&](const std::string& name) {
    return static_cast<int>(std::find(names_.begin(), names_.end(), name) - names_.begin());
  };
  for (size_t c = 0; c < num_cols_; ++c) {
    const std::string& h = names_[c];
    if (static_cast<size_t>(find(h)) != c) {
      return Error{where + ": duplicate column '" + ShortText(h) + "'"};
    }
    const bool known = h == "t" ||
                       std::find(input_names.begin(), input_names.end(), h) != input_names.end() ||
                       std::find(y_names.begin(), y_names.end(), h) != y_names.end();
    if (!known) {
      return Error{where + ": unknown column '" + ShortText(h) +
                   "'; this model's log has columns: " + ShortText(expected, 200)};
    }
  }
  auto require = [&](const std::vector<std::string>& names, std::vector<int>& cols) -> Status {
    cols.clear();
    for (const auto& n : names) {
      const int c = find(n);
      if (c == static_cast<int>(num_cols_)) {
        return Error{path_ + ": missing column '" + n + "'; columns: " + ShortText(expected, 200)};
      }
      cols.push_back(c);
    }
    return Status::Ok();
  };
  if (Status s = require(input_names, input_cols_); !s.ok()) return s;
  if (Status s = require(y_names, y_cols_); !s.ok()) return s;
  const int t = find("t");
  t_col_ = t < static_cast<int>(num_cols_) ? t : -1;
  return Status::Ok();
}

Status FilterLogReader::ReadBenchHeader() {
  const std::string where = path_ + ":" + std::to_string(line_no_);
  if (model_->transition != TransitionSource::kBroadcast || model_->num_outputs() != 1) {
    return Error{where +
                 ": a bench log gives each bundle's broadcasts and one force: the model "
                 "must have a broadcast transition and one output"};
  }
  names_.assign(cells_.begin(), cells_.end());
  num_cols_ = names_.size();
  auto cols = FindBenchLogColumns(names_, where);
  if (!cols.ok()) return cols.failure();
  auto b = SelectBenchBundle(*cols, bundle_, path_);
  if (!b.ok()) return b.failure();
  const BenchLogColumns::Bundle& c = cols->bundles[*b];
  bench_ = true;
  t_col_ = cols->time;
  instant_col_ = cols->control_instant;
  input_cols_ = {c.p_on, c.p_off};
  y_cols_ = {c.sensed_force};
  return Status::Ok();
}

Result<bool> FilterLogReader::Next(FilterLogRow& row) {
  const FilterModel& model = *model_;
  const int m = model.num_states();
  const int r = model.num_outputs();
  std::string_view line;
  for (;;) {
    if (!NextLine(&line)) {
      if (file_ != nullptr && std::ferror(file_))
        return Error{"cannot read '" + path_ + "'", ErrorCode::kIo};
      return false;
    }
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    if (!bench_ || instant_col_ < 0) break;
    // A bench log's rows between control instants are skipped.
    SplitCsv(line, cells_);
    if (cells_.size() != num_cols_) break;  // reported below
    const std::string at = path_ + ":" + std::to_string(line_no_);
    auto instant = ParseControlInstant(cells_[instant_col_], at);
    if (!instant.ok()) return instant.failure();
    if (*instant) break;
  }
  auto where = [&] { return path_ + ":" + std::to_string(line_no_); };
  if (last_without_inputs_) {
    return Error{path_ + ":" + std::to_string(last_data_line_) +
                 ": inputs are empty; only the last row may omit them"};
  }
  last_data_line_ = line_no_;
  row.line = line_no_;
  SplitCsv(line, cells_);
  if (cells_.size() != num_cols_) {
    return Error{where() + ": has " + std::to_string(cells_.size()) + " cells, the header " +
                 std::to_string(num_cols_)};
  }
  auto number = [&](int col, double* v) -> Status {
    if (ParseNumber(cells_[col], v)) return Status::Ok();
    return Error{where() + ": column '" + names_[col] + "': '" +
                 ShortText(std::string(cells_[col])) + "' is not a finite number"};
  };
  if (t_col_ >= 0) {
    if (Status s = number(t_col_, &row.t); !s.ok()) return Error{s.error(), s.code()};
  }
  // Measurement: all cells or none.
  int present = 0;
  for (int c : y_cols_) present += !cells_[c].empty();
  row.has_y = present > 0;
  if (present > 0 && present != r) {
    return Error{where() + ": measurement cells must be all given or all empty (no measurement)"};
  }
  if (row.has_y) {
    row.y.resize(r);
    for (int i = 0; i < r; ++i) {
      if (Status s = number(y_cols_[i], &row.y(i)); !s.ok()) return Error{s.error(), s.code()};
    }
  }
  // Inputs.
  int given = 0;
  for (int c : input_cols_) given += !cells_[c].empty();
  row.has_inputs = true;
  if (model.transition == TransitionSource::kConstant) return true;
  if (given == 0) {
    row.has_inputs = false;
    last_without_inputs_ = true;
  } else if (given != static_cast<int>(input_cols_.size())) {
    return Error{where() + ": input cells must be all given or all empty (last row only)"};
  } else if (model.transition == TransitionSource::kBroadcast) {
    if (Status s = number(input_cols_[0], &row.p_on); !s.ok()) return Error{s.error(), s.code()};
    if (Status s = number(input_cols_[1], &row.p_off); !s.ok()) return Error{s.error(), s.code()};
    if (Status s = BroadcastTransitionModel::ValidateInputs(row.p_on, row.p_off, where());
        !s.ok()) {
      return Error{s.error(), s.code()};
    }
  } else {
    row.A.resize(m, m);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) {
        if (Status s = number(input_cols_[i * m + j], &row.A(i, j)); !s.ok()) {
          return Error{s.error(), s.code()};
        }
      }
    }
    if (Status s = ValidateColumnStochastic(row.A, kStochasticTolerance, m, where() + ": A");
        !s.ok()) {
      return Error{s.error(), s.code()};
    }
  }
  return true;
}

Status RunFilterStream(const FilterModel& model, FilterLogReader& log, CountFilter& filter,
                       std::ostream& out) {
  const int m = model.num_states();
  std::string buf;
  // Room for the longest row: per number its comma and kShortestDoubleMaxChars characters, and
  // WriteShortest's room after the last one.
  const size_t row_room =
      (kShortestDoubleMaxChars + 1) * (2 * static_cast<size_t>(m) + 3) + kShortestDoubleRoom + 8;
  buf.reserve(kChunk + row_room + 4096);
  buf += "step";
  if (log.has_time()) buf += ",t";
  buf += ",updated";
  for (const auto& s : model.state_names) buf += ",x_" + s;
  for (const auto& s : model.state_names) buf += ",var_" + s;
  buf += "\n";
  auto flush = [&]() -> Status {
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    buf.clear();
    if (!out) return Error{"writing the output failed (disk full?)", ErrorCode::kIo};
    return Status::Ok();
  };
  FilterLogRow row, prev;
  Eigen::VectorXd mean(m), var(m);
  uint64_t k = 0;
  for (;; ++k) {
    auto more = log.Next(row);
    if (!more.ok()) return Error{more.error(), more.code()};
    if (!*more) break;
    if (k > 0) {  // A(k - 1): the inputs of the previous row
      switch (model.transition) {
        case TransitionSource::kBroadcast:
          filter.PredictBroadcast(model.broadcast, prev.p_on, prev.p_off);
          break;
        case TransitionSource::kExplicit:
          filter.Predict(prev.A);
          break;
        case TransitionSource::kConstant:
          filter.Predict(model.A);
          break;
      }
    }
    if (row.has_y) filter.Update(row.y);
    filter.MeanAndVariance(mean, var);
    if (!mean.allFinite() || !var.allFinite()) {
      return Error{log.path() + ": step " + std::to_string(k) + ": the estimate is not finite"};
    }
    // The row is formatted straight into the buffer's tail (row_room: room for the longest
    // row), then the buffer is cut to what was written.
    const size_t start = buf.size();
    buf.resize(start + row_room);
    char* p = buf.data() + start;
    char* const end = buf.data() + buf.size();
    p = std::to_chars(p, end, k).ptr;
    if (log.has_time()) {
      *p++ = ',';
      p = WriteShortest(p, row.t);  // shortest round-trip form, as std::to_chars
    }
    *p++ = ',';
    *p++ = row.has_y ? '1' : '0';
    for (int i = 0; i < m; ++i) {
      *p++ = ',';
      p = WriteShortest(p, mean(i));
    }
    for (int i = 0; i < m; ++i) {
      *p++ = ',';
      p = WriteShortest(p, var(i));
    }
    *p++ = '\n';
    buf.resize(static_cast<size_t>(p - buf.data()));
    if (buf.size() >= kChunk) {
      if (Status s = flush(); !s.ok()) return s;
    }
    std::swap(row, prev);  // swaps the vectors' storage: no copy, no allocation
  }
  if (k == 0) return Error{log.path() + ": no data rows after the header"};
  return flush();
}

Result<std::string> RunFilterOverText(const FilterModel& model, const std::string& text,
                                      const std::string& path, CountFilter& filter) {
  auto log = FilterLogReader::OpenText(text, model, path);
  if (!log.ok()) return Error{log.error(), log.code()};
  std::ostringstream out;
  if (Status s = RunFilterStream(model, **log, filter, out); !s.ok())
    return Error{s.error(), s.code()};
  return out.str();
}

}  // namespace recruit::estimation
