// Space-filling samples of the unit cube [0, 1)^d for sweeps over many plant parameters: a Latin
// hypercube (each axis cut into n equal strata, one point per stratum) and a Sobol sequence
// (Joe-Kuo direction numbers, randomised by a digital shift that keeps its net property). Both are
// seeded and deterministic: the same (n, d, seed) gives the same points on any machine.
#pragma once

#include <cstdint>
#include <vector>

#include "common/result.h"

namespace recruit::sweep {

using UnitPoints = std::vector<std::vector<double>>;  // [point][dimension], each in [0, 1)

UnitPoints LatinHypercube(int n, int dims, std::uint64_t seed);

// The first n points of the d-dimensional Sobol sequence (d <= MaxSobolDims()), each XORed with a
// seeded random shift per dimension (seed 0: no shift, the plain sequence from the origin).
Result<UnitPoints> Sobol(int n, int dims, std::uint64_t seed);
int MaxSobolDims();

}  // namespace recruit::sweep
