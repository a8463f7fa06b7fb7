// Level-crossing protection, on-board part (spec/design/lc.md §1-§3).
// Seeded faults (negative tests; the model mirrors them as mutants), active only in the
// test-only schemata variant (spec/design/seeded-faults.md):
//   FAULT_LC_CLEAR_WITHOUT_WARNING_TIME  clearance ignores ws + warning_time <= now + ETA
//   FAULT_LC_STALE_CONFIRMATION          the age of a CLOSED confirmation is not checked
//   FAULT_LC_WITHDRAW_AT_FRONT           withdrawal when the front (front_max) passed far
//   FAULT_LC_CLEAR_ON_ANY_CLOSED         a CLOSED report clears although it does not list this train
#include "railproof/core/seeded_fault.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"

#include <cmath>

namespace railproof::lc::onboard {

namespace {

// @implements REQ-LC-001
ProtectionError FromDataError(CrossingDataError e) noexcept {
  switch (e) {
    case CrossingDataError::kNone: return ProtectionError::kNone;
    case CrossingDataError::kExtentInvalid: return ProtectionError::kCrossingExtentInvalid;
    case CrossingDataError::kWarningTimeInvalid: return ProtectionError::kCrossingWarningTimeInvalid;
    case CrossingDataError::kDuplicateId: return ProtectionError::kCrossingDuplicateId;
    case CrossingDataError::kUnsorted: return ProtectionError::kCrossingUnsorted;
    case CrossingDataError::kOverlap: return ProtectionError::kCrossingOverlap;
    case CrossingDataError::kTooMany: return ProtectionError::kTooManyCrossings;
  }
  return ProtectionError::kCrossingExtentInvalid;  // GCOVR_EXCL_LINE defensive
}

}  // namespace

// @implements REQ-LC-002 REQ-LC-003
ProtectionConfig DefaultProtectionConfig(std::uint32_t train_id, std::int64_t train_length_mm,
                                         std::int64_t accel_max_mm_s2) noexcept {
  ProtectionConfig c;
  c.train_id = train_id;
  c.train_length_mm = train_length_mm;
  c.accel_max_mm_s2 = accel_max_mm_s2;
  return c;
}

// @implements REQ-LC-001 REQ-LC-014
CrossingProtection::CreateResult CrossingProtection::Create(const ProtectionConfig& config) noexcept {
  CreateResult r;
  if (config.train_length_mm < 1 || config.train_length_mm > core::kMaxTrainLengthMm) {
    r.error = ProtectionError::kTrainLengthInvalid;
    return r;
  }
  if (config.accel_max_mm_s2 < 0 || config.accel_max_mm_s2 > core::kMaxAccelerationMmS2) {
    r.error = ProtectionError::kAccelerationInvalid;
    return r;
  }
  if (config.request_lead_ms < 0 || config.request_lead_ms > kMaxWarningTimeMs ||
      config.confirmation_max_age_ms < 0 || config.confirmation_max_age_ms > kMaxWarningTimeMs ||
      config.protection_offset_mm < 0 || config.protection_offset_mm > core::kMaxPositionErrorMm ||
      config.lookahead_mm < 1 || config.lookahead_mm > core::kMaxPositionMm) {
    r.error = ProtectionError::kParameterInvalid;
    return r;
  }
  r.protection = CrossingProtection(config);
  r.protection->ComputeOutputs();
  return r;
}

// @implements REQ-LC-001
ProtectionError CrossingProtection::AddCrossing(const CrossingData& crossing) noexcept {
  if (count_ >= kMaxCrossings) {
    return ProtectionError::kTooManyCrossings;
  }
  const CrossingDataError e = CheckCrossing(crossing);
  if (e != CrossingDataError::kNone) {
    return FromDataError(e);
  }
  if (Find(crossing.id) != nullptr) {
    return ProtectionError::kCrossingDuplicateId;
  }
  if (count_ > 0) {
    const CrossingData& last = entries_[count_ - 1].data;
    if (crossing.near_mm < last.near_mm) {
      return ProtectionError::kCrossingUnsorted;
    }
    if (crossing.near_mm < last.far_mm) {
      return ProtectionError::kCrossingOverlap;
    }
  }
  Append(crossing);
  ComputeOutputs();
  return ProtectionError::kNone;
}

// @implements REQ-LC-001
ProtectionError CrossingProtection::LoadCrossings(std::span<const CrossingData> crossings) noexcept {
  count_ = 0;
  const CrossingDataCheck check = ValidateCrossings(crossings);
  if (check.error != CrossingDataError::kNone) {
    ComputeOutputs();
    return FromDataError(check.error);
  }
  for (const CrossingData& c : crossings) {
    Append(c);
  }
  ComputeOutputs();
  return ProtectionError::kNone;
}

// @implements REQ-LC-001
void CrossingProtection::Append(const CrossingData& crossing) noexcept {
  CrossingEntry entry;
  entry.data = crossing;
  entries_[count_] = entry;
  ++count_;
}

// @implements REQ-LC-004
void CrossingProtection::DropDone() noexcept {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    if (entries_[i].state != CrossingState::kDone) {
      entries_[kept] = entries_[i];
      ++kept;
    }
  }
  count_ = kept;
  ComputeOutputs();
}

// @implements REQ-LC-002 REQ-LC-003
const CrossingEntry* CrossingProtection::Find(std::uint32_t crossing_id) const noexcept {
  return FindCrossing(std::span<const CrossingEntry>(entries_.data(), count_), crossing_id);
}

// @implements REQ-LC-002 REQ-LC-003
CrossingEntry* CrossingProtection::FindMutable(std::uint32_t crossing_id) noexcept {
  return FindCrossing(std::span<CrossingEntry>(entries_.data(), count_), crossing_id);
}

// Step 4 of design §3 and the messages to send.
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-004
void CrossingProtection::ComputeOutputs() noexcept {
  output_.request_count = 0;
  output_.withdrawal_count = 0;
  output_.stop_limit_mm.reset();
  output_.limiting_crossing_id = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    const CrossingEntry& e = entries_[i];
    switch (e.state) {
      case CrossingState::kApproaching:
      case CrossingState::kRequested: {
        const std::int64_t limit = e.data.near_mm - config_.protection_offset_mm;
        if (!output_.stop_limit_mm.has_value() || limit < *output_.stop_limit_mm) {
          output_.stop_limit_mm = limit;
          output_.limiting_crossing_id = e.data.id;
        }
        if (e.state == CrossingState::kRequested) {
          output_.requests[output_.request_count++] = e.data.id;
        }
        break;
      }
      case CrossingState::kCleared:
        output_.requests[output_.request_count++] = e.data.id;
        break;
      case CrossingState::kPassed:
        output_.withdrawals[output_.withdrawal_count++] = e.data.id;
        break;
      case CrossingState::kDone:
        break;
    }
  }
}

// @implements REQ-LC-001 REQ-LC-002 REQ-LC-003 REQ-LC-004 REQ-LC-005 REQ-LC-014
ProtectionError CrossingProtection::Cycle(const ProtectionInput& in) noexcept {
  ProtectionError error = ProtectionError::kNone;
  if (!ClockOk(in.now_ms) || (in.dwell && !ClockOk(in.departure_ms))) {
    error = ProtectionError::kTimeInvalid;
  } else if (last_now_.has_value() && in.now_ms < *last_now_) {
    error = ProtectionError::kTimeWentBack;
  } else if (!PositionOk(in.front_mm) || in.front_error_mm < 0 ||
             in.front_error_mm > core::kMaxPositionErrorMm || in.rear_error_mm < 0 ||
             in.rear_error_mm > core::kMaxPositionErrorMm) {
    error = ProtectionError::kPositionInvalid;
  } else if (in.speed_mm_s < 0 || in.speed_mm_s > core::kMaxMeasuredSpeedMmS) {
    error = ProtectionError::kSpeedInvalid;
  } else if (in.dwell && in.speed_mm_s != 0) {
    error = ProtectionError::kDwellWhileMoving;
  } else if (!ProfileOk(in.restrictions)) {
    error = ProtectionError::kProfileInvalid;
  } else if (in.reports.size() > kMaxMessagesPerCycle || in.acks.size() > kMaxMessagesPerCycle) {
    error = ProtectionError::kTooManyMessages;
  }
  if (error != ProtectionError::kNone) {
    ComputeOutputs();
    output_.ignored_messages = 0;
    return error;
  }
  const std::int64_t now = in.now_ms;
  last_now_ = now;
  // front_max may exceed kMaxPositionMm by the error: the ETA target comparison below handles
  // it (front_max >= near gives 0); clamp for EarliestArrivalMs's range.
  const std::int64_t front_max = in.front_mm + in.front_error_mm;
  const std::int64_t eta_front = front_max > core::kMaxPositionMm ? core::kMaxPositionMm : front_max;
  const std::int64_t rear_min = in.front_mm - config_.train_length_mm - in.rear_error_mm;

  std::size_t ignored = 0;
  for (const CrossingReport& r : in.reports) {
    if (Find(r.crossing_id) == nullptr || r.issued_ms > now) {
      ++ignored;
    }
  }
  for (const WithdrawalAck& a : in.acks) {
    if (a.train_id != config_.train_id || Find(a.crossing_id) == nullptr) {
      ++ignored;
    }
  }

  for (std::size_t i = 0; i < count_; ++i) {
    CrossingEntry& e = entries_[i];
    const CrossingData& c = e.data;
    // Step 0: ETA (REQ-LC-001, REQ-LC-005).
    e.within_lookahead = c.near_mm - front_max <= config_.lookahead_mm;
    if (e.state == CrossingState::kApproaching || e.state == CrossingState::kRequested ||
        e.state == CrossingState::kCleared) {
      if (front_max >= c.near_mm) {
        e.eta_ms = 0;
      } else if (in.dwell) {
        const std::int64_t wait = in.departure_ms > now ? in.departure_ms - now : 0;
        const std::int64_t run = EarliestArrivalUncheckedMs(eta_front, c.near_mm, 0, config_.accel_max_mm_s2, in.restrictions);
        e.eta_ms = run == kEtaNeverMs ? kEtaNeverMs : SaturatingAddMs(wait, run);
      } else {
        e.eta_ms = EarliestArrivalUncheckedMs(eta_front, c.near_mm, in.speed_mm_s, config_.accel_max_mm_s2, in.restrictions);
      }
    } else {
      e.eta_ms = -1;
    }

    // Step 1: passage and withdrawal (REQ-LC-004).
    const bool was_passed = e.state == CrossingState::kPassed;
    const bool passed = RAILPROOF_FAULT(FAULT_LC_WITHDRAW_AT_FRONT) ? front_max >= c.far_mm : rear_min >= c.far_mm;
    if (e.state != CrossingState::kDone && passed) {
      e.state = CrossingState::kPassed;
      e.cleared_ws_ms = 0;
    }
    if (was_passed) {
      for (const WithdrawalAck& a : in.acks) {
        if (a.train_id == config_.train_id && a.crossing_id == c.id) {
          e.state = CrossingState::kDone;
          break;
        }
      }
    }

    // Step 2: request (REQ-LC-002).
    if (e.state == CrossingState::kApproaching && e.within_lookahead &&
        e.eta_ms <= SaturatingAddMs(c.warning_time_ms, config_.request_lead_ms)) {
      e.state = CrossingState::kRequested;
    }

    // Step 3: clearance and re-protection (REQ-LC-003, REQ-LC-014).
    for (const CrossingReport& r : in.reports) {
      if (r.crossing_id != c.id || r.issued_ms > now) {
        continue;
      }
      // A confirmation is a CLOSED report that lists this train among the requesters; any
      // other report of the crossing revokes a clearance (design §3 item 3).
      const bool confirms = r.status == CrossingStatus::kClosed &&
                            (RAILPROOF_FAULT(FAULT_LC_CLEAR_ON_ANY_CLOSED) || r.Lists(config_.train_id));
      if (e.state == CrossingState::kRequested && confirms) {
        const bool fresh = RAILPROOF_FAULT(FAULT_LC_STALE_CONFIRMATION) ||
                           r.issued_ms >= now - config_.confirmation_max_age_ms;  // no overflow
        const bool warned_long_enough =
            RAILPROOF_FAULT(FAULT_LC_CLEAR_WITHOUT_WARNING_TIME) ||
            SaturatingAddMs(r.warning_start_ms, c.warning_time_ms) <= SaturatingAddMs(now, e.eta_ms);
        if (fresh && warned_long_enough) {
          e.state = CrossingState::kCleared;
          e.cleared_ws_ms = r.warning_start_ms;
        }
      } else if (e.state == CrossingState::kCleared && !confirms) {
        e.state = CrossingState::kRequested;
        e.cleared_ws_ms = 0;
      }
    }
  }
  ComputeOutputs();
  output_.ignored_messages = ignored;
  return ProtectionError::kNone;
}

}  // namespace railproof::lc::onboard
