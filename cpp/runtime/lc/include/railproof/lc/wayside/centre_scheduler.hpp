// Centre scheduler of the GNSS-time pre-armed crossings (spec/design/lc.md §5;
// D4 §4.8.2; model: the centre process of models/lc.pml, GNSS configuration).
// One scheduler per train run between two stops: for a departure (train, departure_id,
// t_dep) from station A to the next stop B it computes the start time of every crossing in
// between, sends it until acknowledged, clears the departure signal, recomputes the start
// times from the position reports and sends the warning stop after the passage.
//
// Usage:
//   auto created = CentreScheduler::Create(DefaultSchedulerConfig(accel_max));
//   CentreScheduler& s = *created.scheduler;
//   s.StartDeparture({train, departure_id, t_dep, front_at_A}, crossings_A_to_B, profile, now);
//   every centre cycle:
//     SchedulerInput in{now, start_acks, stop_acks, crossing_reports, position_report, profile};
//     s.Cycle(in);
//     send s.Output().StartTimes() and s.Output().WarningStops();
//     departure signal of the train: s.Output().departure_cleared.
//
// Runtime module: no heap at all (fixed arrays), no exceptions, no recursion, bounded loops,
// typed results, deterministic. Units: mm, mm/s, mm/s^2, ms (int64). Times are the centre's
// GNSS clock.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/track.hpp"
#include "railproof/core/units.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/messages/crossing.hpp"
#include "railproof/messages/position_report.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"

namespace railproof::lc::wayside {

using lc::CrossingData;
using lc::kMaxCrossings;

// Most acknowledgements / reports accepted per list per cycle.
inline constexpr std::size_t kMaxSchedulerMessages = 64;

// Parameters.
//   accel_max_mm_s2     the train's maximum acceleration (1..core::kMaxAccelerationMmS2)
//   clock_allowance_ms  start times are advanced by it (0..lc::kMaxWarningTimeMs)
struct SchedulerConfig {
  std::int64_t accel_max_mm_s2 = 0;
  std::int64_t clock_allowance_ms = params::lc::clock_allowance_ms;
};

SchedulerConfig DefaultSchedulerConfig(std::int64_t accel_max_mm_s2) noexcept;

// A planned departure from station A: front_mm is the front of the train's position
// envelope (front_max) standing at A.
struct Departure {
  std::uint32_t train_id = 0;
  std::uint32_t departure_id = 0;
  std::int64_t departure_ms = 0;  // t_dep, planned (earliest) departure time
  std::int64_t front_mm = 0;
};

using messages::CentrePositionReport;  // railproof/messages/position_report.hpp

// Why the departure signal is not cleared this cycle (first reason found, in this order).
// @implements REQ-LC-009 REQ-LC-013
enum class DepartureBlock : std::uint8_t {
  kNone,            // cleared
  kNoDeparture,     // no departure started
  kMissingAck,      // a crossing has not acknowledged this departure's start time
  kClockFault,      // a crossing reported a clock fault (last report)
  kBeforeDeparture, // now < t_dep
};

constexpr const char* ToString(DepartureBlock b) noexcept {
  return core::EnumName(b, std::array<const char*, 5>{"NONE", "NO_DEPARTURE", "MISSING_ACK", "CLOCK_FAULT", "BEFORE_DEPARTURE"});
}

// Errors of Create / StartDeparture / Cycle.
// @implements REQ-LC-008 REQ-LC-012
enum class SchedulerError : std::uint8_t {
  kNone,
  kConfigInvalid,          // Create: a parameter out of range
  kCrossingDataInvalid,    // StartDeparture: see crossing_error (lc::ValidateCrossings)
  kPositionInvalid,        // front / rear out of core::kMaxPositionMm, or rear > front
  kSpeedInvalid,           // report speed not in 0..core::kMaxMeasuredSpeedMmS
  kProfileInvalid,         // restriction profile refused (lc::EtaError::kProfileInvalid)
  kTimeInvalid,            // a time out of lc::kMaxClockMs
  kTimeWentBack,           // now < now of the previous accepted call
  kNoDeparture,            // Cycle before any StartDeparture
  kTooManyMessages,        // an input list longer than kMaxSchedulerMessages
};

constexpr const char* ToString(SchedulerError e) noexcept {
  return core::EnumName(e, std::array<const char*, 10>{"NONE", "CONFIG_INVALID", "CROSSING_DATA_INVALID", "POSITION_INVALID", "SPEED_INVALID", "PROFILE_INVALID", "TIME_INVALID", "TIME_WENT_BACK", "NO_DEPARTURE", "TOO_MANY_MESSAGES"});
}

// One centre cycle's inputs.
//   start_acks / stop_acks  acknowledgements of the controllers received since the last cycle
//   reports                 crossing reports received (only clock_fault is used: the last
//                           report of a crossing decides)
//   position                a position report of the departure's train, if one arrived
//                           (reports of another train id are ignored, counted)
//   restrictions            the permitted-speed profile for the recomputation
// Entries for crossings not of this departure, or acks of another departure, are ignored
// (counted in ignored_messages).
struct SchedulerInput {
  std::int64_t now_ms = 0;
  std::span<const StartTimeAck> start_acks;
  std::span<const WarningStopAck> stop_acks;
  std::span<const CrossingReport> reports;
  std::optional<CentrePositionReport> position;
  std::span<const core::RestrictionSegment> restrictions;
};

// The per-crossing state of the departure (readable for the vectors).
//   initial_start_ms   st_i = t_dep + ETA_i(from rest at A) - warning_time_i - clock_allowance
//   start_ms           the start time last computed and sent (initial, then updates)
//   start_pending      start_ms is (re-)sent every cycle until acknowledged
//   acked              an ack of this departure with start <= initial_start_ms arrived (latched)
//   acked_start_ms     start time in force at the controller by its last ack
//   clock_fault        the last report of the crossing showed a clock fault
//   passed             a plausible passage report arrived (rear_min >= far)
//   stop_pending       the warning stop is (re-)sent every cycle until acknowledged
//   stop_acked         the warning stop was acknowledged
// @implements REQ-LC-008 REQ-LC-009 REQ-LC-010 REQ-LC-012
struct ScheduledCrossing {
  CrossingData data{};
  std::int64_t initial_start_ms = 0;
  std::int64_t start_ms = 0;
  bool start_pending = false;
  bool acked = false;
  std::int64_t acked_start_ms = 0;
  bool clock_fault = false;
  bool passed = false;
  bool stop_pending = false;
  bool stop_acked = false;
};

// One cycle's outputs.
// @implements REQ-LC-008 REQ-LC-009 REQ-LC-010 REQ-LC-012
struct SchedulerOutput {
  std::array<StartTimeMessage, kMaxCrossings> start_times{};
  std::size_t start_time_count = 0;
  std::array<WarningStopMessage, kMaxCrossings> warning_stops{};
  std::size_t warning_stop_count = 0;
  bool departure_cleared = false;
  DepartureBlock block = DepartureBlock::kNoDeparture;
  bool report_rejected = false;  // this cycle's position report was implausible (ignored)
  std::size_t ignored_messages = 0;

  [[nodiscard]] std::span<const StartTimeMessage> StartTimes() const noexcept {
    return {start_times.data(), start_time_count};
  }
  [[nodiscard]] std::span<const WarningStopMessage> WarningStops() const noexcept {
    return {warning_stops.data(), warning_stop_count};
  }
};

struct CentreSchedulerResult;

// @implements REQ-LC-008 REQ-LC-009 REQ-LC-010 REQ-LC-012 REQ-LC-013 REQ-LC-014
class CentreScheduler {
 public:
  using CreateResult = CentreSchedulerResult;

  static CreateResult Create(const SchedulerConfig& config) noexcept;

  // Starts a departure (replaces any previous one): validates the crossings (sorted,
  // non-overlapping, unique, <= kMaxCrossings; crossing_error tells which) and the profile,
  // computes st_i for each (design §5 step 1, REQ-LC-008) and marks every start time
  // pending; the tracked front is departure.front_mm. now_ms is the centre time (must not go
  // back). On an error no departure is held (Cycle then refuses with kNoDeparture).
  SchedulerError StartDeparture(const Departure& departure, std::span<const CrossingData> crossings,
                                std::span<const core::RestrictionSegment> restrictions,
                                std::int64_t now_ms) noexcept;

  // One centre cycle (design §5), in this order:
  //  1. Reports: the clock_fault of each crossing's last report.
  //  2. Start-time acks of this departure with stored set (others: ignored, the start time
  //     keeps being re-sent): ack start <= initial_start_ms -> acked (latched);
  //     acked_start_ms = ack start; ack start <= start_ms ends the re-sending of start_ms
  //     (start_pending false: the time in force is no later than the one sent).
  //     Stop acks of this departure for a crossing with a stop sent -> stop_acked, stop_pending
  //     false.
  //  3. Position report (of this train): plausible iff front >= tracked front (not behind the
  //     previously tracked front) and time_ms <= now; an implausible report is ignored
  //     (report_rejected). For a plausible one: tracked front = front; for each crossing not
  //     passed: rear >= far -> passed, stop_pending, start_pending false (REQ-LC-012);
  //     else st' = time_ms + ETA - warning_time - clock_allowance with
  //     ETA = lc::EarliestArrivalMs(front, near, speed, accel_max, restrictions)
  //     (standing before t_dep: EarliestArrivalAfterDwellMs from t_dep); st' != start_ms ->
  //     start_ms = st', start_pending (REQ-LC-010; an earlier st' is sent as well: the
  //     controller accepts earlier times always, so this is the safe extension of "if later").
  //  4. Outputs: the pending start times and warning stops; departure_cleared iff every
  //     crossing acked, no clock fault, now >= t_dep (REQ-LC-009, REQ-LC-013).
  // An error refuses the cycle: nothing changes, outputs recomputed from the unchanged state.
  SchedulerError Cycle(const SchedulerInput& input) noexcept;

  [[nodiscard]] const SchedulerOutput& Output() const noexcept { return output_; }
  [[nodiscard]] std::span<const ScheduledCrossing> Crossings() const noexcept {
    return {crossings_.data(), count_};
  }
  [[nodiscard]] const ScheduledCrossing* Find(std::uint32_t crossing_id) const noexcept;
  [[nodiscard]] const std::optional<Departure>& CurrentDeparture() const noexcept { return departure_; }
  [[nodiscard]] std::int64_t TrackedFrontMm() const noexcept { return tracked_front_mm_; }
  // The crossing-data error of the last refused StartDeparture.
  [[nodiscard]] lc::CrossingDataCheck CrossingError() const noexcept { return crossing_error_; }
  [[nodiscard]] const SchedulerConfig& Config() const noexcept { return config_; }

 private:
  explicit CentreScheduler(const SchedulerConfig& config) noexcept : config_(config) {}
  ScheduledCrossing* FindMutable(std::uint32_t crossing_id) noexcept;
  void ComputeOutputs(std::int64_t now_ms) noexcept;

  SchedulerConfig config_;
  std::optional<Departure> departure_;
  std::array<ScheduledCrossing, kMaxCrossings> crossings_{};
  std::size_t count_ = 0;
  std::int64_t tracked_front_mm_ = 0;
  std::optional<std::int64_t> last_now_;
  lc::CrossingDataCheck crossing_error_{};
  SchedulerOutput output_{};
};

struct CentreSchedulerResult {
  SchedulerError error = SchedulerError::kNone;
  std::optional<CentreScheduler> scheduler;  // engaged iff error == kNone
};

}  // namespace railproof::lc::wayside
