#include "estimation/filter_log.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <sstream>

#include "common/atomic_file.h"
#include "estimation/population_chain.h"

namespace recruit {
namespace {

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::string cell;
  std::istringstream ss(line);
  while (std::getline(ss, cell, ',')) out.push_back(Trim(cell));
  if (!line.empty() && line.back() == ',') out.push_back("");
  return out;
}

// A strict number: the whole cell, finite.
bool ParseNumber(const std::string& s, double* v) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *v = std::strtod(s.c_str(), &end);
  return errno == 0 && end == s.c_str() + s.size() && std::isfinite(*v);
}

}  // namespace

Result<FilterLog> ParseFilterLog(const std::string& text, const FilterModel& model,
                                 const std::string& path) {
  const int m = model.num_states();
  const int r = model.num_outputs();
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    header = SplitCsv(t);
    break;
  }
  if (header.empty()) return Error{path + ": empty log (expected a CSV header line)"};

  // Which columns the model needs.
  std::vector<std::string> y_names;
  if (r == 1) {
    y_names = {"y"};
  } else {
    for (int i = 0; i < r; ++i) y_names.push_back("y_" + std::to_string(i));
  }
  std::vector<std::string> input_names;
  switch (model.transition) {
    case TransitionSource::kBroadcast:
      input_names = {"p_on", "p_off"};
      break;
    case TransitionSource::kExplicit:
      for (int i = 0; i < m; ++i) {
        for (int j = 0; j < m; ++j) {
          input_names.push_back("A_" + std::to_string(i) + "_" + std::to_string(j));
        }
      }
      break;
    case TransitionSource::kConstant:
      break;
  }
  std::map<std::string, int> col;
  for (size_t c = 0; c < header.size(); ++c) {
    const std::string& h = header[c];
    if (col.count(h))
      return Error{path + ":" + std::to_string(line_no) + ": duplicate column '" + h + "'"};
    col[h] = static_cast<int>(c);
  }
  std::string expected = "t (optional)";
  for (const auto& n : input_names) expected += ", " + n;
  for (const auto& n : y_names) expected += ", " + n;
  for (const auto& [h, c] : col) {
    const bool known = h == "t" ||
                       std::find(input_names.begin(), input_names.end(), h) != input_names.end() ||
                       std::find(y_names.begin(), y_names.end(), h) != y_names.end();
    if (!known) {
      return Error{path + ":" + std::to_string(line_no) + ": unknown column '" + h +
                   "'; this model's log has columns: " + expected};
    }
  }
  for (const auto& n : input_names) {
    if (!col.count(n)) return Error{path + ": missing column '" + n + "'; columns: " + expected};
  }
  for (const auto& n : y_names) {
    if (!col.count(n)) return Error{path + ": missing column '" + n + "'; columns: " + expected};
  }

  FilterLog log;
  log.has_time = col.count("t") > 0;
  bool last_without_inputs = false;
  int last_data_line = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string t = Trim(line);
    if (t.empty() || t[0] == '#') continue;
    const std::string where = path + ":" + std::to_string(line_no);
    if (last_without_inputs) {
      return Error{path + ":" + std::to_string(last_data_line) +
                   ": inputs are empty; only the last row may omit them"};
    }
    last_data_line = line_no;
    const auto cells = SplitCsv(t);
    if (cells.size() != header.size()) {
      return Error{where + ": has " + std::to_string(cells.size()) + " cells, the header " +
                   std::to_string(header.size())};
    }
    auto cell_number = [&](const std::string& name, double* v) -> Status {
      const std::string& s = cells[col[name]];
      if (!ParseNumber(s, v)) {
        return Error{where + ": column '" + name + "': '" + s + "' is not a finite number"};
      }
      return Status::Ok();
    };
    if (log.has_time) {
      double v;
      if (Status s = cell_number("t", &v); !s.ok()) return Error{s.error()};
      log.t.push_back(v);
    }
    // Measurement: all cells or none.
    int present = 0;
    for (const auto& n : y_names) present += !cells[col[n]].empty();
    if (present == 0) {
      log.y.emplace_back(std::nullopt);
    } else if (present != r) {
      return Error{where + ": measurement cells must be all given or all empty (no measurement)"};
    } else {
      Eigen::VectorXd y(r);
      for (int i = 0; i < r; ++i) {
        if (Status s = cell_number(y_names[i], &y(i)); !s.ok()) return Error{s.error()};
      }
      log.y.emplace_back(y);
    }
    // Inputs.
    int given = 0;
    for (const auto& n : input_names) given += !cells[col[n]].empty();
    if (model.transition == TransitionSource::kConstant) {
      log.A.emplace_back(model.A);
    } else if (given == 0) {
      log.A.emplace_back(std::nullopt);
      last_without_inputs = true;
    } else if (given != static_cast<int>(input_names.size())) {
      return Error{where + ": input cells must be all given or all empty (last row only)"};
    } else if (model.transition == TransitionSource::kBroadcast) {
      double p_on, p_off;
      if (Status s = cell_number("p_on", &p_on); !s.ok()) return Error{s.error()};
      if (Status s = cell_number("p_off", &p_off); !s.ok()) return Error{s.error()};
      if (Status s = BroadcastTransitionModel::ValidateInputs(p_on, p_off, where); !s.ok()) {
        return Error{s.error()};
      }
      log.A.emplace_back(model.broadcast.Matrix(p_on, p_off));
    } else {
      Eigen::MatrixXd A(m, m);
      for (int i = 0; i < m; ++i) {
        for (int j = 0; j < m; ++j) {
          if (Status s = cell_number(input_names[i * m + j], &A(i, j)); !s.ok()) {
            return Error{s.error()};
          }
        }
      }
      if (Status s = ValidateColumnStochastic(A, kStochasticTolerance, m, where + ": A"); !s.ok()) {
        return Error{s.error()};
      }
      log.A.emplace_back(A);
    }
  }
  if (log.y.empty()) return Error{path + ": no data rows after the header"};
  return log;
}

Result<FilterLog> ReadFilterLog(const std::string& path, const FilterModel& model) {
  auto text = ReadFile(path);
  if (!text.ok()) return Error{text.error()};
  return ParseFilterLog(*text, model, path);
}

Result<std::string> RunFilterOverLog(const FilterModel& model, const FilterLog& log,
                                     CountFilter& filter) {
  std::ostringstream out;
  out << "step";
  if (log.has_time) out << ",t";
  out << ",updated";
  for (const auto& s : model.state_names) out << ",x_" << s;
  for (const auto& s : model.state_names) out << ",var_" << s;
  out << "\n";
  char buf[64];
  auto num = [&](double v) {
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return std::string(buf);
  };
  for (size_t k = 0; k < log.num_steps(); ++k) {
    if (k > 0) filter.Predict(*log.A[k - 1]);
    if (log.y[k]) filter.Update(*log.y[k]);
    const Eigen::VectorXd x = filter.Mean();
    const Eigen::VectorXd v = filter.Covariance().diagonal();
    if (!x.allFinite() || !v.allFinite()) {
      return Error{"step " + std::to_string(k) + ": the estimate is not finite"};
    }
    out << k;
    if (log.has_time) out << "," << num(log.t[k]);
    out << "," << (log.y[k] ? 1 : 0);
    for (int i = 0; i < x.size(); ++i) out << "," << num(x(i));
    for (int i = 0; i < v.size(); ++i) out << "," << num(v(i));
    out << "\n";
  }
  return out.str();
}

}  // namespace recruit
