// The C sources of the exported packages (src/export/templates/), embedded at build time by
// src/export/CMakeLists.txt.
#pragma once

namespace recruit::exporter::templates {

extern const char* const kControllerH;  // recruit_controller.h
extern const char* const kControllerC;  // recruit_controller.c
extern const char* const kUnitH;        // recruit_unit.h
extern const char* const kUnitC;        // recruit_unit.c

}  // namespace recruit::exporter::templates
