// Bundle step responses kept between processes: control::PredictBundleResponse is a pure
// function of the chain, its force row and lambda, and a self-tuned run computes one per bundle
// before its loops' designs (~10 M instructions each; a warm 60 s arm run is ~630 M). An entry
// holds every input in full (the exact bits of every field of the chain, of the force row and of
// lambda) with this build's code version, compared byte for byte (no hash is trusted), and the
// response's every number bit for bit; a missing, damaged or foreign entry is a miss. Entries
// live beside the loop designs (control::design_store::Folder: RECRUIT_DESIGN_CACHE=off turns
// both off), written to a temporary sibling and renamed into place.
#pragma once

#include <vector>

#include "common/result.h"
#include "control/actuator_response.h"
#include "estimation/broadcast_transition_model.h"

namespace recruit::sim {

// PredictBundleResponse(chain, force, lambda), from the store when an earlier process of this
// build computed it; a response computed now is stored (errors are not).
Result<control::ActuatorResponse> StoredBundleResponse(
    const estimation::BroadcastTransitionModel& chain, const std::vector<double>& force,
    double lambda);

}  // namespace recruit::sim
