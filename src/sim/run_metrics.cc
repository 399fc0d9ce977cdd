#include "sim/run_metrics.h"

#include <cmath>

namespace recruit::sim {

double MetricValue(const RunMetrics& m, const MetricField& f) {
  return f.real ? m.*f.real : static_cast<double>(m.*f.count);
}

void SetMetric(RunMetrics& m, const MetricField& f, double value) {
  if (f.real) {
    m.*f.real = value;
  } else {
    m.*f.count = static_cast<int>(std::lround(value));
  }
}

nlohmann::json MetricsToJson(const RunMetrics& m) {
  nlohmann::json j = nlohmann::json::object();
  for (const MetricField& f : kMetricFields) {
    if (f.real) {
      j[f.name] = m.*f.real;  // NaN is dumped as null
    } else {
      j[f.name] = m.*f.count;
    }
  }
  return j;
}

RunMetrics MetricsFromJson(const nlohmann::json& j) {
  RunMetrics m;
  for (const MetricField& f : kMetricFields) {
    const nlohmann::json& v = j.at(f.name);
    if (f.count) {
      m.*f.count = v.get<int>();
    } else if (f.may_be_nan && v.is_null()) {
      m.*f.real = std::nan("");
    } else {
      m.*f.real = v.get<double>();
    }
  }
  return m;
}

std::vector<std::string> CellMetricColumns() {
  std::vector<std::string> out;
  for (const MetricField& f : kMetricFields) {
    if (!f.cell_mean) continue;
    out.push_back(f.cell_mean);
    if (f.cell_sd) out.push_back(std::string(f.name) + "_sd");
  }
  return out;
}

}  // namespace recruit::sim
