// CsvStepWriter: the per-step CSV of `recruit simulate` (docs/formats/task.md lists the columns).
// It writes through an AtomicFile, so the CSV appears only when the run finishes.
#pragma once

#include <string>

#include "common/atomic_file.h"
#include "common/step_observer.h"

namespace recruit::sim {

class CsvStepWriter : public StepObserver {
 public:
  // Writes every `every`-th physics step (1 = all).
  explicit CsvStepWriter(std::string path, int every = 1);
  Status OnStep(const mjModel* m, const mjData* d, const TelemetrySample& s) override;
  Status Finish() override;

 private:
  AtomicFile file_;
  int every_;
  long count_ = 0;
  bool header_written_ = false;
  std::string buffer_;
};

}  // namespace recruit::sim
