// The plant's side of `recruit sil` (docs/sil.md): a ControlInstantHook that, at each control
// instant of RunTask, paces the run against the wall clock, sends the measurement frame to the
// controller and applies the command frame it answers with. The plant and the metrics are
// RunTask's, as in `recruit simulate`.
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "sil/transport.h"
#include "sim/run_task.h"

namespace recruit::sil {

struct SilOptions {
  double speed = 1;             // simulated s per wall s; 0: as fast as the controller answers
  double deadline = 0;          // wall s an answer may take after its measurement; 0: default
  double connect_timeout = 10;  // wall s to wait for the hello, and the longest silence after
};

// What the run saw on the link.
struct SilCounters {
  long instants = 0;    // measurements sent
  long applied = 0;     // instants whose own command arrived in time
  long lost = 0;        // instants without one by the deadline: the last command held
  long late = 0;        // commands for an earlier instant that had none in time (dropped)
  long replayed = 0;    // commands for an instant already applied (dropped)
  long unexpected = 0;  // valid frames out of place: a future instant, another bundle count, a
                        // frame type the controller does not send (dropped)
  long overruns = 0;    // instants the plant reached after their wall-clock time (paced runs)
  double latency_sum = 0, latency_max = 0;  // wall s from a measurement to its applied answer
  Refused refused;
  nlohmann::json ToJson() const;
};

class SilHook : public sim::ControlInstantHook {
 public:
  // `dT`: the run's control period (s), for pacing and the default deadline.
  SilHook(Transport& transport, const SilOptions& options, double dT);
  bool Replaces() const override { return true; }
  Status OnInstant(sim::ControlInstant& instant) override;
  // Tells the controller the run is over (the end frame), also when it ended in an error.
  void Finish();

  const SilCounters& counters() const { return counters_; }
  // The controller never said hello, or fell silent longer than connect_timeout.
  bool timed_out() const { return timed_out_; }
  double deadline() const { return deadline_; }

 private:
  Status Connect(int bundles);
  void Pace(double time);
  std::optional<Command> AwaitCommand(std::uint32_t k, int bundles);
  void Hold(sim::ControlInstant& instant) const;

  Transport& transport_;
  SilOptions options_;
  double dT_, deadline_;
  SilCounters counters_;
  bool connected_ = false, timed_out_ = false;
  int bundles_ = 0;  // known once the first instant is reached
  Clock::time_point start_, last_heard_;
  std::vector<bool> applied_;  // per instant
  Command last_;               // held on loss; before the first: p_on = p_off = 0
};

}  // namespace recruit::sil
