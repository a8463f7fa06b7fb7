// Level-crossing controller on the ground (spec/design/lc.md §4, §5 step 2 and
// the clock rule; model: the controller process of models/lc.pml). One
// controller per crossing; one Cycle per ground cycle. It serves both variants at once:
// warning requests of trains (on-board-requested crossings, D5 §5.3) and the stored start
// time of the centre (GNSS-time pre-armed crossings, D4 §4.8.2).
//
// Usage:
//   auto created = CrossingController::Create(DefaultControllerConfig(crossing_id));
//   CrossingController& c = *created.controller;
//   every ground cycle:
//     ControllerInput in{now, request_train_ids, withdrawal_train_ids, down, up,
//                        start_times, warning_stops, clock};
//     c.Cycle(in);
//     broadcast c.Output().report; send c.Output().WithdrawalAcks(), StartAcks(), StopAcks();
//     drive the lights (lights_on) and the barriers (barriers_down_commanded).
//
// Runtime module: no heap at all (fixed arrays), no exceptions, no recursion, bounded loops,
// typed results, deterministic. Units: ms (int64). All times are the controller's clock.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/messages/crossing.hpp"

namespace railproof::lc::wayside {

using messages::CrossingReport;
using messages::CrossingStatus;

// Trains whose requests one controller holds at once (the report lists all of them).
inline constexpr std::size_t kMaxRequesters = messages::kMaxReportRequesters;
// Most entries per input list (requests, withdrawals, start times, warning stops) per cycle.
inline constexpr std::size_t kMaxControllerMessages = 32;

// Controller states (design §4). ToString gives the names of the model and the vectors.
// @implements REQ-LC-006 REQ-LC-007
enum class ControllerState : std::uint8_t { kOpen, kWarning, kClosing, kClosed, kOpening, kFailed };

constexpr const char* ToString(ControllerState s) noexcept {
  return core::EnumName(s, std::array<const char*, 6>{"OPEN", "WARNING", "CLOSING", "CLOSED", "OPENING", "FAILED"});
}

// What the clock hardware tells this cycle (REQ-LC-013):
//   kGnss     GNSS time received, clock synchronised (within gnss_sync_accuracy_ms)
//   kNoGnss   no GNSS time: the clock holds over
//   kFault    the clock itself reports a fault (oscillator, self-test)
enum class ClockInput : std::uint8_t { kGnss, kNoGnss, kFault };

constexpr const char* ToString(ClockInput c) noexcept {
  return core::EnumName(c, std::array<const char*, 3>{"GNSS", "NO_GNSS", "FAULT"});
}

// Clock state of the controller (REQ-LC-013). kFaulty is latched until MaintenanceReset
// (safe reading: a clock that was faulty is not trusted again on its own).
// @implements REQ-LC-013
enum class ClockState : std::uint8_t { kSynchronised, kHoldover, kFaulty };

constexpr const char* ToString(ClockState c) noexcept {
  return core::EnumName(c, std::array<const char*, 3>{"SYNCHRONISED", "HOLDOVER", "FAULTY"});
}

// Why the controller is kFailed.
// @implements REQ-LC-006 REQ-LC-014
enum class FailureReason : std::uint8_t {
  kNone,
  kBarrierNotDown,    // kClosing: down not detected by ws + barrier_lowering_ms + barrier_timeout_ms
  kBarrierDownLost,   // kClosed: down no longer detected
  kBarrierNotUp,      // kOpening: up not detected within barrier_timeout_ms
};

constexpr const char* ToString(FailureReason r) noexcept {
  return core::EnumName(r, std::array<const char*, 4>{"NONE", "BARRIER_NOT_DOWN", "BARRIER_DOWN_LOST", "BARRIER_NOT_UP"});
}

// Parameters (spec/parameters/lc.yaml).
struct ControllerConfig {
  std::uint32_t crossing_id = 0;
  std::int64_t barrier_lowering_ms = params::lc::barrier_lowering_ms;  // 0..kMaxWarningTimeMs
  std::int64_t barrier_timeout_ms = params::lc::barrier_timeout_ms;    // 1..kMaxWarningTimeMs
  std::int64_t max_warning_ms = params::lc::max_warning_ms;            // 1..lc::kMaxClockMs
  std::int64_t holdover_max_ms = params::lc::holdover_max_ms;          // 0..lc::kMaxClockMs
};

ControllerConfig DefaultControllerConfig(std::uint32_t crossing_id) noexcept;

// Start time of a departure for this crossing (centre -> controller, design §5 steps 1, 4).
// @implements REQ-LC-008 REQ-LC-010
struct StartTimeMessage {
  std::uint32_t crossing_id = 0;
  std::uint32_t departure_id = 0;
  std::int64_t start_ms = 0;
};

// Warning stop of a departure for this crossing (centre -> controller, design §5 step 5).
// @implements REQ-LC-012
struct WarningStopMessage {
  std::uint32_t crossing_id = 0;
  std::uint32_t departure_id = 0;
};

// Acknowledgement of a start-time message (every message for this crossing is acknowledged).
//   stored    true: departure_id is the controller's pending departure after the message and
//             start_ms is its start time in force (the message's time if it was taken; the
//             earlier time in force if a later time was refused because the warning had
//             started, REQ-LC-010 "a lost update leaves the earlier time"). false: nothing
//             stored for departure_id (another departure is pending, or this departure's
//             warning stop was already received); start_ms is the message's time.
// The centre counts an ack for its departure only with stored (CentreScheduler::Cycle).
// @implements REQ-LC-009 REQ-LC-010
struct StartTimeAck {
  std::uint32_t crossing_id = 0;
  std::uint32_t departure_id = 0;
  std::int64_t start_ms = 0;
  bool stored = false;
};

// Acknowledgement of a warning stop (sent for every stop received, also repeated ones).
// @implements REQ-LC-012
struct WarningStopAck {
  std::uint32_t crossing_id = 0;
  std::uint32_t departure_id = 0;
};

// One ground cycle's inputs (plain integers: the conformance runner fills them directly).
//   requests / withdrawals    train ids whose request / withdrawal arrived since the last
//                             cycle (for this crossing; the radio layer dispatches by id)
//   barrier_down / barrier_up barrier detection this cycle; both set at once is inconsistent
//                             and taken as neither (the barrier timers then fail the crossing)
//   start_times, warning_stops centre messages since the last cycle; entries for another
//                             crossing id are ignored (counted in ignored_messages)
//   clock                     clock hardware status this cycle
struct ControllerInput {
  std::int64_t now_ms = 0;
  std::span<const std::uint32_t> requests;
  std::span<const std::uint32_t> withdrawals;
  bool barrier_down = false;
  bool barrier_up = true;
  std::span<const StartTimeMessage> start_times;
  std::span<const WarningStopMessage> warning_stops;
  ClockInput clock = ClockInput::kGnss;
};

// The stored departure start time (design §5 step 2). One pending departure per controller
// (see Cycle, step 3). active: now >= start_ms was reached (its warning is due / running).
// @implements REQ-LC-010 REQ-LC-011
struct PendingDeparture {
  bool present = false;
  std::uint32_t departure_id = 0;
  std::int64_t start_ms = 0;
  bool active = false;
};

// One cycle's outputs.
//   report                  broadcast every cycle (status, ws, issue time = now, clock fault)
//   lights_on               every state but kOpen
//   barriers_down_commanded kClosing, kClosed, kFailed (a failed crossing keeps commanding
//                           down: best effort, it never reports CLOSED)
//   alarm                   the current warning episode (left kOpen at episode_start) is
//                           longer than max_warning_ms; it never ends the warning
//   acks                    this cycle's acknowledgements
// @implements REQ-LC-006 REQ-LC-007 REQ-LC-009 REQ-LC-012 REQ-LC-013
struct ControllerOutput {
  CrossingReport report{};
  bool lights_on = false;
  bool barriers_down_commanded = false;
  bool alarm = false;
  std::array<std::uint32_t, kMaxControllerMessages> withdrawal_acks{};  // train ids
  std::size_t withdrawal_ack_count = 0;
  std::array<StartTimeAck, kMaxControllerMessages> start_acks{};
  std::size_t start_ack_count = 0;
  std::array<WarningStopAck, kMaxControllerMessages> stop_acks{};
  std::size_t stop_ack_count = 0;
  std::size_t ignored_messages = 0;

  [[nodiscard]] std::span<const std::uint32_t> WithdrawalAcks() const noexcept {
    return {withdrawal_acks.data(), withdrawal_ack_count};
  }
  [[nodiscard]] std::span<const StartTimeAck> StartAcks() const noexcept {
    return {start_acks.data(), start_ack_count};
  }
  [[nodiscard]] std::span<const WarningStopAck> StopAcks() const noexcept {
    return {stop_acks.data(), stop_ack_count};
  }
};

// The full state (for the vectors and diagnostics).
//   warning_start_ms  ws of the current warning (kWarning..kClosed, kOpening, kFailed)
//   episode_start_ms  when the controller last left kOpen (alarm timer)
//   phase_start_ms    when kClosing / kOpening was entered (barrier timers)
//   requester_overflow a request could not be stored (more than kMaxRequesters trains): the
//                     warning is then never ended until MaintenanceReset (safe side)
//   last_stopped_departure  the departure of the last warning stop received
//   outage_start_ms   start of the GNSS outage (kHoldover)
struct ControllerStatus {
  ControllerState state = ControllerState::kOpen;
  std::int64_t warning_start_ms = 0;
  std::int64_t episode_start_ms = 0;
  std::int64_t phase_start_ms = 0;
  std::array<std::uint32_t, kMaxRequesters> requesters{};
  std::size_t requester_count = 0;
  bool requester_overflow = false;
  PendingDeparture pending{};
  std::optional<std::uint32_t> last_stopped_departure;
  ClockState clock = ClockState::kSynchronised;
  std::int64_t outage_start_ms = 0;
  bool alarm = false;
  FailureReason failure = FailureReason::kNone;
  std::optional<std::int64_t> last_cycle_ms;

  [[nodiscard]] std::span<const std::uint32_t> Requesters() const noexcept {
    return {requesters.data(), requester_count};
  }
};

// @implements REQ-LC-006 REQ-LC-007
enum class ControllerError : std::uint8_t {
  kNone,
  kConfigInvalid,      // Create: a parameter out of range
  kTimeWentBack,       // Cycle: now_ms < now of the previous accepted cycle
  kTimeInvalid,        // Cycle: |now_ms| > lc::kMaxClockMs, or a start time out of range
  kTooManyMessages,    // Cycle: an input list longer than kMaxControllerMessages
};

constexpr const char* ToString(ControllerError e) noexcept {
  return core::EnumName(e, std::array<const char*, 5>{"NONE", "CONFIG_INVALID", "TIME_WENT_BACK", "TIME_INVALID", "TOO_MANY_MESSAGES"});
}

struct CrossingControllerResult;

// @implements REQ-LC-006 REQ-LC-007 REQ-LC-009 REQ-LC-010 REQ-LC-011 REQ-LC-013 REQ-LC-014
class CrossingController {
 public:
  using CreateResult = CrossingControllerResult;

  // Validates the configuration. Starts kOpen, no requester, no pending departure, clock
  // synchronised.
  static CreateResult Create(const ControllerConfig& config) noexcept;

  // One ground cycle at input.now_ms (design §4), in this order:
  //  1. Clock: kFault -> kFaulty (latched); kNoGnss: kSynchronised -> kHoldover (outage starts
  //     now), kHoldover and now - outage_start > holdover_max_ms -> kFaulty; kGnss: kHoldover
  //     -> kSynchronised.
  //  2. Requests add their train to requesters; withdrawals remove it and are acknowledged
  //     (every withdrawal, also of a train not held).
  //  3. Start times (in input order, entries for this crossing): a departure whose warning
  //     stop was received last (last_stopped_departure) -> not stored (a late repetition must
  //     not re-arm the crossing); no pending departure -> stored; same departure: earlier or
  //     equal -> stored (at any time); later -> stored only while kOpen and not active, else
  //     the earlier time stays in force; another departure while one is pending -> not stored
  //     (one pending departure per controller: replacing it could lose its warning; the
  //     centre re-sends until stored and does not clear that departure meanwhile). Every
  //     entry is acknowledged (StartTimeAck).
  //     Warning stops: acknowledged; last_stopped_departure = its departure; one for the
  //     pending departure removes it.
  //     Then: pending present and now >= start -> active.
  //  4. State (one transition at most):
  //     kOpen / kOpening: a warning trigger (requesters non-empty, pending active, clock
  //       kFaulty) -> kWarning with ws = now (kOpen: the episode starts now);
  //       else kOpening: up detected -> kOpen; now - phase_start >= barrier_timeout_ms ->
  //       kFailed (kBarrierNotUp).
  //     kWarning: now - ws >= barrier_lowering_ms -> kClosing (phase_start = now).
  //     kClosing: down detected -> kClosed; else now >= ws + barrier_lowering_ms +
  //       barrier_timeout_ms -> kFailed (kBarrierNotDown).
  //     kClosed: down not detected -> kFailed (kBarrierDownLost); else the end of warning:
  //       no requester, no requester overflow, no pending active departure and the clock
  //       not kFaulty -> kOpening (phase_start = now). (REQ-LC-007: on-board variant "every
  //       requester withdrew", GNSS variant "the warning stop of the current departure was
  //       received"; a controller serving both needs both.)
  //     kFailed: stays (MaintenanceReset only).
  //  5. Alarm: state != kOpen and now - episode_start > max_warning_ms; outputs.
  // An error refuses the cycle: nothing changes, the outputs are recomputed from the
  // unchanged state without acknowledgements.
  ControllerError Cycle(const ControllerInput& input) noexcept;

  // Maintenance reset (outside the automatic function, ASM-030): kOpen, no failure, no alarm,
  // clock kSynchronised; requesters and the pending departure are kept (a train that still
  // needs the warning starts it again in the next cycle).
  void MaintenanceReset() noexcept;

  [[nodiscard]] const ControllerOutput& Output() const noexcept { return output_; }
  [[nodiscard]] const ControllerStatus& Status() const noexcept { return status_; }
  [[nodiscard]] ControllerState State() const noexcept { return status_.state; }
  [[nodiscard]] const ControllerConfig& Config() const noexcept { return config_; }

 private:
  explicit CrossingController(const ControllerConfig& config) noexcept : config_(config) {}
  void ComputeOutputs(std::int64_t now_ms) noexcept;

  ControllerConfig config_;
  ControllerStatus status_{};
  ControllerOutput output_{};
};

struct CrossingControllerResult {
  ControllerError error = ControllerError::kNone;
  std::optional<CrossingController> controller;  // engaged iff error == kNone
};

}  // namespace railproof::lc::wayside
