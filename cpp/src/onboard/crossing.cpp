// Level-crossing protection, on-board part (spec/design/level-crossing.md §1-§3).
// Seeded faults (negative tests; the model mirrors them as mutants) are compiled in only with
// their FAULT_LC_* macro:
//   FAULT_LC_CLEAR_WITHOUT_WARNING_TIME  clearance ignores ws + warning_time <= now + ETA
//   FAULT_LC_STALE_CONFIRMATION          the age of a CLOSED confirmation is not checked
//   FAULT_LC_WITHDRAW_AT_FRONT           withdrawal when the front (front_max) passed far
//   FAULT_LC_CLEAR_ON_ANY_CLOSED         a CLOSED report clears although it does not list this train
//
// Magnitudes (EarliestArrivalMs): positions |x| <= 1e10, so a piece D <= 2e10; a <= 2e4;
// speeds and caps <= 1e6 (kMaxLimitMmS, kMaxMeasuredSpeedMmS): c^2 <= 1e12, 2aD <= 8e14,
// 1000 ((c - u)^2 + 2aD) <= 8.02e17, 10^6 V2 < 10^6 c^2 <= 1e18: all inside int64.
#include "railproof/onboard/crossing.hpp"

#include <cmath>

namespace railproof::onboard {

namespace {

using braking::RestrictionSegment;

// @implements REQ-LC-001
// floor(sqrt(n)) for 0 <= n <= 1e18. The standard library has no integer square root; the
// double estimate is corrected by at most a few steps (bounded loops).
std::int64_t ISqrt(std::int64_t n) noexcept {
  if (n <= 0) {
    return 0;
  }
  auto r = static_cast<std::int64_t>(std::sqrt(static_cast<double>(n)));
  for (int k = 0; k < 4 && r > 0 && r * r > n; ++k) {
    --r;
  }
  for (int k = 0; k < 4 && (r + 1) * (r + 1) <= n; ++k) {
    ++r;
  }
  return r;
}

// ceil(sqrt(n)) for 0 <= n <= 1e18.
// @implements REQ-LC-001
std::int64_t CeilSqrt(std::int64_t n) noexcept {
  const std::int64_t r = ISqrt(n);
  return r * r < n ? r + 1 : r;
}

// @implements REQ-LC-001 REQ-LC-014
bool PositionOk(std::int64_t x) noexcept {
  return x >= -braking::kMaxPositionMm && x <= braking::kMaxPositionMm;
}

// @implements REQ-LC-005 REQ-LC-014
bool ClockOk(std::int64_t t) noexcept { return t >= -kMaxClockMs && t <= kMaxClockMs; }

// @implements REQ-LC-001
bool ProfileOk(std::span<const RestrictionSegment> profile) noexcept {
  if (profile.size() > braking::kMaxProfileCapacity) {
    return false;
  }
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const RestrictionSegment& s = profile[i];
    if (!PositionOk(s.begin_mm) || !PositionOk(s.end_mm) || s.begin_mm >= s.end_mm ||
        s.limit_mm_s < 1 || s.limit_mm_s > braking::kMaxLimitMmS) {
      return false;
    }
    if (i > 0 && s.begin_mm < profile[i - 1].end_mm) {
      return false;  // unsorted or overlapping
    }
  }
  return true;
}

// One piece of design §2: time (ms, rounded down) to run d_mm with cap c and entry speed u
// (u <= c), acceleration a; end speed in *v_end. kEtaNeverMs if never.
// @implements REQ-LC-001
std::int64_t PieceMs(std::int64_t d_mm, std::int64_t u, std::int64_t c, std::int64_t a,
                     std::int64_t* v_end) noexcept {
  if (a == 0) {
    *v_end = u;
    if (u == 0) {
      return kEtaNeverMs;
    }
    return 1000 * d_mm / u;
  }
  const std::int64_t two_a_d = 2 * a * d_mm;
  if (two_a_d >= c * c - u * u) {
    // accelerate to c, then cruise: ((c - u)^2 + 2aD) / (2ac) seconds
    *v_end = c;
    return 1000 * ((c - u) * (c - u) + two_a_d) / (2 * a * c);
  }
  // accelerate only: v_end^2 = u^2 + 2aD < c^2
  const std::int64_t v2 = u * u + two_a_d;
  *v_end = CeilSqrt(v2);
  return (ISqrt(1'000'000 * v2) - 1000 * u) / a;
}

// EarliestArrivalMs on validated inputs (design §2).
// @implements REQ-LC-001
std::int64_t EtaUnchecked(std::int64_t front_mm, std::int64_t target_mm, std::int64_t v0,
                          std::int64_t a, std::span<const RestrictionSegment> profile) noexcept {
  if (target_mm <= front_mm) {
    return 0;
  }
  std::int64_t pos = front_mm;
  std::int64_t v = v0;
  std::int64_t total = 0;
  std::size_t idx = 0;
  // at most 2 * size + 1 pieces: each iteration ends a restriction, a gap or the run
  const std::size_t max_iterations = 2 * profile.size() + 2;
  for (std::size_t it = 0; it < max_iterations && pos < target_mm; ++it) {
    while (idx < profile.size() && profile[idx].end_mm <= pos) {
      ++idx;
    }
    std::int64_t piece_end = target_mm;
    std::int64_t limit = braking::kMaxLimitMmS;
    if (idx < profile.size() && profile[idx].begin_mm <= pos) {
      limit = profile[idx].limit_mm_s;
      piece_end = profile[idx].end_mm < target_mm ? profile[idx].end_mm : target_mm;
    } else if (idx < profile.size() && profile[idx].begin_mm < target_mm) {
      piece_end = profile[idx].begin_mm;  // gap up to the next restriction
    }
    const std::int64_t cap = limit > v0 ? limit : v0;
    const std::int64_t u = v < cap ? v : cap;
    std::int64_t v_end = 0;
    const std::int64_t t = PieceMs(piece_end - pos, u, cap, a, &v_end);
    if (t == kEtaNeverMs) {
      return kEtaNeverMs;
    }
    total = SaturatingAddMs(total, t);
    v = v_end;
    pos = piece_end;
  }
  return total;
}

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

// @implements REQ-LC-001 REQ-LC-003
CrossingDataError CheckOne(const CrossingData& c) noexcept {
  if (!PositionOk(c.near_mm) || !PositionOk(c.far_mm) || c.near_mm >= c.far_mm) {
    return CrossingDataError::kExtentInvalid;
  }
  if (c.warning_time_ms < 1 || c.warning_time_ms > kMaxWarningTimeMs) {
    return CrossingDataError::kWarningTimeInvalid;
  }
  return CrossingDataError::kNone;
}

}  // namespace

// @implements REQ-LC-001 REQ-LC-008
CrossingDataCheck ValidateCrossings(std::span<const CrossingData> crossings) noexcept {
  if (crossings.size() > kMaxCrossings) {
    return {CrossingDataError::kTooMany, kMaxCrossings};
  }
  for (std::size_t i = 0; i < crossings.size(); ++i) {
    const CrossingData& c = crossings[i];
    const CrossingDataError e = CheckOne(c);
    if (e != CrossingDataError::kNone) {
      return {e, i};
    }
    for (std::size_t k = 0; k < i; ++k) {
      if (crossings[k].id == c.id) {
        return {CrossingDataError::kDuplicateId, i};
      }
    }
    if (i > 0 && c.near_mm < crossings[i - 1].near_mm) {
      return {CrossingDataError::kUnsorted, i};
    }
    if (i > 0 && c.near_mm < crossings[i - 1].far_mm) {
      return {CrossingDataError::kOverlap, i};
    }
  }
  return {};
}

// @implements REQ-LC-001
EtaResult EarliestArrivalMs(std::int64_t front_mm, std::int64_t target_mm, std::int64_t speed_mm_s,
                            std::int64_t accel_max_mm_s2,
                            std::span<const braking::RestrictionSegment> profile) noexcept {
  if (!PositionOk(front_mm) || !PositionOk(target_mm)) {
    return {EtaError::kPositionInvalid, 0};
  }
  if (speed_mm_s < 0 || speed_mm_s > braking::kMaxMeasuredSpeedMmS) {
    return {EtaError::kSpeedInvalid, 0};
  }
  if (accel_max_mm_s2 < 0 || accel_max_mm_s2 > braking::kMaxAccelerationMmS2) {
    return {EtaError::kAccelerationInvalid, 0};
  }
  if (!ProfileOk(profile)) {
    return {EtaError::kProfileInvalid, 0};
  }
  return {EtaError::kNone, EtaUnchecked(front_mm, target_mm, speed_mm_s, accel_max_mm_s2, profile)};
}

// @implements REQ-LC-005
EtaResult EarliestArrivalAfterDwellMs(std::int64_t now_ms, std::int64_t departure_ms,
                                      std::int64_t front_mm, std::int64_t target_mm,
                                      std::int64_t accel_max_mm_s2,
                                      std::span<const braking::RestrictionSegment> profile) noexcept {
  if (!ClockOk(now_ms) || !ClockOk(departure_ms)) {
    return {EtaError::kTimeInvalid, 0};
  }
  const EtaResult run = EarliestArrivalMs(front_mm, target_mm, 0, accel_max_mm_s2, profile);
  if (run.error != EtaError::kNone || run.eta_ms == kEtaNeverMs) {
    return run;
  }
  const std::int64_t wait = departure_ms > now_ms ? departure_ms - now_ms : 0;
  return {EtaError::kNone, SaturatingAddMs(wait, run.eta_ms)};
}

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
  if (config.train_length_mm < 1 || config.train_length_mm > braking::kMaxTrainLengthMm) {
    r.error = ProtectionError::kTrainLengthInvalid;
    return r;
  }
  if (config.accel_max_mm_s2 < 0 || config.accel_max_mm_s2 > braking::kMaxAccelerationMmS2) {
    r.error = ProtectionError::kAccelerationInvalid;
    return r;
  }
  if (config.request_lead_ms < 0 || config.request_lead_ms > kMaxWarningTimeMs ||
      config.confirmation_max_age_ms < 0 || config.confirmation_max_age_ms > kMaxWarningTimeMs ||
      config.protection_offset_mm < 0 || config.protection_offset_mm > braking::kMaxPositionErrorMm ||
      config.lookahead_mm < 1 || config.lookahead_mm > braking::kMaxPositionMm) {
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
  const CrossingDataError e = CheckOne(crossing);
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
  CrossingEntry entry;
  entry.data = crossing;
  entries_[count_] = entry;
  ++count_;
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
    CrossingEntry entry;
    entry.data = c;
    entries_[count_] = entry;
    ++count_;
  }
  ComputeOutputs();
  return ProtectionError::kNone;
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
  for (std::size_t i = 0; i < count_; ++i) {
    if (entries_[i].data.id == crossing_id) {
      return &entries_[i];
    }
  }
  return nullptr;
}

// @implements REQ-LC-002 REQ-LC-003
CrossingEntry* CrossingProtection::FindMutable(std::uint32_t crossing_id) noexcept {
  for (std::size_t i = 0; i < count_; ++i) {
    if (entries_[i].data.id == crossing_id) {
      return &entries_[i];
    }
  }
  return nullptr;
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
             in.front_error_mm > braking::kMaxPositionErrorMm || in.rear_error_mm < 0 ||
             in.rear_error_mm > braking::kMaxPositionErrorMm) {
    error = ProtectionError::kPositionInvalid;
  } else if (in.speed_mm_s < 0 || in.speed_mm_s > braking::kMaxMeasuredSpeedMmS) {
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
  const std::int64_t eta_front = front_max > braking::kMaxPositionMm ? braking::kMaxPositionMm : front_max;
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
        const std::int64_t run = EtaUnchecked(eta_front, c.near_mm, 0, config_.accel_max_mm_s2, in.restrictions);
        e.eta_ms = run == kEtaNeverMs ? kEtaNeverMs : SaturatingAddMs(wait, run);
      } else {
        e.eta_ms = EtaUnchecked(eta_front, c.near_mm, in.speed_mm_s, config_.accel_max_mm_s2, in.restrictions);
      }
    } else {
      e.eta_ms = -1;
    }

    // Step 1: passage and withdrawal (REQ-LC-004).
    const bool was_passed = e.state == CrossingState::kPassed;
#if defined(FAULT_LC_WITHDRAW_AT_FRONT)
    (void)rear_min;
    const bool passed = front_max >= c.far_mm;
#else
    const bool passed = rear_min >= c.far_mm;
#endif
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
#if defined(FAULT_LC_CLEAR_ON_ANY_CLOSED)
      const bool confirms = r.status == CrossingStatus::kClosed;
#else
      const bool confirms = r.status == CrossingStatus::kClosed && r.Lists(config_.train_id);
#endif
      if (e.state == CrossingState::kRequested && confirms) {
#if defined(FAULT_LC_STALE_CONFIRMATION)
        const bool fresh = true;
#else
        const bool fresh = r.issued_ms >= now - config_.confirmation_max_age_ms;  // no overflow
#endif
#if defined(FAULT_LC_CLEAR_WITHOUT_WARNING_TIME)
        const bool warned_long_enough = true;
#else
        const bool warned_long_enough =
            SaturatingAddMs(r.warning_start_ms, c.warning_time_ms) <= SaturatingAddMs(now, e.eta_ms);
#endif
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

}  // namespace railproof::onboard
