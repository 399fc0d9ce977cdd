// The sweep's report a lab note can carry: report.md (tables + figure links) and report.html (the
// same, self-contained: figures embedded as PNG data), with the figures as PNG and SVG drawn by
// src/plot: margin.{png,svg} (criterion margin against dT per plant point, one panel per
// estimator, with the output-only loop's latency bound dT = lambda tau / c as dotted lines) and
// critical_dt.{png,svg} (the critical dT against each plant axis). Every file
// depends only on the runs' results, so a merged sharded sweep writes the same bytes.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "sim/sweep.h"
#include "sweep/recommend.h"

namespace recruit::sweep {

struct ReportInput {
  std::string title;        // the task's name
  std::string description;  // one line: what was swept
  sim::TrackingCriterion criterion;
  std::vector<sim::CellStats> cells;
  // Per plant point: the agonist's force latency tau (s, sweep/latency.h; NaN = unknown). Empty:
  // no latency bound in the report.
  std::vector<double> latency;
};

// The Markdown text (figure links relative to the report); figures are listed only if made.
std::string ReportMarkdown(const ReportInput& in, const std::vector<Recommendation>& recs,
                           const std::vector<Sensitivity>& sens, bool with_figures);

// Writes report.md, report.html and the figures into `out_dir`.
Status WriteReport(const ReportInput& in, const std::string& out_dir);

}  // namespace recruit::sweep
