// Level-crossing controller (spec/design/lc.md §4, §5 step 2, clock rule).
// Seeded faults (negative tests; the model mirrors them as mutants), active only in the
// test-only schemata variant (spec/design/seeded-faults.md):
//   FAULT_LC_END_WITH_REQUESTER          a withdrawal removes every requester (the warning
//                                        ends when one of two requesters withdrew)
//   FAULT_LC_LATER_UPDATE_WHILE_WARNING  a later start time is stored although the warning
//                                        for the departure has started
#include "railproof/core/seeded_fault.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"

namespace railproof::lc::wayside {

// The range check of times is lc::ClockOk (common part).

// @implements REQ-LC-006 REQ-LC-007 REQ-LC-013
ControllerConfig DefaultControllerConfig(std::uint32_t crossing_id) noexcept {
  ControllerConfig c;
  c.crossing_id = crossing_id;
  return c;
}

// @implements REQ-LC-006 REQ-LC-007 REQ-LC-013
CrossingController::CreateResult CrossingController::Create(const ControllerConfig& config) noexcept {
  CreateResult r;
  if (config.barrier_lowering_ms < 0 || config.barrier_lowering_ms > lc::kMaxWarningTimeMs ||
      config.barrier_timeout_ms < 1 || config.barrier_timeout_ms > lc::kMaxWarningTimeMs ||
      config.max_warning_ms < 1 || config.max_warning_ms > lc::kMaxClockMs ||
      config.holdover_max_ms < 0 || config.holdover_max_ms > lc::kMaxClockMs) {
    r.error = ControllerError::kConfigInvalid;
    return r;
  }
  r.controller = CrossingController(config);
  r.controller->ComputeOutputs(0);
  return r;
}

// @implements REQ-LC-006 REQ-LC-014
void CrossingController::MaintenanceReset() noexcept {
  status_.state = ControllerState::kOpen;
  status_.failure = FailureReason::kNone;
  status_.alarm = false;
  status_.clock = ClockState::kSynchronised;
  status_.outage_start_ms = 0;
  status_.requester_overflow = false;
  ComputeOutputs(status_.last_cycle_ms.value_or(0));
}

// The report and the commands from the state (design §4).
// @implements REQ-LC-006 REQ-LC-007 REQ-LC-013
void CrossingController::ComputeOutputs(std::int64_t now_ms) noexcept {
  ControllerOutput& o = output_;
  o.report.crossing_id = config_.crossing_id;
  o.report.issued_ms = now_ms;
  o.report.clock_fault = status_.clock == ClockState::kFaulty;
  o.report.warning_start_ms = status_.warning_start_ms;
  o.report.requesters = status_.requesters;
  o.report.requester_count = status_.requester_count;
  switch (status_.state) {
    case ControllerState::kOpen:
    case ControllerState::kOpening:
      o.report.status = CrossingStatus::kOpen;
      o.report.warning_start_ms = 0;
      break;
    case ControllerState::kWarning:
    case ControllerState::kClosing:
      o.report.status = CrossingStatus::kWarning;
      break;
    case ControllerState::kClosed:
      o.report.status = CrossingStatus::kClosed;
      break;
    case ControllerState::kFailed:
      o.report.status = CrossingStatus::kFailed;
      break;
  }
  o.lights_on = status_.state != ControllerState::kOpen;
  o.barriers_down_commanded = status_.state == ControllerState::kClosing ||
                              status_.state == ControllerState::kClosed ||
                              status_.state == ControllerState::kFailed;
  o.alarm = status_.alarm;
}

// @implements REQ-LC-006 REQ-LC-007 REQ-LC-009 REQ-LC-010 REQ-LC-011 REQ-LC-013 REQ-LC-014
ControllerError CrossingController::Cycle(const ControllerInput& in) noexcept {
  ControllerError error = ControllerError::kNone;
  if (!ClockOk(in.now_ms)) {
    error = ControllerError::kTimeInvalid;
  } else if (status_.last_cycle_ms.has_value() && in.now_ms < *status_.last_cycle_ms) {
    error = ControllerError::kTimeWentBack;
  } else if (in.requests.size() > kMaxControllerMessages ||
             in.withdrawals.size() > kMaxControllerMessages ||
             in.start_times.size() > kMaxControllerMessages ||
             in.warning_stops.size() > kMaxControllerMessages) {
    error = ControllerError::kTooManyMessages;
  } else {
    for (const StartTimeMessage& m : in.start_times) {
      if (!ClockOk(m.start_ms)) {
        error = ControllerError::kTimeInvalid;
      }
    }
  }
  output_.withdrawal_ack_count = 0;
  output_.start_ack_count = 0;
  output_.stop_ack_count = 0;
  output_.ignored_messages = 0;
  if (error != ControllerError::kNone) {
    ComputeOutputs(status_.last_cycle_ms.value_or(0));
    return error;
  }
  const std::int64_t now = in.now_ms;
  ControllerStatus& s = status_;
  s.last_cycle_ms = now;

  // 1. Clock (REQ-LC-013).
  switch (in.clock) {
    case ClockInput::kFault:
      s.clock = ClockState::kFaulty;
      break;
    case ClockInput::kNoGnss:
      if (s.clock == ClockState::kSynchronised) {
        s.clock = ClockState::kHoldover;
        s.outage_start_ms = now;
      }
      if (s.clock == ClockState::kHoldover && now - s.outage_start_ms > config_.holdover_max_ms) {
        s.clock = ClockState::kFaulty;
      }
      break;
    case ClockInput::kGnss:
      if (s.clock == ClockState::kHoldover) {
        s.clock = ClockState::kSynchronised;
      }
      break;
  }

  // 2. Requests and withdrawals (REQ-LC-006, REQ-LC-007).
  for (const std::uint32_t train : in.requests) {
    bool held = false;
    for (std::size_t k = 0; k < s.requester_count; ++k) {
      held = held || s.requesters[k] == train;
    }
    if (!held) {
      if (s.requester_count < kMaxRequesters) {
        s.requesters[s.requester_count++] = train;
      } else {
        s.requester_overflow = true;
      }
    }
  }
  for (const std::uint32_t train : in.withdrawals) {
    if (RAILPROOF_FAULT(FAULT_LC_END_WITH_REQUESTER)) {
      s.requester_count = 0;
    }
    for (std::size_t k = 0; k < s.requester_count; ++k) {
      if (s.requesters[k] == train) {
        for (std::size_t m = k + 1; m < s.requester_count; ++m) {
          s.requesters[m - 1] = s.requesters[m];
        }
        --s.requester_count;
        break;
      }
    }
    output_.withdrawal_acks[output_.withdrawal_ack_count++] = train;
  }

  // 3. Start times and warning stops (REQ-LC-009, REQ-LC-010, REQ-LC-011, REQ-LC-012).
  for (const StartTimeMessage& m : in.start_times) {
    if (m.crossing_id != config_.crossing_id) {
      ++output_.ignored_messages;
      continue;
    }
    StartTimeAck ack{config_.crossing_id, m.departure_id, m.start_ms, false};
    if (s.last_stopped_departure.has_value() && *s.last_stopped_departure == m.departure_id) {
      // a late repetition of a departure that has passed: not re-armed
    } else if (!s.pending.present) {
      s.pending = PendingDeparture{true, m.departure_id, m.start_ms, false};
      ack.stored = true;
    } else if (s.pending.departure_id == m.departure_id) {
      if (m.start_ms <= s.pending.start_ms) {
        s.pending.start_ms = m.start_ms;  // earlier: always
      } else {
        const bool later_allowed = RAILPROOF_FAULT(FAULT_LC_LATER_UPDATE_WHILE_WARNING) ||
                                   (s.state == ControllerState::kOpen && !s.pending.active);
        if (later_allowed) {
          s.pending.start_ms = m.start_ms;
        }
      }
      ack.start_ms = s.pending.start_ms;
      ack.stored = true;
    }
    output_.start_acks[output_.start_ack_count++] = ack;
  }
  for (const WarningStopMessage& m : in.warning_stops) {
    if (m.crossing_id != config_.crossing_id) {
      ++output_.ignored_messages;
      continue;
    }
    s.last_stopped_departure = m.departure_id;
    if (s.pending.present && s.pending.departure_id == m.departure_id) {
      s.pending = PendingDeparture{};
    }
    output_.stop_acks[output_.stop_ack_count++] = WarningStopAck{config_.crossing_id, m.departure_id};
  }
  if (s.pending.present && now >= s.pending.start_ms) {
    s.pending.active = true;
  }

  // 4. State (design §4; REQ-LC-006, REQ-LC-007, REQ-LC-011, REQ-LC-013).
  const bool down = in.barrier_down && !in.barrier_up;
  const bool up = in.barrier_up && !in.barrier_down;
  const bool trigger = s.requester_count > 0 || s.requester_overflow || s.pending.active ||
                       s.clock == ClockState::kFaulty;
  switch (s.state) {
    case ControllerState::kOpen:
    case ControllerState::kOpening:
      if (trigger) {
        if (s.state == ControllerState::kOpen) {
          s.episode_start_ms = now;
        }
        s.state = ControllerState::kWarning;
        s.warning_start_ms = now;
      } else if (s.state == ControllerState::kOpening) {
        if (up) {
          s.state = ControllerState::kOpen;
        } else if (now - s.phase_start_ms >= config_.barrier_timeout_ms) {
          s.state = ControllerState::kFailed;
          s.failure = FailureReason::kBarrierNotUp;
        }
      }
      break;
    case ControllerState::kWarning:
      if (now - s.warning_start_ms >= config_.barrier_lowering_ms) {
        s.state = ControllerState::kClosing;
        s.phase_start_ms = now;
      }
      break;
    case ControllerState::kClosing:
      if (down) {
        s.state = ControllerState::kClosed;
      } else if (now - s.warning_start_ms >= config_.barrier_lowering_ms + config_.barrier_timeout_ms) {
        s.state = ControllerState::kFailed;
        s.failure = FailureReason::kBarrierNotDown;
      }
      break;
    case ControllerState::kClosed:
      if (!down) {
        s.state = ControllerState::kFailed;
        s.failure = FailureReason::kBarrierDownLost;
      } else if (!trigger) {
        s.state = ControllerState::kOpening;
        s.phase_start_ms = now;
      }
      break;
    case ControllerState::kFailed:
      break;
  }

  // 5. Alarm (REQ-LC-007): never ends the warning.
  if (s.state == ControllerState::kOpen) {
    s.alarm = false;
  } else if (now - s.episode_start_ms > config_.max_warning_ms) {
    s.alarm = true;
  }
  ComputeOutputs(now);
  return ControllerError::kNone;
}

}  // namespace railproof::lc::wayside
