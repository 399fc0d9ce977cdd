#include "sil/sil_hook.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>

namespace recruit::sil {
namespace {

std::string Text(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

Clock::duration Seconds(double s) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

nlohmann::json SilCounters::ToJson() const {
  return {{"instants", instants},
          {"applied", applied},
          {"lost", lost},
          {"late", late},
          {"replayed", replayed},
          {"unexpected", unexpected},
          {"malformed", refused.malformed},
          {"truncated", refused.truncated},
          {"oversized", refused.oversized},
          {"foreign", refused.foreign},
          {"junk_bytes", refused.junk_bytes},
          {"overruns", overruns},
          {"latency_mean_ms", applied > 0 ? 1e3 * latency_sum / applied : 0.0},
          {"latency_max_ms", 1e3 * latency_max}};
}

SilHook::SilHook(Transport& transport, const SilOptions& options, double dT)
    : transport_(transport), options_(options), dT_(dT) {
  // Paced: half a period of wall time; unpaced: a second.
  deadline_ = options.deadline > 0 ? options.deadline
              : options.speed > 0  ? 0.5 * dT / options.speed
                                   : 1.0;
}

Status SilHook::Connect(int bundles) {
  bundles_ = bundles;
  const Clock::time_point until = Clock::now() + Seconds(options_.connect_timeout);
  for (;;) {
    std::optional<Frame> f = transport_.Receive(until, counters_.refused);
    if (!f) {
      timed_out_ = true;
      return Error{"no controller connected within " + Text(options_.connect_timeout) + " s on " +
                   transport_.Describe()};
    }
    if (f->type != FrameType::kHello) {
      ++counters_.unexpected;
      continue;
    }
    if (f->bundles != bundles) {
      return Error{"the controller has " + std::to_string(f->bundles) + " bundle(s), the task " +
                   std::to_string(bundles) +
                   ": export this task's controller (recruit export --task ...)"};
    }
    // The controller's period must be the plant's: its model and gains were made for it.
    if (f->dT != 0 && !(std::abs(f->dT - dT_) <= 1e-9 * dT_)) {
      return Error{"the controller's dT is " + Text(f->dT) + " s, the run's " + Text(dT_) +
                   " s: export with the same --dT"};
    }
    connected_ = true;
    last_.force_reference.assign(bundles, 0.0);
    last_.p_on.assign(bundles, 0.0);
    last_.p_off.assign(bundles, 0.0);
    last_.estimated_on.assign(bundles, 0.0);
    last_.variance.assign(bundles, 0.0);
    start_ = last_heard_ = Clock::now();
    return Status::Ok();
  }
}

void SilHook::Pace(double time) {
  if (options_.speed <= 0) return;
  const Clock::time_point due = start_ + Seconds(time / options_.speed);
  if (Clock::now() > due + Seconds(0.5 * dT_ / options_.speed)) ++counters_.overruns;
  std::this_thread::sleep_until(due);
}

std::optional<Command> SilHook::AwaitCommand(std::uint32_t k, int bundles) {
  const Clock::time_point until = Clock::now() + Seconds(deadline_);
  for (;;) {
    std::optional<Frame> f = transport_.Receive(until, counters_.refused);
    if (!f) return std::nullopt;
    last_heard_ = Clock::now();
    if (f->type != FrameType::kCommand || f->bundles != bundles || f->sequence > k) {
      ++counters_.unexpected;
    } else if (f->sequence < k) {
      ++(applied_[f->sequence] ? counters_.replayed : counters_.late);
    } else {
      return std::move(f->command);
    }
  }
}

void SilHook::Hold(sim::ControlInstant& c) const {
  for (std::size_t i = 0; i < c.broadcast.size(); ++i) {
    c.force_reference[i] = last_.force_reference[i];
    c.broadcast[i] = {last_.p_on[i], last_.p_off[i]};
    c.estimated_on[i] = last_.estimated_on[i];
    c.estimated_on_variance[i] = last_.variance[i];
  }
}

Status SilHook::OnInstant(sim::ControlInstant& c) {
  const int n = static_cast<int>(c.sensed_force.size());
  if (!connected_) {
    if (Status s = Connect(n); !s.ok()) return s;
  }
  const auto k = static_cast<std::uint32_t>(counters_.instants);
  Pace(c.time);
  Measurement m;
  m.sequence = k;
  m.time = c.time;
  m.reference = c.reference;
  m.angle = c.angle;
  m.angular_velocity = c.angular_velocity;
  m.force = c.sensed_force;
  m.length = c.tendon_length;
  const Clock::time_point sent = Clock::now();
  if (Status s = transport_.Send(EncodeMeasurement(m)); !s.ok()) return s;
  ++counters_.instants;
  applied_.push_back(false);
  if (std::optional<Command> cmd = AwaitCommand(k, n)) {
    last_ = std::move(*cmd);
    applied_[k] = true;
    ++counters_.applied;
    const double latency = std::chrono::duration<double>(Clock::now() - sent).count();
    counters_.latency_sum += latency;
    counters_.latency_max = std::max(counters_.latency_max, latency);
  } else {
    ++counters_.lost;
    if (Clock::now() - last_heard_ > Seconds(options_.connect_timeout)) {
      timed_out_ = true;
      return Error{"the controller fell silent for more than " + Text(options_.connect_timeout) +
                   " s on " + transport_.Describe()};
    }
  }
  Hold(c);
  return Status::Ok();
}

void SilHook::Finish() {
  // Also after a refused hello, so that the controller does not wait for measurements; with no
  // controller known (UDP) the send fails, which is fine.
  if (bundles_ > 0) {
    (void)transport_.Send(EncodeEnd(bundles_, static_cast<std::uint32_t>(counters_.instants)));
  }
}

}  // namespace recruit::sil
