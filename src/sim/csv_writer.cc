#include "sim/csv_writer.h"

#include <fmt/format.h>

#include <cmath>
#include <iterator>

namespace recruit::sim {

CsvStepWriter::CsvStepWriter(std::string path, int every)
    : file_(std::move(path)), every_(every < 1 ? 1 : every) {}

Status CsvStepWriter::OnStep(const mjModel*, const mjData*, const TelemetrySample& s) {
  if (!file_.ok()) return Error{file_.error()};
  if (!header_written_) {
    buffer_ += "time,reference,measured,angle";
    for (const auto& b : s.bundles) {
      for (const char* col : {"force", "force_reference", "true_on", "estimated_on",
                              "estimated_on_std", "p_on", "p_off", "mean_temperature"}) {
        buffer_ += fmt::format(",{}.{}", b.actuator, col);
      }
    }
    buffer_ += ",control_instant\n";
    header_written_ = true;
  }
  if (count_++ % every_ != 0 && !s.control_instant) return Status::Ok();
  auto out = std::back_inserter(buffer_);
  fmt::format_to(out, "{:.6g},{:.9g},{:.9g},{:.9g}", s.time, s.reference, s.measured, s.angle);
  for (const auto& b : s.bundles) {
    fmt::format_to(out, ",{:.9g},{:.9g},{},", b.force, b.force_reference, b.true_on);
    // Non-finite estimates (no estimator, no variance) are left empty: readers take them as NaN.
    if (std::isfinite(b.estimated_on)) fmt::format_to(out, "{:.6g}", b.estimated_on);
    buffer_ += ',';
    if (std::isfinite(b.estimated_on_std)) fmt::format_to(out, "{:.6g}", b.estimated_on_std);
    fmt::format_to(out, ",{:.6g},{:.6g},{:.6g}", b.p_on, b.p_off, b.mean_temperature);
  }
  fmt::format_to(out, ",{}\n", s.control_instant ? 1 : 0);
  if (buffer_.size() > (1 << 20)) {
    file_.stream() << buffer_;
    buffer_.clear();
  }
  return Status::Ok();
}

Status CsvStepWriter::Finish() {
  if (!file_.ok()) return Error{file_.error()};
  file_.stream() << buffer_;
  buffer_.clear();
  return Status::Ok();
}

Status CsvStepWriter::Commit() {
  if (!file_.ok()) return Error{file_.error()};
  return file_.Commit();
}

}  // namespace recruit::sim
