// CsvStepWriter: the per-step CSV of `recruit simulate` (docs/formats/task.md lists the columns).
// It writes through an AtomicFile, so the CSV appears only when Commit is called: after the run
// and after the run's other outputs are written (a failed summary leaves no CSV behind).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/step_observer.h"
#include "sim/format_g.h"

namespace recruit::sim {

class CsvStepWriter : public StepObserver {
 public:
  // Writes every `every`-th physics step (1 = all).
  explicit CsvStepWriter(std::string path, int every = 1);
  Status OnStep(const mjModel* m, const mjData* d, const TelemetrySample& s) override;
  Status Finish() override;  // writes what is buffered (the file stays temporary)
  Status Commit();           // the CSV appears under its name

 private:
  void Reserve(std::size_t n) {  // room for n more bytes after the used ones
    if (buffer_.size() < used_ + n) buffer_.resize(used_ + n);
  }
  void Flush();  // the used bytes to the file
  AtomicFile file_;
  int every_;
  long count_ = 0;  // steps seen (only counted when every_ > 1)
  // The row layout the sizes below are for: joints, bundles, the longest row's bytes.
  std::size_t joints_ = 0, bundles_ = 0, row_max_ = 0;
  // The run's estimator counts working units (kalman-failures): one more column per bundle.
  bool working_ = false;
  bool header_written_ = false;
  // Rows not yet written (the first used_ bytes), flushed past kFlushBytes. Small and reserved
  // once: a 1 MB buffer grown by doubling touched ~650 more pages (a 60 s arm run: 1392 -> 732
  // page faults, 2.5 MB less memory; its CPU time did not change measurably).
  static constexpr std::size_t kFlushBytes = 64 * 1024;
  std::vector<char> buffer_;
  std::size_t used_ = 0;
  // Each numeric column's last value and its text (a count's: the integer's bits). A column
  // whose value changes a little from step to step (the time, a force, a temperature) usually
  // keeps its sign, its decimal point's place and all but its last few digits: the value rounded
  // to the column's precision is q = base + low, 0 < low < span = 10^m, the m digits of low all
  // after the point. The next value, rounded at the same scale exactly as FormatG rounds it
  // (RoundByScaling's product and midpoint test), that lands in (base, base + span) has the same
  // text but its last m digits: those are rewritten in place (`Step`), the rest of the text kept.
  struct Column {
    std::uint64_t bits = 0;  // of the double
    // +-10^k, the value's sign: the value times it is q's unrounded integer, negative (so no
    // step) if the sign changed.
    double scale = 0;
    std::uint64_t base = 0;
    std::uint64_t span1 = 0;  // span - 1; 0: no step (no value of low passes its test)
    std::uint64_t mask = 0;   // the top m bytes of a word (of 8 bytes; m <= 4: its top half's)
    std::uint8_t len = 0;     // the text's length (%g drops trailing zeros)
    std::uint8_t full = 0;    // with the trailing zeros of its precision, kept after `len`
    // 8 bytes before the text, so that its last m <= 8 digits are one 8-byte word; the text (at
    // most 16 bytes at precisions <= 9) and FormatG's scratch after it.
    char buf[8 + kFormatGMax];
    char* text() { return buf + 8; }
    const char* text() const { return buf + 8; }
  };
  // A changed value's text if only its last digits changed (Column); false if not.
  static bool Step(Column& c, double v, std::uint64_t bits, int precision);
  // A changed value's text and the state of its steps, formatted in full (FormatG).
  static void Format(Column& c, double v, std::uint64_t bits, int precision);
  std::vector<Column> cache_;
  // A bundle's six columns that change only at control instants (force_reference, true_on,
  // estimated_on, estimated_on_std, p_on, p_off): their values' bits and text as last written,
  // so that a row in which none changed copies the text in one fixed-size move.
  static constexpr std::size_t kSlowText = 112;  // >= 6 columns of 16 bytes and a comma each
  struct SlowColumns {
    std::uint64_t key[6];
    std::size_t len = 0;
    char text[kSlowText];
  };
  std::vector<SlowColumns> slow_;
};

}  // namespace recruit::sim
