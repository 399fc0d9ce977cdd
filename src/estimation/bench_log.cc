#include "estimation/bench_log.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string_view>

#include "common/atomic_file.h"
#include "common/short_text.h"

namespace recruit::estimation {
namespace {

constexpr std::string_view kSensed = ".sensed_force";
constexpr std::string_view kAngle = ".angle";

bool BenchEndsWith(std::string_view s, std::string_view suffix) {
  return s.size() > suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

template <class S>
bool IsBenchHeader(const std::vector<S>& header) {
  bool time = false, sensed = false;
  for (const auto& h : header) {
    time = time || std::string_view(h) == "time";
    sensed = sensed || BenchEndsWith(h, kSensed);
  }
  return time && sensed;
}

std::string_view BenchTrim(std::string_view s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

void BenchSplitCsv(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t start = 0;
  for (;;) {
    const size_t c = line.find(',', start);
    out.push_back(BenchTrim(line.substr(start, c == std::string_view::npos ? c : c - start)));
    if (c == std::string_view::npos) break;
    start = c + 1;
  }
}

bool BenchParseNumber(std::string_view s, double* v) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), *v);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(*v);
}

}  // namespace

bool IsBenchLogHeader(const std::vector<std::string_view>& header) { return IsBenchHeader(header); }
bool IsBenchLogHeader(const std::vector<std::string>& header) { return IsBenchHeader(header); }

Result<BenchLogColumns> FindBenchLogColumns(const std::vector<std::string>& header,
                                            const std::string& where) {
  BenchLogColumns c;
  auto find = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : static_cast<int>(it - header.begin());
  };
  for (size_t i = 0; i < header.size(); ++i) {
    if (find(header[i]) != static_cast<int>(i)) {
      return Error{where + ": duplicate column '" + ShortText(header[i]) + "'"};
    }
  }
  c.time = find("time");
  if (c.time < 0) return Error{where + ": a bench log needs a 'time' column (s)"};
  c.control_instant = find("control_instant");
  if (const int a = find("angle"); a >= 0) c.angles.push_back({"angle", a});
  for (size_t i = 0; i < header.size(); ++i) {
    const std::string& h = header[i];
    if (BenchEndsWith(h, kAngle)) {
      c.angles.push_back({h.substr(0, h.size() - kAngle.size()), static_cast<int>(i)});
    }
    if (!BenchEndsWith(h, kSensed)) continue;
    BenchLogColumns::Bundle b;
    b.name = h.substr(0, h.size() - kSensed.size());
    b.sensed_force = static_cast<int>(i);
    b.p_on = find(b.name + ".p_on");
    b.p_off = find(b.name + ".p_off");
    if (b.p_on < 0 || b.p_off < 0) {
      return Error{where + ": column '" + ShortText(h) +
                   "' needs its bundle's broadcast columns '" + ShortText(b.name) + ".p_on' and '" +
                   ShortText(b.name) + ".p_off'"};
    }
    c.bundles.push_back(std::move(b));
  }
  if (c.bundles.empty()) {
    return Error{where + ": a bench log needs a '<bundle>.sensed_force' column per bundle"};
  }
  return c;
}

Result<int> SelectBenchBundle(const BenchLogColumns& c, const std::string& name,
                              const std::string& where) {
  std::string names;
  for (const auto& b : c.bundles) names += (names.empty() ? "" : ", ") + b.name;
  if (name.empty()) {
    if (c.bundles.size() == 1) return 0;
    return Error{where + ": the log has several bundles (" + ShortText(names, 200) +
                 "); name one with --actuator"};
  }
  for (size_t i = 0; i < c.bundles.size(); ++i) {
    if (c.bundles[i].name == name) return static_cast<int>(i);
  }
  return Error{where + ": no bundle '" + ShortText(name) + "' in the log; it has " +
               ShortText(names, 200)};
}

Result<bool> ParseControlInstant(std::string_view cell, const std::string& where) {
  if (cell == "1") return true;
  if (cell == "0") return false;
  return Error{where + ": column 'control_instant': '" + ShortText(cell) + "' must be 0 or 1"};
}

Result<BenchLog> ReadBenchLog(const std::string& path) {
  auto text = ReadFile(path);
  if (!text.ok()) return text.failure();
  return ParseBenchLog(*text, path);
}

Result<BenchLog> ParseBenchLog(const std::string& text, const std::string& path) {
  std::string_view rest = text;
  if (rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // a spreadsheet's BOM
  std::vector<std::string_view> cells;
  int line_no = 0;
  auto next_line = [&](std::string_view* line) {
    while (!rest.empty()) {
      const size_t nl = rest.find('\n');
      *line = BenchTrim(rest.substr(0, nl));
      rest.remove_prefix(nl == std::string_view::npos ? rest.size() : nl + 1);
      ++line_no;
      if (!line->empty() && (*line)[0] != '#') return true;
    }
    return false;
  };
  std::string_view line;
  if (!next_line(&line)) return Error{path + ": empty log (expected a CSV header line)"};
  BenchSplitCsv(line, cells);
  const std::vector<std::string> header(cells.begin(), cells.end());
  auto cols = FindBenchLogColumns(header, path + ":" + std::to_string(line_no));
  if (!cols.ok()) return cols.failure();
  BenchLog log;
  log.path = path;
  for (const auto& b : cols->bundles) log.bundles.push_back({b.name, {}, {}, {}});
  for (const auto& a : cols->angles) log.angles.push_back({a.name, {}});
  while (next_line(&line)) {
    BenchSplitCsv(line, cells);
    const std::string where = path + ":" + std::to_string(line_no);
    if (cells.size() != header.size()) {
      return Error{where + ": has " + std::to_string(cells.size()) + " cells, the header " +
                   std::to_string(header.size())};
    }
    if (cols->control_instant >= 0) {
      auto instant = ParseControlInstant(cells[cols->control_instant], where);
      if (!instant.ok()) return instant.failure();
      if (!*instant) continue;
    }
    auto number = [&](int col, double lo, double hi, double* v) -> Status {
      if (BenchParseNumber(cells[col], v) && *v >= lo && *v <= hi) return Status::Ok();
      return Error{where + ": column '" + header[col] + "': '" + ShortText(cells[col]) +
                   "' is not a finite number" +
                   (std::isfinite(lo) ? fmt::format(" in [{:g}, {:g}]", lo, hi) : std::string())};
    };
    const double inf = INFINITY;
    double t;
    if (Status s = number(cols->time, -inf, inf, &t); !s.ok()) return s.failure();
    if (!log.time.empty() && !(t > log.time.back())) {
      return Error{where + ": time " + ShortText(cells[cols->time]) +
                   " s does not increase (control instants in time order)"};
    }
    log.time.push_back(t);
    log.line.push_back(line_no);
    for (size_t i = 0; i < cols->bundles.size(); ++i) {
      const auto& c = cols->bundles[i];
      double on, off, f;
      if (Status s = number(c.p_on, 0, 1, &on); !s.ok()) return s.failure();
      if (Status s = number(c.p_off, 0, 1, &off); !s.ok()) return s.failure();
      if (Status s = number(c.sensed_force, -inf, inf, &f); !s.ok()) return s.failure();
      log.bundles[i].p_on.push_back(on);
      log.bundles[i].p_off.push_back(off);
      log.bundles[i].sensed_force.push_back(f);
    }
    for (size_t j = 0; j < cols->angles.size(); ++j) {
      double a;
      if (Status s = number(cols->angles[j].col, -inf, inf, &a); !s.ok()) return s.failure();
      log.angles[j].value.push_back(a);
    }
  }
  const int n = log.size();
  if (n < 2) return Error{path + ": needs at least 2 control instants, has " + std::to_string(n)};
  log.dT = (log.time.back() - log.time.front()) / (n - 1);
  for (int k = 1; k < n; ++k) {
    const double step = log.time[k] - log.time[k - 1];
    if (std::abs(step - log.dT) > kBenchLogPeriodTolerance * log.dT) {
      return Error{path + ":" + std::to_string(log.line[k]) + ": control period " +
                   fmt::format("{:g}", step) + " s differs from the mean " +
                   fmt::format("{:g}", log.dT) +
                   " s by more than 1 % (the control instants must be uniformly spaced)"};
    }
  }
  return log;
}

}  // namespace recruit::estimation
