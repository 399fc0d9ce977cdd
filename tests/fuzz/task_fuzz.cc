// Fuzz target: the task parser (sim::Task::FromJsonText, docs/formats/task.md). Any input must
// give a task or an error, never a crash; a parsed task's reference is evaluated as a run would.
#include <cstddef>
#include <cstdint>
#include <string>

#include "sim/task.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  // The task "file" sits in models/tasks, so the seeds' relative model paths resolve.
  static const std::string kSource = RECRUIT_SOURCE_DIR "/models/tasks/fuzz_task.json";
  auto task = recruit::sim::Task::FromJsonText(text, kSource);
  if (!task.ok()) return 0;
  const auto& ref = task->reference;
  volatile double sink = ref.MaxValue() + ref.MinValue();
  for (double t : {0.0, 0.5 * task->duration, task->duration}) sink = sink + ref(t);
  sink = sink + static_cast<double>(ref.Steps(task->duration).size());
  (void)sink;
  return 0;
}
