// Writes the worked example of docs/formats/filter.md into a directory (models/filter/ in the
// repository): a three-state filter model, a simulated log of broadcasts and force measurements
// (every fifth measurement missing) and the simulated truth. Deterministic (seed 2010).
//   build/tests/estimation/estimation_make_filter_example models/filter
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>

#include "common/atomic_file.h"
#include "common/rng.h"
#include "estimation/population_chain.h"
#include "test_util.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: " << argv[0] << " OUTPUT_DIR\n";
    return 2;
  }
  const std::string dir = argv[1];
  using namespace recruit;
  estimation::FilterModel f = testing_util::ThreeStateModel(60, 0.3);
  if (Status s = f.Save(dir + "/three_state_model.json"); !s.ok()) {
    std::cerr << s.error() << "\n";
    return 1;
  }
  Rng rng(2010);
  std::ostringstream log, truth;
  log << "t,p_on,p_off,y\n";
  truth << "step,t,n_off,n_warming,n_on\n";
  Eigen::VectorXd x = f.x0;
  const int steps = 80;
  char buf[160];
  for (int k = 0; k < steps; ++k) {
    const double t = k * f.broadcast.dt;
    // Open-loop broadcasts: recruit, hold, release, recruit half.
    const int phase = k / 20;
    const double p_on = phase == 0 ? 0.2 : (phase == 1 ? 0.03 : (phase == 2 ? 0.0 : 0.08));
    const double p_off = phase == 0 ? 0.0 : (phase == 1 ? 0.03 : (phase == 2 ? 0.2 : 0.06));
    std::string y = "";
    if (k % 5 != 4) {
      std::snprintf(buf, sizeof buf, "%.4f", testing_util::Measure(f, x, rng)(0));
      y = buf;
    }
    if (k + 1 < steps) {
      std::snprintf(buf, sizeof buf, "%.1f,%.2f,%.2f,%s\n", t, p_on, p_off, y.c_str());
    } else {
      std::snprintf(buf, sizeof buf, "%.1f,,,%s\n", t, y.c_str());  // last row: no inputs
    }
    log << buf;
    std::snprintf(buf, sizeof buf, "%d,%.1f,%g,%g,%g\n", k, t, x(0), x(1), x(2));
    truth << buf;
    x = estimation::SimulateStepAggregate(f.broadcast.Matrix(p_on, p_off), x, rng);
  }
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"three_state_log.csv", log.str()},
        {"three_state_truth.csv", truth.str()}}) {
    if (Status s = WriteFileAtomically(dir + "/" + name, text); !s.ok()) {
      std::cerr << s.error() << "\n";
      return 1;
    }
  }
  return 0;
}
