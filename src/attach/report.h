// What `recruit attach` changed and designed: the printed table and the JSON report.
#pragma once

#include <mujoco/mujoco.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "attach/attach.h"

namespace recruit::attach {

// One line per edit of the model (after the edits, `spec` is the edited spec).
std::vector<std::string> ChangeLines(const AttachReport& report, const mjSpec* spec);
// The design table: per bundle the muscle, force, excursion, wire, units, costs.
std::string DesignTable(const AttachReport& report);
nlohmann::json ReportJson(const AttachReport& report);

}  // namespace recruit::attach
