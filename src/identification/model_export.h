// Conversion of an identified TransientChain to the estimation part's FilterModel file.
#pragma once

#include <cstdint>

#include "estimation/filter_model.h"
#include "identification/transient_chain.h"

namespace recruit::identification {

// states = chain.StateNames(), H = chain.force^T (1 x m), R = [force_noise_var],
// R_transit = [transit_noise_var] (N^2 per unit in transit), R_transit2 = [transit2_noise_var]
// (N^2 per squared count of units in transit; both 0: constant R), no process noise,
// transition "broadcast" with the chain's interior, is_on and switching targets (-1 where a switch
// does not apply), dt = dT; x0 = N in "cold", P0 = 0.
estimation::FilterModel ToFilterModel(const TransientChain& chain, std::int64_t num_units,
                                      double dT, double force_noise_var,
                                      double transit_noise_var = 0, double transit2_noise_var = 0);

}  // namespace recruit::identification
