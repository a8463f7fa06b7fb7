// Level-crossing protection, on-board part and the pieces shared with the ground
// (spec/design/level-crossing.md §1-§3; model: models/level_crossing.pml):
//   CrossingData / CrossingExtentOf   crossing geometry [near, far) and design warning time (§1)
//   EarliestArrivalMs                 earliest arrival of the front at a position (§2,
//   EarliestArrivalAfterDwellMs       REQ-LC-001, REQ-LC-005); also used by the centre
//                                     (wayside::CentreScheduler) and the warning-time study
//   CrossingReport, WithdrawalAck,    radio messages between the train, the crossing
//   CrossingRequest                   controllers (wayside::CrossingController) and the centre
//   CrossingProtection                per-crossing request / clearance / protection / withdrawal
//                                     (§3, REQ-LC-002..005, REQ-LC-014)
//
// Usage (one CrossingProtection per train):
//   auto created = CrossingProtection::Create(DefaultProtectionConfig(train_id, length, accel));
//   CrossingProtection& p = *created.protection;
//   p.LoadCrossings(crossings_of_the_journey);       // sorted by near edge, <= kMaxCrossings
//   every on-board cycle:
//     ProtectionInput in{now, front, front_error, rear_error, v_s, dwell, t_dep,
//                        restrictions, received_reports, received_acks};
//     const ProtectionError e = p.Cycle(in);         // e != kNone: state unchanged (see Cycle)
//     send p.Output().Requests() and p.Output().Withdrawals();
//     stop limit for braking::PatternCalculator::Evaluate: the more restrictive (smaller) of
//     the movement-authority limit and p.Output().stop_limit_mm (if engaged).
//
// Runtime module: no heap at all (fixed arrays of kMaxCrossings), no exceptions, no
// recursion, bounded loops, typed results, deterministic. Units: mm, mm/s, mm/s^2, ms
// (int64), positions increasing in the running direction.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

#include "railproof/braking/patterns.hpp"
#include "railproof/generated/level_crossing_params.hpp"

namespace railproof::onboard {

// Crossings handled at once by one on-board unit, one controller group or one departure
// (parameter max_crossings).
inline constexpr std::size_t kMaxCrossings =
    static_cast<std::size_t>(params::level_crossing::max_crossings);

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
  kExtentInvalid,       // near_mm >= far_mm, or |near|, |far| > braking::kMaxPositionMm
  kWarningTimeInvalid,  // warning_time_ms not in 1..kMaxWarningTimeMs
  kDuplicateId,         // id already present
  kUnsorted,            // near_mm < near_mm of the previous crossing
  kOverlap,             // near_mm < far_mm of the previous crossing
  kTooMany,             // more than kMaxCrossings
};

constexpr const char* ToString(CrossingDataError e) noexcept {
  switch (e) {
    case CrossingDataError::kNone: return "NONE";
    case CrossingDataError::kExtentInvalid: return "EXTENT_INVALID";
    case CrossingDataError::kWarningTimeInvalid: return "WARNING_TIME_INVALID";
    case CrossingDataError::kDuplicateId: return "DUPLICATE_ID";
    case CrossingDataError::kUnsorted: return "UNSORTED";
    case CrossingDataError::kOverlap: return "OVERLAP";
    case CrossingDataError::kTooMany: return "TOO_MANY";
  }
  return "INVALID";
}

struct CrossingDataCheck {
  CrossingDataError error = CrossingDataError::kNone;
  std::size_t entry = 0;  // index of the offending crossing (0 if none)
};

// Validates a list of crossings (sorted by near edge, non-overlapping, unique ids, at most
// kMaxCrossings).
// @implements REQ-LC-001 REQ-LC-008
CrossingDataCheck ValidateCrossings(std::span<const CrossingData> crossings) noexcept;

// ---- earliest arrival (design §2) --------------------------------------------------------

// Errors of EarliestArrivalMs, checked in this order.
enum class EtaError : std::uint8_t {
  kNone,
  kPositionInvalid,      // |front_mm| or |target_mm| > braking::kMaxPositionMm
  kSpeedInvalid,         // speed not in 0..braking::kMaxMeasuredSpeedMmS
  kAccelerationInvalid,  // accel not in 0..braking::kMaxAccelerationMmS2
  kProfileInvalid,       // more than braking::kMaxProfileCapacity segments, a segment empty,
                         // unsorted, overlapping, outside kMaxPositionMm, or a limit not in
                         // 1..braking::kMaxLimitMmS
  kTimeInvalid,          // (dwell variant) |now| or |t_dep| > kMaxClockMs
};

constexpr const char* ToString(EtaError e) noexcept {
  switch (e) {
    case EtaError::kNone: return "NONE";
    case EtaError::kPositionInvalid: return "POSITION_INVALID";
    case EtaError::kSpeedInvalid: return "SPEED_INVALID";
    case EtaError::kAccelerationInvalid: return "ACCELERATION_INVALID";
    case EtaError::kProfileInvalid: return "PROFILE_INVALID";
    case EtaError::kTimeInvalid: return "TIME_INVALID";
  }
  return "INVALID";
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
//    has the limit braking::kMaxLimitMmS (no speed bound below it: faster is the safe side).
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
// Profile: braking::RestrictionSegment list sorted by begin, non-overlapping, non-empty
// (static line limits and temporary restrictions merged by the caller: the lower applies).
// Bounded: O(number of restrictions).
// @implements REQ-LC-001
EtaResult EarliestArrivalMs(std::int64_t front_mm, std::int64_t target_mm, std::int64_t speed_mm_s,
                            std::int64_t accel_max_mm_s2,
                            std::span<const braking::RestrictionSegment> profile) noexcept;

// Dwell-aware variant (design §2, REQ-LC-005) for a train standing at a scheduled stop whose
// departure is not authorised before departure_ms:
//   max(0, departure_ms - now_ms) + EarliestArrivalMs(front, target, 0, accel, profile)
// (saturating; kEtaNeverMs stays never).
// @implements REQ-LC-005
EtaResult EarliestArrivalAfterDwellMs(std::int64_t now_ms, std::int64_t departure_ms,
                                      std::int64_t front_mm, std::int64_t target_mm,
                                      std::int64_t accel_max_mm_s2,
                                      std::span<const braking::RestrictionSegment> profile) noexcept;

// ---- radio messages (train <-> crossing controller <-> centre) -------------------------------

// Status a crossing controller reports every cycle (wayside::CrossingController):
//   kOpen     controller kOpen or kOpening (barriers up or rising): not closed
//   kWarning  controller kWarning or kClosing (lights on, barriers not yet detected down)
//   kClosed   controller kClosed (barriers detected down), with the warning start
//   kFailed   controller kFailed (never closed)
// @implements REQ-LC-003 REQ-LC-006
enum class CrossingStatus : std::uint8_t { kOpen, kWarning, kClosed, kFailed };

constexpr const char* ToString(CrossingStatus s) noexcept {
  switch (s) {
    case CrossingStatus::kOpen: return "OPEN";
    case CrossingStatus::kWarning: return "WARNING";
    case CrossingStatus::kClosed: return "CLOSED";
    case CrossingStatus::kFailed: return "FAILED";
  }
  return "INVALID";
}

// Crossing report (the controller's cycle output, broadcast to trains and the centre).
// issued_ms is the controller's cycle time of the report; the on-board unit measures the age
// of a confirmation from it (design §3 "received at rx": a delayed message is as old as its
// issue, so the age from the issue time is the safe reading; with no delay both agree).
// warning_start_ms (ws) is meaningful in kWarning and kClosed (and kFailed: the start of the
// warning in force); clock_fault reports REQ-LC-013. requesters lists the trains among the
// controller's requesters (design §3 item 3: a CLOSED report clears only a train it lists; a
// crossing closed for another train is no confirmation for this one, whose own requests may
// have been lost: the warning ends when that other train withdraws).
// @implements REQ-LC-003 REQ-LC-006 REQ-LC-013
inline constexpr std::size_t kMaxReportRequesters = 16;
struct CrossingReport {
  std::uint32_t crossing_id = 0;
  CrossingStatus status = CrossingStatus::kOpen;
  std::int64_t warning_start_ms = 0;
  std::int64_t issued_ms = 0;
  bool clock_fault = false;
  std::array<std::uint32_t, kMaxReportRequesters> requesters{};
  std::size_t requester_count = 0;

  // True if train_id is among the first requester_count entries (a count above the capacity
  // is read as the capacity).
  [[nodiscard]] constexpr bool Lists(std::uint32_t train_id) const noexcept {
    const std::size_t n = requester_count < kMaxReportRequesters ? requester_count : kMaxReportRequesters;
    for (std::size_t i = 0; i < n; ++i) {
      if (requesters[i] == train_id) {
        return true;
      }
    }
    return false;
  }
};

// A request or a withdrawal of the warning of one crossing by one train (design §3:
// "Requests and withdrawals name the train and the crossing").
// @implements REQ-LC-002 REQ-LC-004
struct CrossingRequest {
  std::uint32_t train_id = 0;
  std::uint32_t crossing_id = 0;
};

// The controller's acknowledgement of a withdrawal (sent for every withdrawal received, also
// repeated ones).
// @implements REQ-LC-004 REQ-LC-007
struct WithdrawalAck {
  std::uint32_t crossing_id = 0;
  std::uint32_t train_id = 0;
};

// ---- on-board crossing function (design §3) ---------------------------------------------------

// Per-crossing state (design §3). ToString gives the names of the model and the vectors.
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-004
enum class CrossingState : std::uint8_t { kApproaching, kRequested, kCleared, kPassed, kDone };

constexpr const char* ToString(CrossingState s) noexcept {
  switch (s) {
    case CrossingState::kApproaching: return "APPROACHING";
    case CrossingState::kRequested: return "REQUESTED";
    case CrossingState::kCleared: return "CLEARED";
    case CrossingState::kPassed: return "PASSED";
    case CrossingState::kDone: return "DONE";
  }
  return "INVALID";
}

// Train and parameters. Defaults from spec/parameters/level_crossing.yaml.
struct ProtectionConfig {
  std::uint32_t train_id = 0;
  std::int64_t train_length_mm = 0;          // 1..braking::kMaxTrainLengthMm
  std::int64_t accel_max_mm_s2 = 0;          // 0..braking::kMaxAccelerationMmS2
  std::int64_t request_lead_ms = params::level_crossing::request_lead_ms;                   // 0..kMaxWarningTimeMs
  std::int64_t confirmation_max_age_ms = params::level_crossing::confirmation_max_age_ms;   // 0..kMaxWarningTimeMs
  std::int64_t protection_offset_mm = params::level_crossing::protection_offset_mm;         // 0..braking::kMaxPositionErrorMm
  std::int64_t lookahead_mm = params::level_crossing::crossing_lookahead_mm;                // 1..braking::kMaxPositionMm
};

// The parameter values of spec/parameters/level_crossing.yaml for a train.
ProtectionConfig DefaultProtectionConfig(std::uint32_t train_id, std::int64_t train_length_mm,
                                         std::int64_t accel_max_mm_s2) noexcept;

// Errors of Create, AddCrossing, LoadCrossings and Cycle (typed input validation).
// @implements REQ-LC-001 REQ-LC-014
enum class ProtectionError : std::uint8_t {
  kNone,
  // Create
  kTrainLengthInvalid,
  kAccelerationInvalid,
  kParameterInvalid,        // request_lead / max_age / offset / lookahead out of range
  // AddCrossing / LoadCrossings (see CrossingDataError)
  kCrossingExtentInvalid,
  kCrossingWarningTimeInvalid,
  kCrossingDuplicateId,
  kCrossingUnsorted,        // near before the near edge of the last crossing held
  kCrossingOverlap,
  kTooManyCrossings,
  // Cycle (the cycle is refused: see Cycle)
  kTimeWentBack,            // now_ms < now of the previous accepted cycle
  kTimeInvalid,             // |now_ms| or |departure_ms| > kMaxClockMs
  kPositionInvalid,         // |front| > kMaxPositionMm, an error not in 0..kMaxPositionErrorMm
  kSpeedInvalid,            // speed not in 0..braking::kMaxMeasuredSpeedMmS
  kDwellWhileMoving,        // dwell set with speed_mm_s != 0
  kProfileInvalid,          // restriction profile refused (see EtaError::kProfileInvalid)
  kTooManyMessages,         // more than kMaxMessagesPerCycle reports or acks
};

constexpr const char* ToString(ProtectionError e) noexcept {
  switch (e) {
    case ProtectionError::kNone: return "NONE";
    case ProtectionError::kTrainLengthInvalid: return "TRAIN_LENGTH_INVALID";
    case ProtectionError::kAccelerationInvalid: return "ACCELERATION_INVALID";
    case ProtectionError::kParameterInvalid: return "PARAMETER_INVALID";
    case ProtectionError::kCrossingExtentInvalid: return "CROSSING_EXTENT_INVALID";
    case ProtectionError::kCrossingWarningTimeInvalid: return "CROSSING_WARNING_TIME_INVALID";
    case ProtectionError::kCrossingDuplicateId: return "CROSSING_DUPLICATE_ID";
    case ProtectionError::kCrossingUnsorted: return "CROSSING_UNSORTED";
    case ProtectionError::kCrossingOverlap: return "CROSSING_OVERLAP";
    case ProtectionError::kTooManyCrossings: return "TOO_MANY_CROSSINGS";
    case ProtectionError::kTimeWentBack: return "TIME_WENT_BACK";
    case ProtectionError::kTimeInvalid: return "TIME_INVALID";
    case ProtectionError::kPositionInvalid: return "POSITION_INVALID";
    case ProtectionError::kSpeedInvalid: return "SPEED_INVALID";
    case ProtectionError::kDwellWhileMoving: return "DWELL_WHILE_MOVING";
    case ProtectionError::kProfileInvalid: return "PROFILE_INVALID";
    case ProtectionError::kTooManyMessages: return "TOO_MANY_MESSAGES";
  }
  return "INVALID";
}

// Most reports and most acknowledgements accepted per cycle (each).
inline constexpr std::size_t kMaxMessagesPerCycle = 64;

// One on-board cycle's inputs (plain integers: the conformance runner fills them directly).
//   front_mm, front_error_mm, rear_error_mm   position envelope (odometry, REQ-RA-012):
//                                              front_max = front + front_error,
//                                              rear_min = front - length - rear_error
//   speed_mm_s                                 an upper bound of the speed: pass the supervised
//                                              speed v_s of braking (safe reading of "its speed")
//   dwell, departure_ms                        standing at a scheduled stop whose departure is
//                                              not authorised before departure_ms (REQ-LC-005);
//                                              requires speed_mm_s == 0
//   restrictions                               the permitted-speed profile (as for
//                                              EarliestArrivalMs)
//   reports                                    crossing reports received since the last cycle,
//                                              in reception order; reports of crossings not
//                                              held are ignored (counted)
//   acks                                       withdrawal acknowledgements received; acks for
//                                              another train or an unknown crossing are ignored
struct ProtectionInput {
  std::int64_t now_ms = 0;
  std::int64_t front_mm = 0;
  std::int64_t front_error_mm = 0;
  std::int64_t rear_error_mm = 0;
  std::int64_t speed_mm_s = 0;
  bool dwell = false;
  std::int64_t departure_ms = 0;
  std::span<const braking::RestrictionSegment> restrictions;
  std::span<const CrossingReport> reports;
  std::span<const WithdrawalAck> acks;
};

// One crossing held by the on-board unit and its state (readable for the vectors).
//   eta_ms          ETA to near computed this cycle (kEtaNeverMs if never; -1 if not computed:
//                   kPassed / kDone)
//   within_lookahead near - front_max <= lookahead this cycle (requests only then)
//   cleared_ws_ms   warning start of the confirmation that cleared it (kCleared), else 0
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-004
struct CrossingEntry {
  CrossingData data{};
  CrossingState state = CrossingState::kApproaching;
  std::int64_t eta_ms = -1;
  bool within_lookahead = false;
  std::int64_t cleared_ws_ms = 0;
};

// One cycle's outputs.
//   Requests()      crossing ids whose request is sent this cycle (kRequested, kCleared)
//   Withdrawals()   crossing ids whose withdrawal is sent this cycle (kPassed)
//   stop_limit_mm   the most restrictive protection limit near - protection_offset_mm over the
//                   crossings in kApproaching or kRequested (empty if none); for the braking
//                   supervision (braking::PatternCalculator::Evaluate), combined with the
//                   movement authority by the caller (the smaller wins)
//   limiting_crossing_id  the crossing giving stop_limit_mm (0 if none)
//   ignored_messages reports / acks ignored this cycle (unknown crossing, other train, issue
//                   time in the future)
// The messages carry the train id of the configuration (CrossingRequest).
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-004
struct ProtectionOutput {
  std::array<std::uint32_t, kMaxCrossings> requests{};
  std::size_t request_count = 0;
  std::array<std::uint32_t, kMaxCrossings> withdrawals{};
  std::size_t withdrawal_count = 0;
  std::optional<std::int64_t> stop_limit_mm;
  std::uint32_t limiting_crossing_id = 0;
  std::size_t ignored_messages = 0;

  [[nodiscard]] std::span<const std::uint32_t> Requests() const noexcept {
    return {requests.data(), request_count};
  }
  [[nodiscard]] std::span<const std::uint32_t> Withdrawals() const noexcept {
    return {withdrawals.data(), withdrawal_count};
  }
};

struct CrossingProtectionResult;

// The on-board crossing function of design §3.
// @implements REQ-LC-001 REQ-LC-002 REQ-LC-003 REQ-LC-004 REQ-LC-005 REQ-LC-014
class CrossingProtection {
 public:
  using CreateResult = CrossingProtectionResult;

  // Validates the configuration (kNone: engaged). No crossing held.
  static CreateResult Create(const ProtectionConfig& config) noexcept;

  // Appends a crossing of the journey in state kApproaching. It must lie beyond the last one
  // held (near >= its far). Refused (no change) with the kCrossing* / kTooManyCrossings error.
  ProtectionError AddCrossing(const CrossingData& crossing) noexcept;
  // Replaces every crossing held by `crossings` (all kApproaching); on an error nothing is
  // held (the caller must not run without its crossings).
  ProtectionError LoadCrossings(std::span<const CrossingData> crossings) noexcept;
  // Drops the crossings in kDone (frees capacity on long journeys; order kept).
  void DropDone() noexcept;

  // One cycle at input.now_ms, in the order of design §3 for every crossing held:
  //  0. ETA: within_lookahead = near - front_max <= lookahead; for kApproaching / kRequested /
  //     kCleared the ETA from front_max to near (dwell: EarliestArrivalAfterDwellMs).
  //  1. Passage: rear_min >= far and not kDone -> kPassed. A kPassed crossing (already kPassed
  //     before this cycle) with a withdrawal ack for it in input.acks -> kDone.
  //  2. Request: kApproaching, within_lookahead and ETA <= warning_time + request_lead_ms ->
  //     kRequested.
  //  3. Reports of the crossing in input order (a report issued after now is ignored):
  //     kRequested and a report kClosed with now - issued <= confirmation_max_age_ms and
  //     ws + warning_time <= now + ETA -> kCleared; kCleared and a report that is not
  //     kClosed (OPEN, WARNING, FAILED) -> kRequested (design §3 names FAILED and OPEN; a
  //     WARNING report after a clearance means the controller restarted its warning, so the
  //     old closure no longer holds: the safe reading re-protects on it too).
  //  4. Outputs: requests (kRequested, kCleared), withdrawals (kPassed), stop limit.
  // An error (time back, invalid input) refuses the cycle: states unchanged, the outputs are
  // recomputed from the unchanged states (requests, withdrawals and the protection limit keep
  // being given: safe side), last cycle time unchanged.
  ProtectionError Cycle(const ProtectionInput& input) noexcept;

  [[nodiscard]] const ProtectionOutput& Output() const noexcept { return output_; }
  [[nodiscard]] std::span<const CrossingEntry> Entries() const noexcept {
    return {entries_.data(), count_};
  }
  // The crossing with this id, nullptr if not held.
  [[nodiscard]] const CrossingEntry* Find(std::uint32_t crossing_id) const noexcept;
  [[nodiscard]] const ProtectionConfig& Config() const noexcept { return config_; }
  // now of the last accepted cycle (empty before the first).
  [[nodiscard]] std::optional<std::int64_t> LastCycleMs() const noexcept { return last_now_; }

 private:
  explicit CrossingProtection(const ProtectionConfig& config) noexcept : config_(config) {}
  CrossingEntry* FindMutable(std::uint32_t crossing_id) noexcept;
  void ComputeOutputs() noexcept;

  ProtectionConfig config_;
  std::array<CrossingEntry, kMaxCrossings> entries_{};
  std::size_t count_ = 0;
  std::optional<std::int64_t> last_now_;
  ProtectionOutput output_{};
};

struct CrossingProtectionResult {
  ProtectionError error = ProtectionError::kNone;
  std::optional<CrossingProtection> protection;  // engaged iff error == kNone
};

}  // namespace railproof::onboard
