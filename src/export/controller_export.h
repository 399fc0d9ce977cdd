// `recruit export`: a task's tuned controller as a self-contained C99 package for a
// microcontroller (docs/export.md). The package is the controller RunTask builds for the task
// (sim::TaskControllers: the estimator on each bundle's identified model, the length-aware
// target, the expectation law) plus the task's outer loop (hand-set gains, or the self-tuned joint
// loops frozen per reference pose), with every constant written out: recruit_controller.h/.c. The
// unit side (each unit's state machine and the broadcast's wire format,
// docs/broadcast-wire-format.md) is a second package: recruit_unit.h/.c.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "export/c_writer.h"
#include "sim/run_task.h"
#include "sim/task.h"

namespace recruit::exporter {

// "double" or "float".
Result<Precision> ParsePrecision(const std::string& name);

struct ExportedFile {
  std::string name;  // file name, no directory
  std::string contents;
};

struct ExportedPackage {
  std::vector<ExportedFile> files;  // recruit_controller.{h,c}, recruit_unit.{h,c}, export.json
  std::string summary;              // one line: task, estimator, dT, lambda, precision
};

// The package for `task` with `options` applied (dT, lambda, estimator, filter model). A task
// with "outer_loop": "auto" gets its self-tuned joint loops frozen per reference pose of its
// schedule (export/auto_loop_export.h). Refused with a message naming the task: estimators with
// a covariance mode other than extended, models beyond the C layout's limits (more than 255
// states).
Result<ExportedPackage> ExportController(const sim::Task& task, const sim::RunOptions& options,
                                         Precision precision);

// The unit side alone (no task needed): recruit_unit.h and recruit_unit.c.
std::vector<ExportedFile> UnitPackage();

}  // namespace recruit::exporter
