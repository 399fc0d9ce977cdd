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
  // Each numeric column's last value and its text (a count's: the integer's bits).
  struct Column {
    std::uint64_t bits = 0;  // of the double
    std::uint8_t len = 0;    // 0: none yet
    char text[kFormatGMax];
  };
  std::vector<Column> cache_;
};

}  // namespace recruit::sim
