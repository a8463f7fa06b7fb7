// Level-crossing protection, the part shared by the train and the ground: crossing data
// checks and the earliest arrival (spec/design/lc.md §1-§2).
//
// Magnitudes (EarliestArrivalMs): positions |x| <= 1e10, so a piece D <= 2e10; a <= 2e4;
// speeds and caps <= 1e6 (kMaxLimitMmS, kMaxMeasuredSpeedMmS): c^2 <= 1e12, 2aD <= 8e14,
// 1000 ((c - u)^2 + 2aD) <= 8.02e17, 10^6 V2 < 10^6 c^2 <= 1e18: all inside int64.
#include "railproof/lc/crossing.hpp"

#include <cmath>

namespace railproof::lc {

using core::RestrictionSegment;

// @implements REQ-LC-001 REQ-LC-010 REQ-LC-012 REQ-LC-014
bool PositionOk(std::int64_t x) noexcept {
  return x >= -core::kMaxPositionMm && x <= core::kMaxPositionMm;
}

// @implements REQ-LC-005 REQ-LC-006 REQ-LC-008 REQ-LC-013 REQ-LC-014
bool ClockOk(std::int64_t t) noexcept { return t >= -kMaxClockMs && t <= kMaxClockMs; }

// @implements REQ-LC-001
bool ProfileOk(std::span<const RestrictionSegment> profile) noexcept {
  if (profile.size() > core::kMaxProfileCapacity) {
    return false;
  }
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const RestrictionSegment& s = profile[i];
    if (!PositionOk(s.begin_mm) || !PositionOk(s.end_mm) || s.begin_mm >= s.end_mm ||
        s.limit_mm_s < 1 || s.limit_mm_s > core::kMaxLimitMmS) {
      return false;
    }
    if (i > 0 && s.begin_mm < profile[i - 1].end_mm) {
      return false;  // unsorted or overlapping
    }
  }
  return true;
}

namespace {

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

}  // namespace

// EarliestArrivalMs on validated inputs (design §2).
// @implements REQ-LC-001
std::int64_t EarliestArrivalUncheckedMs(std::int64_t front_mm, std::int64_t target_mm, std::int64_t v0,
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
    std::int64_t limit = core::kMaxLimitMmS;
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

// @implements REQ-LC-001 REQ-LC-003
CrossingDataError CheckCrossing(const CrossingData& c) noexcept {
  if (!PositionOk(c.near_mm) || !PositionOk(c.far_mm) || c.near_mm >= c.far_mm) {
    return CrossingDataError::kExtentInvalid;
  }
  if (c.warning_time_ms < 1 || c.warning_time_ms > kMaxWarningTimeMs) {
    return CrossingDataError::kWarningTimeInvalid;
  }
  return CrossingDataError::kNone;
}


// @implements REQ-LC-001 REQ-LC-008
CrossingDataCheck ValidateCrossings(std::span<const CrossingData> crossings) noexcept {
  if (crossings.size() > kMaxCrossings) {
    return {CrossingDataError::kTooMany, kMaxCrossings};
  }
  for (std::size_t i = 0; i < crossings.size(); ++i) {
    const CrossingData& c = crossings[i];
    const CrossingDataError e = CheckCrossing(c);
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
                            std::span<const core::RestrictionSegment> profile) noexcept {
  if (!PositionOk(front_mm) || !PositionOk(target_mm)) {
    return {EtaError::kPositionInvalid, 0};
  }
  if (speed_mm_s < 0 || speed_mm_s > core::kMaxMeasuredSpeedMmS) {
    return {EtaError::kSpeedInvalid, 0};
  }
  if (accel_max_mm_s2 < 0 || accel_max_mm_s2 > core::kMaxAccelerationMmS2) {
    return {EtaError::kAccelerationInvalid, 0};
  }
  if (!ProfileOk(profile)) {
    return {EtaError::kProfileInvalid, 0};
  }
  return {EtaError::kNone, EarliestArrivalUncheckedMs(front_mm, target_mm, speed_mm_s, accel_max_mm_s2, profile)};
}

// @implements REQ-LC-005
EtaResult EarliestArrivalAfterDwellMs(std::int64_t now_ms, std::int64_t departure_ms,
                                      std::int64_t front_mm, std::int64_t target_mm,
                                      std::int64_t accel_max_mm_s2,
                                      std::span<const core::RestrictionSegment> profile) noexcept {
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

}  // namespace railproof::lc
