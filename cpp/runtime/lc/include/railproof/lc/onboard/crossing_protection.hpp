// Level-crossing protection, on-board part and the pieces shared with the ground
// (spec/design/lc.md §1-§3; model: models/lc.pml):
//   CrossingData / CrossingExtentOf   crossing geometry [near, far) and design warning time (§1)
//   EarliestArrivalMs                 earliest arrival of the front at a position (§2,
//   EarliestArrivalAfterDwellMs       REQ-LC-001, REQ-LC-005); also used by the centre
//                                     (lc::wayside::CentreScheduler) and the warning-time study
//   CrossingReport, WithdrawalAck,    radio messages between the train, the crossing
//   CrossingRequest                   controllers (lc::wayside::CrossingController) and the centre
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
//     stop limit for br::PatternCalculator::Evaluate: the more restrictive (smaller) of
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

#include "railproof/core/enum_names.hpp"
#include "railproof/core/track.hpp"
#include "railproof/core/units.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/messages/crossing.hpp"
#include "railproof/generated/lc_params.hpp"

namespace railproof::lc::onboard {

using messages::CrossingReport;
using messages::CrossingRequest;
using messages::CrossingStatus;
using messages::WithdrawalAck;

// ---- on-board crossing function (design §3) ---------------------------------------------------

// Per-crossing state (design §3). ToString gives the names of the model and the vectors.
// @implements REQ-LC-002 REQ-LC-003 REQ-LC-004
enum class CrossingState : std::uint8_t { kApproaching, kRequested, kCleared, kPassed, kDone };

constexpr const char* ToString(CrossingState s) noexcept {
  return core::EnumName(s, std::array<const char*, 5>{"APPROACHING", "REQUESTED", "CLEARED", "PASSED", "DONE"});
}

// Train and parameters. Defaults from spec/parameters/level_crossing.yaml.
struct ProtectionConfig {
  std::uint32_t train_id = 0;
  std::int64_t train_length_mm = 0;          // 1..core::kMaxTrainLengthMm
  std::int64_t accel_max_mm_s2 = 0;          // 0..core::kMaxAccelerationMmS2
  std::int64_t request_lead_ms = params::lc::request_lead_ms;                   // 0..kMaxWarningTimeMs
  std::int64_t confirmation_max_age_ms = params::lc::confirmation_max_age_ms;   // 0..kMaxWarningTimeMs
  std::int64_t protection_offset_mm = params::lc::protection_offset_mm;         // 0..core::kMaxPositionErrorMm
  std::int64_t lookahead_mm = params::lc::crossing_lookahead_mm;                // 1..core::kMaxPositionMm
};

// The parameter values of spec/parameters/lc.yaml for a train.
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
  kSpeedInvalid,            // speed not in 0..core::kMaxMeasuredSpeedMmS
  kDwellWhileMoving,        // dwell set with speed_mm_s != 0
  kProfileInvalid,          // restriction profile refused (see EtaError::kProfileInvalid)
  kTooManyMessages,         // more than kMaxMessagesPerCycle reports or acks
};

constexpr const char* ToString(ProtectionError e) noexcept {
  return core::EnumName(e, std::array<const char*, 17>{"NONE", "TRAIN_LENGTH_INVALID", "ACCELERATION_INVALID", "PARAMETER_INVALID", "CROSSING_EXTENT_INVALID", "CROSSING_WARNING_TIME_INVALID", "CROSSING_DUPLICATE_ID", "CROSSING_UNSORTED", "CROSSING_OVERLAP", "TOO_MANY_CROSSINGS", "TIME_WENT_BACK", "TIME_INVALID", "POSITION_INVALID", "SPEED_INVALID", "DWELL_WHILE_MOVING", "PROFILE_INVALID", "TOO_MANY_MESSAGES"});
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
  std::span<const core::RestrictionSegment> restrictions;
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
//                   supervision (br::PatternCalculator::Evaluate), combined with the
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
  // Holds one more crossing (kApproaching); the caller checked it and the capacity.
  void Append(const CrossingData& crossing) noexcept;
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

}  // namespace railproof::lc::onboard
