// Level-crossing protection, the part shared by the train and the ground
// (spec/design/lc.md §1-§2; model: models/lc.pml):
//   CrossingData / CrossingExtentOf   crossing geometry [near, far) and design warning time (§1)
//   ValidateCrossings                 crossing data checks (REQ-LC-001, REQ-LC-008)
//   FindCrossing                      an entry of a crossing held, by id
//   EarliestArrivalMs                 earliest arrival of the front at a position (§2,
//   EarliestArrivalAfterDwellMs       REQ-LC-001, REQ-LC-005); used on board
//                                     (lc::onboard::CrossingProtection), by the centre
//                                     (lc::wayside::CentreScheduler) and the warning-time study
// Pure functions of their arguments: no state, no heap, no exceptions, bounded loops.
// Units: mm, mm/s, mm/s^2, ms (int64), positions increasing in the running direction.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/track.hpp"
#include "railproof/core/units.hpp"
#include "railproof/generated/lc_params.hpp"

namespace railproof::lc {


// Crossings handled at once by one on-board unit, one controller group or one departure
// (parameter max_crossings).
inline constexpr std::size_t kMaxCrossings =
    static_cast<std::size_t>(params::lc::max_crossings);

// "Never": the front cannot reach the target (standing, no acceleration). Comparisons with
// it are safe (never <= a finite time); sums with it saturate (SaturatingAddMs).
inline constexpr std::int64_t kEtaNeverMs = std::numeric_limits<std::int64_t>::max();

// Ranges accepted by the crossing functions (keep every product inside int64, see crossing.cpp).
inline constexpr std::int64_t kMaxWarningTimeMs = 3'600'000;   // design warning time <= 1 h
inline constexpr std::int64_t kMaxClockMs = 1'000'000'000'000'000;  // |now|, |t_dep|, time stamps

// a + b for times, saturating at kEtaNeverMs / the int64 minimum (never overflows).
constexpr std::int64_t SaturatingAddMs(std::int64_t a, std::int64_t b) noexcept {
  if (b > 0 && a > std::numeric_limits<std::int64_t>::max() - b) {
    return std::numeric_limits<std::int64_t>::max();
  }
  if (b < 0 && a < std::numeric_limits<std::int64_t>::min() - b) {
    return std::numeric_limits<std::int64_t>::min();
  }
  return a + b;
}

// Range checks shared by the crossing functions (typed input validation, REQ-LC-014):
// a line position inside core::kMaxPositionMm, a clock value inside kMaxClockMs, and a
// restriction profile that is sorted, non-overlapping, non-empty per segment, inside the
// position range, with limits in 1..core::kMaxLimitMmS and at most core::kMaxProfileCapacity
// segments.
bool PositionOk(std::int64_t x) noexcept;
bool ClockOk(std::int64_t t) noexcept;
bool ProfileOk(std::span<const core::RestrictionSegment> profile) noexcept;

// ---- crossing data (design §1) --------------------------------------------------------------

// A crossing occupies [near_mm, far_mm) in the running direction; warning_time_ms is its
// design warning time (line data warning_time_s, default default_warning_time_ms).
// @implements REQ-LC-001 REQ-LC-003 REQ-LC-004
struct CrossingData {
  std::uint32_t id = 0;
  std::int64_t near_mm = 0;
  std::int64_t far_mm = 0;
  std::int64_t warning_time_ms = 0;
};

struct CrossingExtent {
  std::int64_t near_mm = 0;
  std::int64_t far_mm = 0;
};

// near = at - width/2, far = at + width/2, rounded outwards (design §1):
// near = at - ceil(width/2), far = at + ceil(width/2). width_mm < 0 is taken as 0.
// @implements REQ-LC-003 REQ-LC-004
constexpr CrossingExtent CrossingExtentOf(std::int64_t at_mm, std::int64_t width_mm) noexcept {
  const std::int64_t w = width_mm < 0 ? 0 : width_mm;
  const std::int64_t half_up = w / 2 + w % 2;
  return {at_mm - half_up, at_mm + half_up};
}

// Crossing data errors (AddCrossing / LoadCrossings / CentreScheduler::StartDeparture /
// ValidateCrossings), checked per entry in this order.
enum class CrossingDataError : std::uint8_t {
  kNone,
  kExtentInvalid,       // near_mm >= far_mm, or |near|, |far| > core::kMaxPositionMm
  kWarningTimeInvalid,  // warning_time_ms not in 1..kMaxWarningTimeMs
  kDuplicateId,         // id already present
  kUnsorted,            // near_mm < near_mm of the previous crossing
  kOverlap,             // near_mm < far_mm of the previous crossing
  kTooMany,             // more than kMaxCrossings
};

constexpr const char* ToString(CrossingDataError e) noexcept {
  return core::EnumName(e, std::array<const char*, 7>{"NONE", "EXTENT_INVALID", "WARNING_TIME_INVALID", "DUPLICATE_ID", "UNSORTED", "OVERLAP", "TOO_MANY"});
}

struct CrossingDataCheck {
  CrossingDataError error = CrossingDataError::kNone;
  std::size_t entry = 0;  // index of the offending crossing (0 if none)
};

// The per-entry checks of ValidateCrossings (extent, warning time).
// @implements REQ-LC-001 REQ-LC-003
CrossingDataError CheckCrossing(const CrossingData& c) noexcept;

// Validates a list of crossings (sorted by near edge, non-overlapping, unique ids, at most
// kMaxCrossings).
// @implements REQ-LC-001 REQ-LC-008
CrossingDataCheck ValidateCrossings(std::span<const CrossingData> crossings) noexcept;

// The entry of `crossing_id` among `entries` (each holding its crossing as `data`), nullptr
// if none: the lookup of the on-board crossing function and of the centre scheduler.
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-008
template <typename Entry>
Entry* FindCrossing(std::span<Entry> entries, std::uint32_t crossing_id) noexcept {
  for (Entry& e : entries) {
    if (e.data.id == crossing_id) {
      return &e;
    }
  }
  return nullptr;
}

// ---- earliest arrival (design §2) --------------------------------------------------------

// Errors of EarliestArrivalMs, checked in this order.
enum class EtaError : std::uint8_t {
  kNone,
  kPositionInvalid,      // |front_mm| or |target_mm| > core::kMaxPositionMm
  kSpeedInvalid,         // speed not in 0..core::kMaxMeasuredSpeedMmS
  kAccelerationInvalid,  // accel not in 0..core::kMaxAccelerationMmS2
  kProfileInvalid,       // more than core::kMaxProfileCapacity segments, a segment empty,
                         // unsorted, overlapping, outside kMaxPositionMm, or a limit not in
                         // 1..core::kMaxLimitMmS
  kTimeInvalid,          // (dwell variant) |now| or |t_dep| > kMaxClockMs
};

constexpr const char* ToString(EtaError e) noexcept {
  return core::EnumName(e, std::array<const char*, 6>{"NONE", "POSITION_INVALID", "SPEED_INVALID", "ACCELERATION_INVALID", "PROFILE_INVALID", "TIME_INVALID"});
}

struct EtaResult {
  EtaError error = EtaError::kNone;
  std::int64_t eta_ms = 0;  // kEtaNeverMs if the target is never reached; 0 on error
};

// Earliest time (ms) for the front, now at front_mm with speed speed_mm_s, to reach
// target_mm (design §2). 0 if target_mm <= front_mm (reached).
//
// Exact arithmetic (the conformance vectors and the study mirror it bit for bit):
//  * Pieces: [front_mm, target_mm) is cut at every restriction begin and end; a piece inside
//    restriction k has the limit L_k, a piece in a gap between restrictions (or outside all)
//    has the limit core::kMaxLimitMmS (no speed bound below it: faster is the safe side).
//    Adjacent restrictions with the same limit are still separate pieces.
//  * Cap of a piece c = max(limit, v0): never above the permitted speed, but never below the
//    current speed v0 (the train is never assumed to brake, design §2).
//  * Entry speed of a piece u = min(speed at the end of the previous piece, c) (u = v0 for
//    the first); the speed at a piece end is an integer (see below). Length of the piece D.
//  * a = accel_max_mm_s2. Per piece, t = time in ms rounded DOWN (earlier is safe):
//      a == 0:                 u == 0 -> never; else t = floor(1000 D / u), end speed u
//      2aD >= c^2 - u^2:       t = floor(1000 ((c - u)^2 + 2aD) / (2ac)), end speed c
//                              (accelerate to c, then cruise)
//      else:                   V2 = u^2 + 2aD; t = floor((isqrt(10^6 V2) - 1000 u) / a),
//                              end speed ceil(sqrt(V2)) (rounded up: faster, safe)
//  * Result: the sum of the pieces' t (each rounded down: the sum is never above the exact
//    time). Never: kEtaNeverMs.
// Profile: core::RestrictionSegment list sorted by begin, non-overlapping, non-empty
// (static line limits and temporary restrictions merged by the caller: the lower applies).
// Bounded: O(number of restrictions).
// @implements REQ-LC-001
EtaResult EarliestArrivalMs(std::int64_t front_mm, std::int64_t target_mm, std::int64_t speed_mm_s,
                            std::int64_t accel_max_mm_s2,
                            std::span<const core::RestrictionSegment> profile) noexcept;

// EarliestArrivalMs on inputs the caller has already validated (PositionOk, the speed and
// acceleration ranges, ProfileOk): the per-cycle path of CrossingProtection, which checks its
// inputs once per cycle.
// @implements REQ-LC-001
std::int64_t EarliestArrivalUncheckedMs(std::int64_t front_mm, std::int64_t target_mm, std::int64_t speed_mm_s,
                                        std::int64_t accel_max_mm_s2,
                                        std::span<const core::RestrictionSegment> profile) noexcept;

// Dwell-aware variant (design §2, REQ-LC-005) for a train standing at a scheduled stop whose
// departure is not authorised before departure_ms:
//   max(0, departure_ms - now_ms) + EarliestArrivalMs(front, target, 0, accel, profile)
// (saturating; kEtaNeverMs stays never).
// @implements REQ-LC-005
EtaResult EarliestArrivalAfterDwellMs(std::int64_t now_ms, std::int64_t departure_ms,
                                      std::int64_t front_mm, std::int64_t target_mm,
                                      std::int64_t accel_max_mm_s2,
                                      std::span<const core::RestrictionSegment> profile) noexcept;

}  // namespace railproof::lc
