// Centre scheduler of the GNSS-time pre-armed crossings (spec/design/lc.md §5).
// Seeded fault (negative test; the model mirrors it as a mutant), active only in the test-only
// schemata variant (spec/design/seeded-faults.md):
//   FAULT_LC_DEPART_WITHOUT_ALL_ACKS  the departure is cleared with one acknowledgement missing
//
// The earliest arrival is lc::EarliestArrivalMs (the common part railproof_lc_common): the centre and the
// train predict with the same function.
#include "railproof/core/seeded_fault.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"

namespace railproof::lc::wayside {

namespace {

// The range checks of times and positions are lc::ClockOk and lc::PositionOk (common part).

// @implements REQ-LC-008 REQ-LC-010
// st = t + eta - warning_time - allowance (design §5 steps 1 and 4), eta finite.
// Magnitudes: |t| <= 1e15, eta <= ~1e14 (accel >= 1, distances <= 2e10 mm), warning time and
// allowance <= 3.6e6: no overflow.
std::int64_t StartTime(std::int64_t t_ms, std::int64_t eta_ms, std::int64_t warning_time_ms,
                       std::int64_t allowance_ms) noexcept {
  return t_ms + eta_ms - warning_time_ms - allowance_ms;
}

}  // namespace

// @implements REQ-LC-008 REQ-LC-013
SchedulerConfig DefaultSchedulerConfig(std::int64_t accel_max_mm_s2) noexcept {
  SchedulerConfig c;
  c.accel_max_mm_s2 = accel_max_mm_s2;
  return c;
}

// @implements REQ-LC-008
CentreScheduler::CreateResult CentreScheduler::Create(const SchedulerConfig& config) noexcept {
  CreateResult r;
  if (config.accel_max_mm_s2 < 1 || config.accel_max_mm_s2 > core::kMaxAccelerationMmS2 ||
      config.clock_allowance_ms < 0 || config.clock_allowance_ms > lc::kMaxWarningTimeMs) {
    r.error = SchedulerError::kConfigInvalid;
    return r;
  }
  r.scheduler = CentreScheduler(config);
  r.scheduler->ComputeOutputs(0);
  return r;
}

// @implements REQ-LC-008
const ScheduledCrossing* CentreScheduler::Find(std::uint32_t crossing_id) const noexcept {
  return FindCrossing(std::span<const ScheduledCrossing>(crossings_.data(), count_), crossing_id);
}

// @implements REQ-LC-008
ScheduledCrossing* CentreScheduler::FindMutable(std::uint32_t crossing_id) noexcept {
  return FindCrossing(std::span<ScheduledCrossing>(crossings_.data(), count_), crossing_id);
}

// Design §5 step 1 (REQ-LC-008).
// @implements REQ-LC-008 REQ-LC-009
SchedulerError CentreScheduler::StartDeparture(const Departure& departure,
                                               std::span<const CrossingData> crossings,
                                               std::span<const core::RestrictionSegment> restrictions,
                                               std::int64_t now_ms) noexcept {
  SchedulerError error = SchedulerError::kNone;
  crossing_error_ = {};
  if (!ClockOk(now_ms) || !ClockOk(departure.departure_ms)) {
    error = SchedulerError::kTimeInvalid;
  } else if (last_now_.has_value() && now_ms < *last_now_) {
    error = SchedulerError::kTimeWentBack;
  } else if (!PositionOk(departure.front_mm)) {
    error = SchedulerError::kPositionInvalid;
  } else {
    crossing_error_ = lc::ValidateCrossings(crossings);
    if (crossing_error_.error != lc::CrossingDataError::kNone) {
      error = SchedulerError::kCrossingDataInvalid;
    } else if (lc::EarliestArrivalMs(0, 0, 0, 0, restrictions).error != lc::EtaError::kNone) {
      error = SchedulerError::kProfileInvalid;
    }
  }
  if (error != SchedulerError::kNone) {
    // a refused departure leaves none held (never the old one: its acks are not this one's)
    departure_.reset();
    count_ = 0;
    ComputeOutputs(last_now_.value_or(0));
    return error;
  }
  last_now_ = now_ms;
  departure_ = departure;
  tracked_front_mm_ = departure.front_mm;
  count_ = 0;
  for (const CrossingData& c : crossings) {
    const lc::EtaResult eta =
        lc::EarliestArrivalMs(departure.front_mm, c.near_mm, 0, config_.accel_max_mm_s2, restrictions);
    ScheduledCrossing sc;
    sc.data = c;
    sc.initial_start_ms = StartTime(departure.departure_ms, eta.eta_ms, c.warning_time_ms,
                                    config_.clock_allowance_ms);
    sc.start_ms = sc.initial_start_ms;
    sc.start_pending = true;
    crossings_[count_] = sc;
    ++count_;
  }
  ComputeOutputs(now_ms);
  return SchedulerError::kNone;
}

// Design §5 step 3 and the messages (REQ-LC-009, REQ-LC-013).
// @implements REQ-LC-008 REQ-LC-009 REQ-LC-010 REQ-LC-012 REQ-LC-013
void CentreScheduler::ComputeOutputs(std::int64_t now_ms) noexcept {
  SchedulerOutput& o = output_;
  o.start_time_count = 0;
  o.warning_stop_count = 0;
  o.departure_cleared = false;
  if (!departure_.has_value()) {
    o.block = DepartureBlock::kNoDeparture;
    return;
  }
  std::size_t missing = 0;
  bool clock_fault = false;
  for (std::size_t i = 0; i < count_; ++i) {
    const ScheduledCrossing& c = crossings_[i];
    if (c.start_pending && !c.passed) {
      o.start_times[o.start_time_count++] = StartTimeMessage{c.data.id, departure_->departure_id, c.start_ms};
    }
    if (c.stop_pending) {
      o.warning_stops[o.warning_stop_count++] = WarningStopMessage{c.data.id, departure_->departure_id};
    }
    missing += c.acked ? 0U : 1U;
    clock_fault = clock_fault || c.clock_fault;
  }
  const bool all_acked = RAILPROOF_FAULT(FAULT_LC_DEPART_WITHOUT_ALL_ACKS) ? missing <= 1 : missing == 0;
  if (!all_acked) {
    o.block = DepartureBlock::kMissingAck;
  } else if (clock_fault) {
    o.block = DepartureBlock::kClockFault;
  } else if (now_ms < departure_->departure_ms) {
    o.block = DepartureBlock::kBeforeDeparture;
  } else {
    o.block = DepartureBlock::kNone;
    o.departure_cleared = true;
  }
}

// @implements REQ-LC-008 REQ-LC-009 REQ-LC-010 REQ-LC-012 REQ-LC-013 REQ-LC-014
SchedulerError CentreScheduler::Cycle(const SchedulerInput& in) noexcept {
  SchedulerError error = SchedulerError::kNone;
  if (!departure_.has_value()) {
    error = SchedulerError::kNoDeparture;
  } else if (!ClockOk(in.now_ms)) {
    error = SchedulerError::kTimeInvalid;
  } else if (last_now_.has_value() && in.now_ms < *last_now_) {
    error = SchedulerError::kTimeWentBack;
  } else if (in.start_acks.size() > kMaxSchedulerMessages || in.stop_acks.size() > kMaxSchedulerMessages ||
             in.reports.size() > kMaxSchedulerMessages) {
    error = SchedulerError::kTooManyMessages;
  } else if (lc::EarliestArrivalMs(0, 0, 0, 0, in.restrictions).error != lc::EtaError::kNone) {
    error = SchedulerError::kProfileInvalid;
  } else if (in.position.has_value() && in.position->train_id == departure_->train_id) {
    const CentrePositionReport& p = *in.position;
    if (!ClockOk(p.time_ms)) {
      error = SchedulerError::kTimeInvalid;
    } else if (!PositionOk(p.front_mm) || !PositionOk(p.rear_mm) || p.rear_mm > p.front_mm) {
      error = SchedulerError::kPositionInvalid;
    } else if (p.speed_mm_s < 0 || p.speed_mm_s > core::kMaxMeasuredSpeedMmS) {
      error = SchedulerError::kSpeedInvalid;
    }
  }
  output_.ignored_messages = 0;
  output_.report_rejected = false;
  if (error != SchedulerError::kNone) {
    ComputeOutputs(last_now_.value_or(0));
    return error;
  }
  const std::int64_t now = in.now_ms;
  last_now_ = now;
  const Departure& dep = *departure_;
  std::size_t ignored = 0;

  // 1. Clock faults (REQ-LC-013).
  for (const CrossingReport& r : in.reports) {
    ScheduledCrossing* c = FindMutable(r.crossing_id);
    if (c == nullptr) {
      ++ignored;
      continue;
    }
    c->clock_fault = r.clock_fault;
  }
  // 2. Acknowledgements (REQ-LC-009, REQ-LC-010, REQ-LC-012).
  for (const StartTimeAck& a : in.start_acks) {
    ScheduledCrossing* c = FindMutable(a.crossing_id);
    if (c == nullptr || a.departure_id != dep.departure_id || !a.stored) {
      ++ignored;
      continue;
    }
    if (a.start_ms <= c->initial_start_ms) {
      c->acked = true;
    }
    c->acked_start_ms = a.start_ms;
    if (a.start_ms <= c->start_ms) {
      c->start_pending = false;
    }
  }
  for (const WarningStopAck& a : in.stop_acks) {
    ScheduledCrossing* c = FindMutable(a.crossing_id);
    if (c == nullptr || a.departure_id != dep.departure_id) {
      ++ignored;
      continue;
    }
    if (c->stop_pending) {
      c->stop_pending = false;
      c->stop_acked = true;
    }
  }
  // 3. Position report: tracking plausibility, passage, recomputation (REQ-LC-010, REQ-LC-012).
  if (in.position.has_value()) {
    const CentrePositionReport& p = *in.position;
    if (p.train_id != dep.train_id) {
      ++ignored;
    } else if (p.front_mm < tracked_front_mm_ || p.time_ms > now) {
      output_.report_rejected = true;
    } else {
      tracked_front_mm_ = p.front_mm;
      for (std::size_t i = 0; i < count_; ++i) {
        ScheduledCrossing& c = crossings_[i];
        if (c.passed) {
          continue;
        }
        if (p.rear_mm >= c.data.far_mm) {
          c.passed = true;
          c.stop_pending = true;
          c.start_pending = false;
          continue;
        }
        const bool dwell = p.speed_mm_s == 0 && p.time_ms < dep.departure_ms;
        const lc::EtaResult eta =
            dwell ? lc::EarliestArrivalAfterDwellMs(p.time_ms, dep.departure_ms, p.front_mm,
                                                         c.data.near_mm, config_.accel_max_mm_s2,
                                                         in.restrictions)
                  : lc::EarliestArrivalMs(p.front_mm, c.data.near_mm, p.speed_mm_s,
                                               config_.accel_max_mm_s2, in.restrictions);
        if (eta.error != lc::EtaError::kNone || eta.eta_ms == lc::kEtaNeverMs) {
          continue;  // GCOVR_EXCL_LINE defensive: inputs validated, accel >= 1
        }
        const std::int64_t st =
            StartTime(p.time_ms, eta.eta_ms, c.data.warning_time_ms, config_.clock_allowance_ms);
        if (st != c.start_ms) {
          c.start_ms = st;
          c.start_pending = true;
        }
      }
    }
  }
  ComputeOutputs(now);
  output_.ignored_messages = ignored;
  return SchedulerError::kNone;
}

}  // namespace railproof::lc::wayside
