// Figures of chosen columns of any numeric CSV (`recruit plot --panel`), for tables that are not
// a `recruit simulate` run, e.g. the Fig. 4 step of sma_fig4_step. Pure: data in, Figure out.
#pragma once

#include <string>
#include <vector>

#include "common/result.h"
#include "plot/figure.h"
#include "plot/run_data.h"

namespace recruit::plot {

struct ColumnRef {
  std::string column;
  double scale = 1;  // the column is plotted times this
};

struct PanelSpec {
  std::string y_label;  // with the unit, e.g. "force (N)"
  std::vector<ColumnRef> columns;
};

// "LABEL=COL[*SCALE][,COL[*SCALE]...]", e.g. "force (N)=tension,on*0.5". Errors quote the spec.
Result<PanelSpec> ParsePanelSpec(const std::string& spec);

// One panel per spec, x from column `x`; series named after their column (with " x SCALE" when
// scaled). Unknown columns are errors that list the table's columns.
Result<Figure> MakeColumnFigure(const RunCsv& table, const std::string& x,
                                const std::string& x_label, const std::vector<PanelSpec>& panels,
                                const std::string& title);

}  // namespace recruit::plot
