#include "control/recruitment_controller.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "control/failure_estimator.h"

namespace recruit::control {

Status ControllerParams::Validate() const {
  if (num_units < 1) {
    return Error{"controller: num_units = " + std::to_string(num_units) + " must be >= 1"};
  }
  if (!std::isfinite(unit_force) || unit_force <= 0) {
    return Error{"controller: unit_force = " + std::to_string(unit_force) +
                 " N must be finite and > 0"};
  }
  RECRUIT_TRY(CheckDT(dT, "controller"));
  if (!std::isfinite(lambda) || lambda <= 0 || lambda > 1) {
    return Error{"controller: lambda = " + std::to_string(lambda) + " must be in (0, 1]"};
  }
  const ExplorationParams& e = exploration;
  if (!std::isfinite(e.p_on) || e.p_on < 0 || e.p_on > 1) {
    return Error{"controller: exploration.p_on = " + std::to_string(e.p_on) + " must be in [0, 1]"};
  }
  if (e.unmeasured < 0 || e.unmeasured > e.instants) {
    return Error{"controller: exploration.unmeasured = " + std::to_string(e.unmeasured) +
                 " must be in [0, instants]"};
  }
  if (e.instants < 1) {
    return Error{"controller: exploration.instants = " + std::to_string(e.instants) +
                 " must be >= 1"};
  }
  if (!std::isfinite(e.suspicion) || e.suspicion < 0) {
    return Error{"controller: exploration.suspicion = " + std::to_string(e.suspicion) +
                 " must be finite and >= 0"};
  }
  if (!std::isfinite(e.period) || e.period < 0) {
    return Error{"controller: exploration.period = " + std::to_string(e.period) +
                 " s must be finite and >= 0"};
  }
  if (!std::isfinite(census_period) || census_period < 0) {
    return Error{"controller: census_period = " + std::to_string(census_period) +
                 " s must be finite and >= 0"};
  }
  return Status::Ok();
}

Result<RecruitmentController> RecruitmentController::Create(
    const ControllerParams& params, std::unique_ptr<OnCountEstimator> estimator) {
  if (Status s = params.Validate(); !s) return Error{s.error(), s.code()};
  if (!estimator) return Error{"controller: no estimator"};
  if (params.census_period > 0 && !dynamic_cast<FailureOnCountEstimator*>(estimator.get())) {
    return Error{"controller: census_period = " + std::to_string(params.census_period) +
                 " s needs the failure-aware estimator (kalman-failures)"};
  }
  std::optional<UnitForceMap> on_force;
  if (params.geometry) {
    auto map = UnitForceMap::FromForces(*params.geometry, params.geometry->unit.prestretch,
                                        Eigen::VectorXd::Constant(1, params.unit_force));
    if (!map) return Error{"controller: " + map.error(), map.code()};
    on_force = std::move(map).value();
  }
  RecruitmentController c(params, std::move(estimator), std::move(on_force));
  c.Reset();
  return c;
}

Result<RecruitmentController> RecruitmentController::Create(const ControllerParams& params,
                                                            const EstimatorSpec& spec) {
  if (Status s = params.Validate(); !s) return Error{s.error(), s.code()};
  auto est = MakeEstimator(spec, params.num_units, params.unit_force, params.dT,
                           params.geometry ? &*params.geometry : nullptr);
  if (!est) return Error{est.error(), est.code()};
  return Create(params, std::move(est).value());
}

void RecruitmentController::Reset() {
  estimator_->Reset();
  target_on_ = 0;
  unit_force_ = params_.unit_force;
  estimated_on_ = estimator_->EstimatedOn();
  estimated_on_variance_ = estimator_->EstimatedOnVariance();
  estimated_working_ = params_.num_units;
  saturation_ = 0;
  explore_left_ = 0;
  rest_left_ = 0;
  unmeasured_left_ = 0;
  since_period_ = 0;
  exploring_ = false;
  instants_ = 0;
  census_ = false;
  last_ = Broadcast{};
}

void RecruitmentController::Census(double conducting, double stuck, double variance) {
  if (auto* f = dynamic_cast<FailureOnCountEstimator*>(estimator_.get())) {
    f->UpdateWithCensus(conducting, stuck, variance);
  }
}

double RecruitmentController::OnUnitForce(double tendon_length) const {
  return on_force_ && std::isfinite(tendon_length) ? on_force_->Force(0, tendon_length)
                                                   : params_.unit_force;
}

Broadcast RecruitmentController::Step(double reference_force, double measured_force,
                                      double tendon_length) {
  // While an exploration's switched units are in transient (ExplorationParams::unmeasured) the
  // estimator predicts through it without the force.
  const bool skip = unmeasured_left_ > 0;
  if (skip) --unmeasured_left_;
  estimator_->UpdateWithMeasurement(
      skip ? std::numeric_limits<double>::quiet_NaN() : measured_force, tendon_length);
  unit_force_ = OnUnitForce(tendon_length);
  // Where no on unit can pull (a slack tendon) no count reaches the reference: ask for all.
  target_on_ = unit_force_ > 0 ? reference_force / unit_force_
                               : (reference_force > 0 ? params_.num_units : 0.0);
  estimated_on_ = estimator_->EstimatedOn();
  estimated_on_variance_ = estimator_->EstimatedOnVariance();
  if (const auto f = estimator_->Failures()) {
    last_ = FailureAwareLaw(*f);
    if (params_.exploration.p_on > 0) last_ = Explore(last_, *f);
  } else {
    // More than every unit asked for: the bundle beyond its capacity (the run's summary says so).
    saturation_ = target_on_ > params_.num_units ? 1 : 0;
    last_ = ExpectationLaw(target_on_, estimated_on_, params_.num_units, params_.lambda);
  }
  estimator_->Broadcasted(last_);
  ++instants_;
  if (params_.census_period > 0) {
    const long period = std::max(1L, std::lround(params_.census_period / params_.dT));
    census_ = instants_ % period == 0;
  }
  return last_;
}

Broadcast RecruitmentController::FailureAwareLaw(const FailureEstimate& f) {
  const double n = params_.num_units;
  const double stuck = std::clamp(f.stuck, 0.0, n);
  const double working = std::clamp(f.working, 0.0, n - stuck);
  estimated_working_ = working;
  // The working units must make up what the stuck ones do not, each pulling the estimated
  // fraction c of a fresh unit (functional fatigue; c = 1 unless estimated).
  const double c = f.force_scale > 0 ? f.force_scale : 1.0;
  const double target = (target_on_ - stuck) / c;  // exact for c = 1 (IEEE division by 1)
  saturation_ = target > working ? 1 : (target < 0 ? -1 : 0);
  return ExpectationLaw(target, estimated_on_ - stuck, working, params_.lambda);
}

Broadcast RecruitmentController::Explore(const Broadcast& law, const FailureEstimate& f) {
  const ExplorationParams& e = params_.exploration;
  const long period = e.period > 0 ? std::max(1L, std::lround(e.period / params_.dT)) : 0;
  const bool periodic = period > 0 && ++since_period_ >= period;
  if (periodic) since_period_ = 0;
  const bool triggered = (e.after_declaration && f.declared) ||
                         (e.suspicion > 0 && f.suspicion >= e.suspicion) || periodic;
  if (explore_left_ == 0 && rest_left_ > 0) {
    --rest_left_;  // resting: triggers are ignored
  } else if (triggered && explore_left_ == 0) {
    explore_left_ = e.instants;
  }
  exploring_ = explore_left_ > 0;
  if (!exploring_) return law;
  const bool first = explore_left_ == e.instants;
  if (first) unmeasured_left_ = e.unmeasured;
  if (--explore_left_ == 0) rest_left_ = e.rest;
  // Toggle: every unit switches with p_on at the first instant, then nothing switches so the
  // switched units settle (the chain's transients are least exact for a synchronised cohort).
  if (!e.balanced) return first ? Broadcast{e.p_on, e.p_on} : Broadcast{};
  // The working units the broadcast reaches: on ones (the stuck ones ignore it) and off ones.
  const double on = std::max(0.0, estimated_on_ - std::max(0.0, f.stuck));
  const double off = std::max(0.0, estimated_working_ - on);
  return ExplorationLaw(law, on, off, e.p_on);
}

}  // namespace recruit::control
