// The paper-style figures of one run (docs/plotting.md): tracked quantity vs reference, true vs
// estimated on-count with the filter's +-2 sd band, broadcast probabilities, mean unit
// temperature; and all four stacked in one figure. Pure: data in, Figure out.
#pragma once

#include <string>
#include <vector>

#include "plot/figure.h"
#include "plot/run_data.h"

namespace recruit::plot {

struct NamedFigure {
  // File name part: tracking, forces (angle tasks only), count, broadcast, temperature, all.
  std::string name;
  Figure figure;
};

// True for an angle task: the summary says "rad", or (without one) `measured` equals `angle`
// on every row and is not all zero (a force task measures the force, not the joint angle).
bool IsAngleRun(const RunCsv& csv, const RunInfo& info);

Axes TrackingAxes(const RunCsv& csv, bool angle);
Axes ForceAxes(const RunCsv& csv);  // each bundle's force and force reference
Axes CountAxes(const RunCsv& csv);
Axes BroadcastAxes(const RunCsv& csv);
Axes TemperatureAxes(const RunCsv& csv);

// The single figures and the combined one (all panels stacked), titled with TitleOf(info).
std::vector<NamedFigure> MakeRunFigures(const RunCsv& csv, const RunInfo& info);

}  // namespace recruit::plot
