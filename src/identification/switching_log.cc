#include "identification/switching_log.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "common/atomic_file.h"
#include "estimation/bench_log.h"

namespace recruit::identification {
namespace {

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    while (!cell.empty() && (cell.back() == '\r' || cell.back() == ' ')) cell.pop_back();
    while (!cell.empty() && cell.front() == ' ') cell.erase(cell.begin());
    out.push_back(cell);
  }
  return out;
}

// A bench log's control instants, for the chosen bundle.
Result<SwitchingLog> FromBenchLog(const std::string& path, int num_units,
                                  const std::string& bundle) {
  auto bench = estimation::ReadBenchLog(path);
  if (!bench.ok()) return bench.failure();
  estimation::BenchLogColumns names;
  for (const auto& b : bench->bundles) names.bundles.push_back({b.name});
  auto i = estimation::SelectBenchBundle(names, bundle, path);
  if (!i.ok()) return i.failure();
  const estimation::BenchLog::Bundle& b = bench->bundles[*i];
  SwitchingLog log;
  log.num_units = num_units;
  log.dT = bench->dT;
  log.time = bench->time;
  log.p_on = b.p_on;
  log.p_off = b.p_off;
  log.force = b.sensed_force;
  if (Status s = log.Validate(path); !s) return s.failure();
  return log;
}

}  // namespace

Result<SwitchingLog> SwitchingLog::FromCsv(const std::string& path, int num_units,
                                           const std::string& bundle) {
  std::ifstream in(path);
  if (!in) return Error{path + ": cannot open the switching log", ErrorCode::kIo};
  std::string line;
  if (!std::getline(in, line)) return Error{path + ": empty file (expected a CSV header)"};
  if (line.substr(0, 3) == "\xEF\xBB\xBF") line.erase(0, 3);
  const auto header = SplitCsv(line);
  if (estimation::IsBenchLogHeader(header)) return FromBenchLog(path, num_units, bundle);
  int col_t = -1, col_on = -1, col_off = -1, col_f = -1, col_true = -1, col_ron = -1, col_roff = -1;
  for (int i = 0; i < static_cast<int>(header.size()); ++i) {
    if (header[i] == "time") col_t = i;
    if (header[i] == "p_on") col_on = i;
    if (header[i] == "p_off") col_off = i;
    if (header[i] == "force") col_f = i;
    if (header[i] == "true_on") col_true = i;
    if (header[i] == "realized_on") col_ron = i;
    if (header[i] == "realized_off") col_roff = i;
  }
  if (col_t < 0 || col_on < 0 || col_off < 0 || col_f < 0) {
    return Error{path + ": header must name the columns time, p_on, p_off, force (got \"" + line +
                 "\")"};
  }
  if ((col_ron < 0) != (col_roff < 0)) {
    return Error{path + ": realized_on and realized_off must be given together"};
  }
  SwitchingLog log;
  log.num_units = num_units;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty() || line == "\r") continue;
    const auto cells = SplitCsv(line);
    auto get = [&](int col, const char* name, double& v) -> Status {
      if (col >= static_cast<int>(cells.size())) {
        return Error{path + ": line " + std::to_string(row) + ": missing column " + name};
      }
      char* end = nullptr;
      v = std::strtod(cells[col].c_str(), &end);
      if (cells[col].empty() || *end != '\0' || !std::isfinite(v)) {
        return Error{path + ": line " + std::to_string(row) + ": " + name + " = \"" + cells[col] +
                     "\" is not a finite number"};
      }
      return Status::Ok();
    };
    double t, on, off, f, tr = 0;
    if (Status s = get(col_t, "time", t); !s) return Error{s.error(), s.code()};
    if (Status s = get(col_on, "p_on", on); !s) return Error{s.error(), s.code()};
    if (Status s = get(col_off, "p_off", off); !s) return Error{s.error(), s.code()};
    if (Status s = get(col_f, "force", f); !s) return Error{s.error(), s.code()};
    if (col_true >= 0) {
      if (Status s = get(col_true, "true_on", tr); !s) return Error{s.error(), s.code()};
      log.true_on.push_back(tr);
    }
    if (col_ron >= 0) {
      double ron, roff;
      if (Status s = get(col_ron, "realized_on", ron); !s) return Error{s.error(), s.code()};
      if (Status s = get(col_roff, "realized_off", roff); !s) return Error{s.error(), s.code()};
      log.realized_on.push_back(ron);
      log.realized_off.push_back(roff);
    }
    log.time.push_back(t);
    log.p_on.push_back(on);
    log.p_off.push_back(off);
    log.force.push_back(f);
  }
  if (log.size() < 2) return Error{path + ": needs at least 2 data rows"};
  log.dT = log.time[1] - log.time[0];
  for (int k = 1; k < log.size(); ++k) {
    const double step = log.time[k] - log.time[k - 1];
    if (!(std::abs(step - log.dT) <= 1e-6 * std::max(1.0, log.dT))) {
      return Error{path + ": line " + std::to_string(k + 2) + ": time step " +
                   std::to_string(step) + " s differs from the first, " + std::to_string(log.dT) +
                   " s (rows must be the control instants, uniformly spaced)"};
    }
  }
  if (Status s = log.Validate(path); !s) return Error{s.error(), s.code()};
  return log;
}

Status SwitchingLog::Validate(const std::string& where) const {
  const size_t n = force.size();
  if (n < 2) return Error{where + ": a switching log needs at least 2 samples"};
  if (time.size() != n || p_on.size() != n || p_off.size() != n ||
      (!true_on.empty() && true_on.size() != n) ||
      (has_realized() && (realized_on.size() != n || realized_off.size() != n))) {
    return Error{where +
                 ": columns time, p_on, p_off, force (and true_on, realized_on, realized_off) "
                 "differ in length"};
  }
  if (num_units < 1) return Error{where + ": num_units must be >= 1"};
  RECRUIT_TRY(control::CheckDT(dT, where));
  for (size_t k = 0; k < n; ++k) {
    for (auto [v, name] : {std::pair{p_on[k], "p_on"}, std::pair{p_off[k], "p_off"},
                           std::pair{has_realized() ? realized_on[k] : 0.0, "realized_on"},
                           std::pair{has_realized() ? realized_off[k] : 0.0, "realized_off"}}) {
      if (!(v >= 0 && v <= 1)) {
        return Error{where + ": sample " + std::to_string(k) + ": " + name + " = " +
                     std::to_string(v) + " is not in [0, 1]"};
      }
    }
    if (!std::isfinite(force[k])) {
      return Error{where + ": sample " + std::to_string(k) + ": force is not finite"};
    }
  }
  return Status::Ok();
}

Status SwitchingLog::SaveCsv(const std::string& path) const {
  AtomicFile f(path);
  if (!f.ok()) return Error{f.error(), f.code()};
  auto& o = f.stream();
  o << "time,p_on,p_off,force" << (true_on.empty() ? "" : ",true_on")
    << (has_realized() ? ",realized_on,realized_off" : "") << "\n";
  o << std::setprecision(10);
  for (int k = 0; k < size(); ++k) {
    o << time[k] << ',' << p_on[k] << ',' << p_off[k] << ',' << force[k];
    if (!true_on.empty()) o << ',' << true_on[k];
    if (has_realized()) o << ',' << realized_on[k] << ',' << realized_off[k];
    o << '\n';
  }
  return f.Commit();
}

}  // namespace recruit::identification
