#include "estimation/population_kalman_filter.h"

#include "common/short_text.h"
#include "estimation/json_matrix.h"

namespace recruit::estimation {

const char* ToString(CovarianceMode mode) {
  switch (mode) {
    case CovarianceMode::kExtended:
      return "extended";
    case CovarianceMode::kConservative:
      return "conservative";
    case CovarianceMode::kPlain:
      return "plain";
  }
  return "?";
}

Result<CovarianceMode> ParseCovarianceMode(const std::string& name) {
  if (name == "extended") return CovarianceMode::kExtended;
  if (name == "conservative") return CovarianceMode::kConservative;
  if (name == "plain") return CovarianceMode::kPlain;
  return Error{"covariance mode '" + ShortText(name) +
               "' is not one of extended, conservative, plain"};
}

// The dynamic-size filter and the common small sizes are compiled once here.
template class PopulationKalmanFilterT<Eigen::Dynamic, Eigen::Dynamic>;
template class PopulationKalmanFilterT<2, 1>;
template class PopulationKalmanFilterT<3, 1>;
template class PopulationKalmanFilterT<20, 1>;

}  // namespace recruit::estimation
