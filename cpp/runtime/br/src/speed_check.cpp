// Two-counter digital speed check (D3, digest §5; spec/design/br.md §6). See the
// header for the gate timing and the fail-safe rules.
//
// Seeded faults (negative tests; each killed by cpp/runtime/br/tests/test_speed_check.cpp):
//   FAULT_SC_BRAKE_STRICT     brake iff n_1 < n_1F (misses the train exactly at the check
//                             speed)
//   FAULT_SC_NO_GATE_TIMEOUT  the gate timeout is never raised (a silent TG keeps the last
//                             decision)
#include "railproof/core/seeded_fault.hpp"
#include "railproof/br/speed_check.hpp"

namespace railproof::br {

namespace {

// Bounds that keep every product below in int64 (n_1F <= 1e9, f_1 <= 1e9 Hz).
constexpr std::int64_t kMaxN1f = 1'000'000'000;
constexpr std::int64_t kMaxF1Hz = 1'000'000'000;

constexpr std::int64_t CeilDiv(std::int64_t a, std::int64_t b) noexcept { return (a + b - 1) / b; }

}  // namespace

// @implements REQ-SC-002 REQ-SC-003
SpeedCheckCreateResult TwoCounterSpeedCheck::Create(const SpeedCheckConfig& config,
                                                    std::int64_t now_ms) noexcept {
  SpeedCheckCreateResult result;
  if (config.f_1_hz <= 0 || config.f_1_hz > kMaxF1Hz) {
    result.error = SpeedCheckConfigError::kOscillatorInvalid;
    return result;
  }
  if (config.n_1f < 1 || config.n_1f > kMaxN1f) {
    result.error = SpeedCheckConfigError::kThresholdInvalid;
    return result;
  }
  if (config.table.empty()) {
    result.error = SpeedCheckConfigError::kTableEmpty;
    return result;
  }
  if (config.table.size() > kMaxCheckSpeeds) {
    result.error = SpeedCheckConfigError::kTableTooLarge;
    return result;
  }
  for (std::size_t i = 0; i < config.table.size(); ++i) {
    const CheckSpeedEntry& e = config.table[i];
    bool duplicate = false;
    for (std::size_t j = 0; j < i; ++j) {
      duplicate = duplicate || config.table[j].check_speed_kmh == e.check_speed_kmh;
    }
    if (e.check_speed_kmh <= 0 || duplicate) {
      result.error = SpeedCheckConfigError::kCheckSpeedInvalid;
      result.entry = i;
      return result;
    }
    if (e.n_2e < 1) {
      result.error = SpeedCheckConfigError::kN2eInvalid;
      result.entry = i;
      return result;
    }
  }
  // The sampling time (n_1F + 1 counts, the longest a gate lasts before its outcome is
  // known) must end before the gate timeout, or every gate of a slow train would time out.
  const std::int64_t sampling_ms = CeilDiv((config.n_1f + 1) * 1000, config.f_1_hz);
  if (config.gate_timeout_ms <= sampling_ms) {
    result.error = SpeedCheckConfigError::kGateTimeoutInvalid;
    return result;
  }
  const std::int64_t period_ms = CeilDiv(1000, config.f_1_hz);
  if (config.oscillator_timeout_ms < period_ms ||
      config.oscillator_timeout_ms > config.gate_timeout_ms) {
    result.error = SpeedCheckConfigError::kOscillatorTimeoutInvalid;
    return result;
  }

  TwoCounterSpeedCheck check;
  for (std::size_t i = 0; i < config.table.size(); ++i) {
    check.table_[i] = config.table[i];
  }
  check.table_size_ = config.table.size();
  check.f_1_hz_ = config.f_1_hz;
  check.n_1f_ = config.n_1f;
  check.gate_timeout_ms_ = config.gate_timeout_ms;
  check.oscillator_timeout_ms_ = config.oscillator_timeout_ms;
  check.last_now_ms_ = now_ms;
  check.Reset(now_ms);
  result.check.emplace(check);
  return result;
}

void TwoCounterSpeedCheck::Reset(std::int64_t now_ms) noexcept {
  gate_open_ = false;
  n_1_ = 0;
  n_2_ = 0;
  have_decision_ = false;
  decision_brake_ = true;
  gate_timeout_ = false;
  oscillator_stopped_ = false;
  clock_fault_ = false;
  last_now_ms_ = now_ms;
  last_decision_ms_ = now_ms;
  last_tick_ms_ = now_ms;
}

// @implements REQ-SC-001
bool TwoCounterSpeedCheck::BrakeDecision(std::int64_t n_1) const noexcept {
  if (RAILPROOF_FAULT(FAULT_SC_BRAKE_STRICT)) {
    return n_1 < n_1f_;
  }
  return n_1 <= n_1f_;
}

// @implements REQ-SC-003
void TwoCounterSpeedCheck::CheckTime(std::int64_t now_ms) noexcept {
  if (now_ms < last_now_ms_) {
    clock_fault_ = true;  // latched until Reset
    return;
  }
  last_now_ms_ = now_ms;
  if (now_ms - last_tick_ms_ > oscillator_timeout_ms_) {
    oscillator_stopped_ = true;
  }
  if (!RAILPROOF_FAULT(FAULT_SC_NO_GATE_TIMEOUT) && now_ms - last_decision_ms_ > gate_timeout_ms_) {
    gate_timeout_ = true;
  }
}

// @implements REQ-SC-002 REQ-SC-003
SelectVerdict TwoCounterSpeedCheck::SelectCheckSpeed(std::int64_t check_speed_kmh,
                                                     std::int64_t now_ms) noexcept {
  CheckTime(now_ms);
  std::optional<std::size_t> found;
  for (std::size_t i = 0; i < table_size_; ++i) {
    if (table_[i].check_speed_kmh == check_speed_kmh) {
      found = i;
    }
  }
  if (!found) {
    unknown_check_speed_ = true;
    selected_.reset();
    gate_open_ = false;
    n_1_ = 0;
    n_2_ = 0;
    have_decision_ = false;
    return SelectVerdict::kUnknownCheckSpeed;
  }
  if (selected_ && *selected_ == *found && !unknown_check_speed_) {
    return SelectVerdict::kUnchanged;
  }
  // A lower check speed invalidates a "release" decided at the higher one; a higher
  // check speed keeps the decision (release stays valid, brake stays until a gate says so).
  const bool lower =
      !selected_ || table_[*found].check_speed_kmh < table_[*selected_].check_speed_kmh;
  if (lower) {
    have_decision_ = false;
  }
  selected_ = found;
  unknown_check_speed_ = false;
  gate_open_ = false;  // the next TG pulse opens a gate with the new n_2E
  n_1_ = 0;
  n_2_ = 0;
  return SelectVerdict::kSelected;
}

// @implements REQ-SC-001 REQ-SC-002
GateResult TwoCounterSpeedCheck::OnTgPulse(std::int64_t now_ms) noexcept {
  CheckTime(now_ms);
  GateResult result;
  if (clock_fault_ || !selected_) {
    return result;
  }
  if (!gate_open_) {
    gate_open_ = true;
    n_1_ = 0;
    n_2_ = 0;
    return result;
  }
  ++n_2_;
  const std::int64_t n_2e = table_[*selected_].n_2e;
  if (n_2_ >= n_2e) {
    result.closed = true;
    result.brake = BrakeDecision(n_1_);
  } else if (n_1_ > n_1f_) {
    result.closed = true;  // outcome already "release": n_1 only grows
    result.early = true;
    result.brake = false;
  } else {
    return result;
  }
  result.n_1 = n_1_;
  result.n_2 = n_2_;
  ++decisions_;
  have_decision_ = true;
  decision_brake_ = result.brake;
  last_decision_ms_ = now_ms;
  gate_timeout_ = false;
  n_1_ = 0;  // this pulse opens the next gate
  n_2_ = 0;
  return result;
}

// @implements REQ-SC-001 REQ-SC-003
void TwoCounterSpeedCheck::OnOscillatorTick(std::int64_t now_ms) noexcept {
  if (now_ms >= last_now_ms_) {
    last_tick_ms_ = now_ms;
    oscillator_stopped_ = false;
  }
  CheckTime(now_ms);
  if (gate_open_ && n_1_ <= n_1f_) {
    ++n_1_;  // saturates at n_1F + 1
  }
}

// @implements REQ-SC-003
void TwoCounterSpeedCheck::OnTime(std::int64_t now_ms) noexcept { CheckTime(now_ms); }

// @implements REQ-SC-001 REQ-SC-003
SpeedCheckOutput TwoCounterSpeedCheck::Output() const noexcept {
  if (clock_fault_) {
    return {true, SpeedCheckReason::kClockFault};
  }
  if (oscillator_stopped_) {
    return {true, SpeedCheckReason::kOscillatorStopped};
  }
  if (gate_timeout_) {
    return {true, SpeedCheckReason::kGateTimeout};
  }
  if (unknown_check_speed_) {
    return {true, SpeedCheckReason::kUnknownCheckSpeed};
  }
  if (!have_decision_) {
    return {true, SpeedCheckReason::kNoDecision};
  }
  if (decision_brake_) {
    return {true, SpeedCheckReason::kOverspeed};
  }
  return {false, SpeedCheckReason::kRelease};
}

std::optional<std::int64_t> TwoCounterSpeedCheck::CheckSpeedKmh() const noexcept {
  if (!selected_) {
    return std::nullopt;
  }
  return table_[*selected_].check_speed_kmh;
}

std::int64_t TwoCounterSpeedCheck::N2e() const noexcept {
  return selected_ ? table_[*selected_].n_2e : 0;
}

}  // namespace railproof::br
