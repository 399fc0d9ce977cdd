#include "identification/model_export.h"

namespace recruit::identification {

estimation::FilterModel ToFilterModel(const TransientChain& chain, std::int64_t num_units,
                                      double dT, double force_noise_var, double transit_noise_var,
                                      double transit2_noise_var) {
  const int m = chain.num_states();
  estimation::FilterModel f;
  f.state_names = chain.StateNames();
  f.N = num_units;
  f.H = chain.force.transpose();
  f.R = Eigen::MatrixXd::Constant(1, 1, force_noise_var);
  f.R_transit = Eigen::MatrixXd::Constant(1, 1, transit_noise_var);
  f.R_transit2 = Eigen::MatrixXd::Constant(1, 1, transit2_noise_var);
  f.G = Eigen::MatrixXd::Zero(m, 0);
  f.Qw = Eigen::MatrixXd::Zero(0, 0);
  f.transition = estimation::TransitionSource::kBroadcast;
  estimation::BroadcastTransitionModel& b = f.broadcast;
  b.state_names = f.state_names;
  b.is_on = chain.IsOn();
  b.interior = chain.Interior();
  b.on_target = chain.switch_on;
  b.off_target = chain.switch_off;
  b.dt = dT;
  f.x0 = Eigen::VectorXd::Zero(m);
  f.x0[chain.cold()] = static_cast<double>(num_units);
  f.P0 = Eigen::MatrixXd::Zero(m, m);
  return f;
}

}  // namespace recruit::identification
