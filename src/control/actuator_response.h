// The mean response of a bundle's tension to a step of its force reference, under the
// expectation law at sampling period dT and gain lambda, predicted from the bundle's identified
// population chain (the Kalman filter's model: its broadcast transition model and the force of
// one unit in each state). The outer loop's design (control/loop_design.h) is made on it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "common/result.h"
#include "estimation/broadcast_transition_model.h"

namespace recruit::control {

struct ActuatorResponse {
  double dT = 0;  // s, between samples
  // s[k]: the fraction of a step of the force reference that the tension has made k sampling
  // periods after it (s[0] = 0; tends to 1).
  std::vector<double> s;
  // The same for a step the other way (the reference stepped back down, units released and
  // cooling; PredictBundleResponse), when it differs from s; empty: the same as s.
  std::vector<double> release;

  // Linear interpolation between samples; 1 after the last. Inline: the loop design calls it
  // millions of times per joint (control::PredictStep), and an out-of-line call kept those
  // calls' divisions from overlapping.
  double At(double t) const {
    if (s.empty()) return 1;
    const double k = Quotient(t, dT);
    if (k <= 0) return s.front();
    const size_t i = static_cast<size_t>(k);
    if (i + 1 >= s.size()) return s.back();
    const double f = k - i;
    return s[i] + f * (s[i + 1] - s[i]);
  }
  // The first time the response reaches `fraction` (linear between samples).
  double TimeTo(double fraction) const;
  // The response to a step the other way (`release` as s, or s when there is none), and this
  // one with its two directions swapped.
  ActuatorResponse Released() const;
  ActuatorResponse Reversed() const;

  // t / d, bit for bit. When d is a power of two (dT is 0.5, 1 or 2 s in every shipped task)
  // its reciprocal 2^-n is exact, and t * 2^-n and t / 2^n are both the correctly rounded value
  // of the same real number: a multiplication where a division costs several times as long.
  static double Quotient(double t, double d) {
    std::uint64_t bits;
    std::memcpy(&bits, &d, sizeof bits);
    constexpr std::uint64_t kMantissa = (std::uint64_t{1} << 52) - 1;
    const std::uint64_t exponent = (bits >> 52) & 0x7ff;
    // A normal power of two whose reciprocal is normal too (biased exponent 2046 - e).
    if ((bits & kMantissa) == 0 && exponent >= 1 && exponent <= 2045) {
      const std::uint64_t inverse_bits = (bits & (std::uint64_t{1} << 63)) | (2046 - exponent)
                                                                                 << 52;
      double inverse;
      std::memcpy(&inverse, &inverse_bits, sizeof inverse);
      return t * inverse;
    }
    return t / d;
  }
};

// The chain's expected state (fractions of units per state) starts settled at `from` of the
// settled on-force, the reference then steps to `to` (both in (0, 1)); the expectation law acts
// on the chain's own on-fraction (a perfect estimate). `force` gives one unit's tension in each
// state (the model's H row at the working length). Stops when the remaining error is below
// 1e-4 of the step, or after `max_samples`.
Result<ActuatorResponse> PredictActuatorResponse(const estimation::BroadcastTransitionModel& chain,
                                                 const std::vector<double>& force, double lambda,
                                                 double from = 0.25, double to = 0.5,
                                                 int max_samples = 1000);

// A bundle's response both ways under the law: the rise from 0.25 to 0.5 of the settled on-force
// (s) and the release from 0.5 back to 0.25 (release). The identified chains of the project's
// limbs release within 0.6-1.12x the rise's time to 63 %, some with one more sampling period of
// dead time (the elbow arm's flexor at dT 1 s: docs/controller.md).
Result<ActuatorResponse> PredictBundleResponse(const estimation::BroadcastTransitionModel& chain,
                                               const std::vector<double>& force, double lambda);

// Without a usable chain: the expected on-count's approach under the law, 1 - (1 - lambda)^k at
// the control instants (held between them), through a first-order thermal lag of time constant
// `tau` (s; the unit's, UnitModel::time_constant).
ActuatorResponse FirstOrderActuatorResponse(double dT, double lambda, double tau,
                                            int max_samples = 1000);

}  // namespace recruit::control
