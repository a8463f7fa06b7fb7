// Two-counter digital speed check (D3, digest §5; spec/design/br.md §6;
// REQ-SC-001..003). Counter 2 counts tachogenerator (TG) pulses up to n_2E, the value of
// the block's check speed; while it counts, gate G lets counter 1 count the reference
// oscillator (f_1). When counter 2 reaches n_2E the gate closes and the check commands
// braking iff n_1 <= n_1F (a faster train gives a shorter gate and fewer counts).
// The offline design (n_1F, f_1, n_2E per check speed, error bounds) is
// railproof/br/analysis/speedcheck_design.hpp.
//
// Event-driven: the owner feeds every TG pulse (OnTgPulse), every oscillator tick
// (OnOscillatorTick) and the time at least once per supervision cycle (OnTime), each with
// the current time in ms (non-decreasing). The brake command is Output().
//
// Gate timing (the rules a conformance test or the analysis must reproduce):
//  - A gate opens at a TG pulse. The pulse that closes a gate opens the next one (gates
//    run back to back); after Create, Reset or a check-speed change the first TG pulse
//    opens the gate.
//  - While the gate is open, each oscillator tick increments counter 1 (saturating at
//    n_1F + 1: only "n_1 > n_1F" matters) and each TG pulse increments counter 2.
//  - At the TG pulse that makes counter 2 = n_2E: decision brake iff n_1 <= n_1F
//    (REQ-SC-001).
//  - Early release: at a TG pulse with counter 2 < n_2E and counter 1 already > n_1F the
//    gate's outcome is known (n_1 can only grow), so the gate closes with "release" at
//    that pulse. Without it a train far below the check speed (e.g. 40 km/h under a
//    250 km/h check speed: a gate of 481 pulses lasts 1.3 s) would never complete a gate
//    within gate_timeout_ms and would be braked. The release is issued at a TG pulse, so a
//    TG that falls silent never releases a brake.
//  - Fail-safe (REQ-SC-003), each a typed reason that commands braking:
//      kGateTimeout        no gate decision for more than gate_timeout_ms (counted from
//                          the last decision, Create or Reset; a check-speed change does
//                          not restart it): TG silent (broken TG, standstill) or a gate
//                          that stays open; cleared by the next decision.
//      kOscillatorStopped  no oscillator tick for more than oscillator_timeout_ms;
//                          cleared by the next tick (a gate that lost ticks counts too
//                          few and decides "brake" by itself: the method is fail-safe
//                          against a slow or stopped oscillator).
//      kUnknownCheckSpeed  SelectCheckSpeed with a speed not in the table; no gate runs
//                          until a known check speed is selected.
//      kClockFault         time going backwards; latched until Reset.
//    kNoDecision (brake) holds after Create/Reset and after a change to a LOWER check
//    speed until the first gate at the new check speed has decided (a "release" at the
//    old, higher check speed says nothing about the new one). A change to a higher
//    check speed keeps the current decision. Either change abandons the open gate
//    (its n_2E no longer applies).
//  - At standstill no TG pulses arrive, so the check brakes (kGateTimeout). The
//    integration must accept that (the train is held) and release by its own standstill
//    logic if needed; the check itself only releases after a completed gate.
//
// Runtime module: no heap (fixed-size members), no exceptions, no recursion, bounded
// loops, typed results, deterministic. Units: Hz, counts, ms, km/h (check-speed codes).
#pragma once

#include "railproof/core/enum_names.hpp"

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

namespace railproof::br {

inline constexpr std::size_t kMaxCheckSpeeds = 16;

// One row of the n_2E table: the check-speed code of the block (km/h, as signalled, D3:
// 250, 210, 160, 110, 70, 30, 5) and the number of TG pulses of the gate.
struct CheckSpeedEntry {
  std::int64_t check_speed_kmh = 0;
  std::int64_t n_2e = 0;
};

struct SpeedCheckConfig {
  std::int64_t f_1_hz = 0;                // reference oscillator frequency, 1..1e9
  std::int64_t n_1f = 0;                  // counter-1 count at the check speed, 1..1e9
  std::int64_t gate_timeout_ms = 0;       // > sampling time (n_1F + 1) / f_1
  std::int64_t oscillator_timeout_ms = 0; // >= one oscillator period, <= gate_timeout_ms
  std::span<const CheckSpeedEntry> table; // 1..kMaxCheckSpeeds rows, check speeds distinct
};

// @implements REQ-SC-002 REQ-SC-003
enum class SpeedCheckConfigError : std::uint8_t {
  kNone,
  kOscillatorInvalid,         // f_1_hz <= 0
  kThresholdInvalid,          // n_1f < 1
  kTableEmpty,                // no check speed
  kTableTooLarge,             // more than kMaxCheckSpeeds rows
  kCheckSpeedInvalid,         // a check speed <= 0 or listed twice (entry = its row)
  kN2eInvalid,                // an n_2e < 1 (entry = its row)
  kGateTimeoutInvalid,        // gate_timeout_ms <= (n_1F + 1) * 1000 / f_1 (rounded up)
  kOscillatorTimeoutInvalid,  // < ceil(1000 / f_1) or > gate_timeout_ms
};

constexpr const char* ToString(SpeedCheckConfigError e) noexcept {
  return core::EnumName(e, std::array<const char*, 9>{"None", "OscillatorInvalid", "ThresholdInvalid", "TableEmpty", "TableTooLarge", "CheckSpeedInvalid", "N2eInvalid", "GateTimeoutInvalid", "OscillatorTimeoutInvalid"}, "Invalid");
}

// Why the check brakes (or kRelease). When several hold, the first in this order of
// priority is reported: kClockFault, kOscillatorStopped, kGateTimeout, kUnknownCheckSpeed,
// kNoDecision, kOverspeed.
// @implements REQ-SC-001 REQ-SC-003
enum class SpeedCheckReason : std::uint8_t {
  kRelease,             // last gate: n_1 > n_1F, no fault
  kOverspeed,           // last gate: n_1 <= n_1F (REQ-SC-001)
  kNoDecision,          // no gate decided yet at this (lowered) check speed
  kUnknownCheckSpeed,   // REQ-SC-003
  kGateTimeout,         // REQ-SC-003
  kOscillatorStopped,   // REQ-SC-003
  kClockFault,          // time went backwards (defensive)
};

constexpr const char* ToString(SpeedCheckReason r) noexcept {
  return core::EnumName(r, std::array<const char*, 7>{"RELEASE", "OVERSPEED", "NO_DECISION", "UNKNOWN_CHECK_SPEED", "GATE_TIMEOUT", "OSCILLATOR_STOPPED", "CLOCK_FAULT"});
}

struct SpeedCheckOutput {
  bool brake = true;
  SpeedCheckReason reason = SpeedCheckReason::kNoDecision;
};

// Result of one TG pulse: whether it closed a gate, and that gate's decision.
struct GateResult {
  bool closed = false;        // a gate closed at this pulse
  bool early = false;         // closed by the early release (counter 2 < n_2E)
  bool brake = false;         // the gate's decision (n_1 <= n_1F)
  std::int64_t n_1 = 0;       // counter 1 at the close (saturated at n_1F + 1)
  std::int64_t n_2 = 0;       // counter 2 at the close
};

enum class SelectVerdict : std::uint8_t {
  kSelected,            // new check speed in force; the open gate was abandoned
  kUnchanged,           // same check speed as before: nothing changes
  kUnknownCheckSpeed,   // not in the table: brake (REQ-SC-003) until a known one
};

constexpr const char* ToString(SelectVerdict v) noexcept {
  return core::EnumName(v, std::array<const char*, 3>{"SELECTED", "UNCHANGED", "UNKNOWN_CHECK_SPEED"});
}

struct SpeedCheckCreateResult;

// @implements REQ-SC-001 REQ-SC-002 REQ-SC-003
class TwoCounterSpeedCheck {
 public:
  // Validates the configuration (typed error) and copies the table. The check starts at
  // now_ms with no check speed selected (kUnknownCheckSpeed until SelectCheckSpeed) and
  // no decision: it brakes.
  static SpeedCheckCreateResult Create(const SpeedCheckConfig& config,
                                       std::int64_t now_ms) noexcept;

  // Check speed of the current block (REQ-SC-002): selects n_2E from the table.
  SelectVerdict SelectCheckSpeed(std::int64_t check_speed_kmh, std::int64_t now_ms) noexcept;

  // One TG pulse (counter 2); returns the gate decided at this pulse, if any.
  GateResult OnTgPulse(std::int64_t now_ms) noexcept;

  // One reference-oscillator tick (counter 1).
  void OnOscillatorTick(std::int64_t now_ms) noexcept;

  // Time supervision (gate timeout, oscillator stopped); call at least once per cycle.
  void OnTime(std::int64_t now_ms) noexcept;

  // Back to the state of Create (check speed kept; clears the clock fault).
  void Reset(std::int64_t now_ms) noexcept;

  // The command as of the last event (call OnTime(now) first for fresh time checks).
  [[nodiscard]] SpeedCheckOutput Output() const noexcept;

  // Observers (tests, analysis).
  [[nodiscard]] std::optional<std::int64_t> CheckSpeedKmh() const noexcept;
  [[nodiscard]] std::int64_t N2e() const noexcept;  // 0 if no check speed
  [[nodiscard]] std::int64_t N1f() const noexcept { return n_1f_; }
  [[nodiscard]] std::int64_t F1Hz() const noexcept { return f_1_hz_; }
  [[nodiscard]] bool GateOpen() const noexcept { return gate_open_; }
  [[nodiscard]] std::int64_t Counter1() const noexcept { return n_1_; }
  [[nodiscard]] std::int64_t Counter2() const noexcept { return n_2_; }
  [[nodiscard]] std::uint64_t Decisions() const noexcept { return decisions_; }

 private:
  TwoCounterSpeedCheck() noexcept = default;

  void CheckTime(std::int64_t now_ms) noexcept;
  // @implements REQ-SC-001
  [[nodiscard]] bool BrakeDecision(std::int64_t n_1) const noexcept;

  std::array<CheckSpeedEntry, kMaxCheckSpeeds> table_{};
  std::size_t table_size_ = 0;
  std::int64_t f_1_hz_ = 0;
  std::int64_t n_1f_ = 0;
  std::int64_t gate_timeout_ms_ = 0;
  std::int64_t oscillator_timeout_ms_ = 0;

  std::optional<std::size_t> selected_;  // index into table_
  bool unknown_check_speed_ = true;
  bool gate_open_ = false;
  std::int64_t n_1_ = 0;
  std::int64_t n_2_ = 0;
  bool have_decision_ = false;   // a decision valid for the current check speed
  bool decision_brake_ = true;
  bool gate_timeout_ = false;
  bool oscillator_stopped_ = false;
  bool clock_fault_ = false;
  std::int64_t last_now_ms_ = 0;
  std::int64_t last_decision_ms_ = 0;
  std::int64_t last_tick_ms_ = 0;
  std::uint64_t decisions_ = 0;
};

struct SpeedCheckCreateResult {
  SpeedCheckConfigError error = SpeedCheckConfigError::kNone;
  std::size_t entry = 0;                      // offending table row (0 if n/a)
  std::optional<TwoCounterSpeedCheck> check;  // engaged iff error == kNone
};

}  // namespace railproof::br
