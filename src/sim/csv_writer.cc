#include "sim/csv_writer.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>

#include "sim/format_g.h"

namespace recruit::sim {

CsvStepWriter::CsvStepWriter(std::string path, int every)
    : file_(std::move(path)), every_(every < 1 ? 1 : every) {
  buffer_.reserve(2 * kFlushBytes);
}

Status CsvStepWriter::OnStep(const mjModel*, const mjData*, const TelemetrySample& s) {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  if (!header_written_) {
    std::string header = "time,reference,measured,angle";
    for (const auto& j : s.joints) header += fmt::format(",{0}.reference,{0}.angle", j.joint);
    for (const auto& b : s.bundles) {
      for (const char* col : {"force", "force_reference", "true_on", "estimated_on",
                              "estimated_on_std", "p_on", "p_off", "mean_temperature"}) {
        header += fmt::format(",{}.{}", b.actuator, col);
      }
    }
    header += ",control_instant";
    // Added after every older column, so that readers by position keep working.
    for (const auto& b : s.bundles) header += fmt::format(",{}.sensed_force", b.actuator);
    for (const auto& b : s.bundles) working_ = working_ || std::isfinite(b.estimated_working);
    if (working_) {
      for (const auto& b : s.bundles) header += fmt::format(",{}.estimated_working", b.actuator);
    }
    header += '\n';
    Reserve(header.size());
    std::memcpy(buffer_.data() + used_, header.data(), header.size());
    used_ += header.size();
    header_written_ = true;
  }
  if (every_ > 1 && count_++ % every_ != 0 && !s.control_instant) return Status::Ok();
  // The row is formatted in place, with room for the longest row (FormatG: "%.9g" etc. byte
  // for byte, without fmt's format-string parsing). Most columns hold between control instants
  // (references, estimates, broadcasts): a column equal to its last value reuses its text, and
  // one equal to the number formatted just before in the row (an angle task's measured value and
  // angle, a force task's measured value and force) copies that one's.
  // The longest row and the columns' texts, sized when the layout is new (once in a run).
  if (s.joints.size() != joints_ || s.bundles.size() != bundles_ || row_max_ == 0) {
    joints_ = s.joints.size();
    bundles_ = s.bundles.size();
    row_max_ = 8 + (4 + 2 * joints_ + 10 * bundles_) * kFormatGMax;
    cache_.resize(4 + 2 * joints_ + 10 * bundles_);
  }
  Reserve(row_max_);
  char* p = buffer_.data() + used_;
  Column* col = cache_.data();
  const Column* last = nullptr;  // the number formatted last in this row
  int last_precision = 0;
  // Inlined: an out-of-line call per number (18 per row of a two-bundle task) was ~1 % of an
  // arm run's CPU.
  auto num = [&](double v, int precision) __attribute__((always_inline)) {
    Column& c = *col++;
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    if (c.len == 0 || bits != c.bits) {
      if (last != nullptr && last->bits == bits && last_precision == precision) {
        c = *last;
      } else {
        c.bits = bits;
        c.len = static_cast<std::uint8_t>(FormatG(v, precision, c.text) - c.text);
      }
      last = &c;
      last_precision = precision;
    }
    std::memcpy(p, c.text, sizeof c.text);  // fixed size: one move, the end is overwritten
    p += c.len;
  };
  // A count (a bundle's units on): its text cached like a number's, apart from `last`.
  auto count = [&](int v) __attribute__((always_inline)) {
    Column& c = *col++;
    const auto bits = static_cast<std::uint64_t>(static_cast<std::int64_t>(v));
    if (c.len == 0 || bits != c.bits) {
      c.bits = bits;
      c.len = static_cast<std::uint8_t>(FormatInt(v, c.text) - c.text);
    }
    std::memcpy(p, c.text, sizeof c.text);
    p += c.len;
  };
  auto comma = [&p] { *p++ = ','; };
  num(s.time, 6);
  comma();
  num(s.reference, 9);
  comma();
  num(s.measured, 9);
  comma();
  num(s.angle, 9);
  for (const auto& j : s.joints) {
    comma();
    num(j.reference, 9);
    comma();
    num(j.angle, 9);
  }
  for (const auto& b : s.bundles) {
    comma();
    num(b.force, 9);
    comma();
    num(b.force_reference, 9);
    comma();
    count(b.true_on);
    comma();
    // Non-finite estimates (no estimator, no variance) are left empty: readers take them as NaN.
    if (std::isfinite(b.estimated_on)) {
      num(b.estimated_on, 6);
    } else {
      ++col;
    }
    comma();
    if (std::isfinite(b.estimated_on_std)) {
      num(b.estimated_on_std, 6);
    } else {
      ++col;
    }
    comma();
    num(b.p_on, 6);
    comma();
    num(b.p_off, 6);
    comma();
    num(b.mean_temperature, 6);
  }
  *p++ = ',';
  *p++ = s.control_instant ? '1' : '0';
  for (const auto& b : s.bundles) {
    comma();
    if (std::isfinite(b.sensed_force)) {
      num(b.sensed_force, 9);
    } else {
      ++col;
    }
  }
  for (std::size_t i = 0; working_ && i < s.bundles.size(); ++i) {
    comma();
    if (std::isfinite(s.bundles[i].estimated_working)) {
      num(s.bundles[i].estimated_working, 6);
    } else {
      ++col;
    }
  }
  *p++ = '\n';
  used_ = static_cast<std::size_t>(p - buffer_.data());
  if (used_ > kFlushBytes) Flush();
  return Status::Ok();
}

void CsvStepWriter::Flush() {
  file_.stream().write(buffer_.data(), static_cast<std::streamsize>(used_));
  used_ = 0;
}

Status CsvStepWriter::Finish() {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  Flush();
  return Status::Ok();
}

Status CsvStepWriter::Commit() {
  if (!file_.ok()) return Error{file_.error(), file_.code()};
  return file_.Commit();
}

}  // namespace recruit::sim
