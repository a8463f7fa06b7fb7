// Unit tests of the two-counter digital speed check (runtime; D3, digest §5;
// spec/design/br.md §6). A small configuration with hand-countable numbers:
// f_1 = 1000 Hz (one tick per ms), n_1F = 10 (sampling time 10 ms), check speeds
// 70 km/h (n_2E = 12) and 30 km/h (n_2E = 5).
//
// Kills the seeded faults FAULT_SC_BRAKE_STRICT (AtTheCheckSpeedItBrakes) and
// FAULT_SC_NO_GATE_TIMEOUT (SilentTgBrakesAfterTheGateTimeout) (ctest unit_fault_<F>: these tests against the schemata variant with the fault selected).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <optional>

#include "railproof/testing/alloc_counter.hpp"
#include "railproof/br/speed_check.hpp"
#include "railproof/generated/sc_params.hpp"

namespace railproof::br {
namespace {

constexpr std::array<CheckSpeedEntry, 2> kTable{{{70, 12}, {30, 5}}};

SpeedCheckConfig SmallConfig() {
  SpeedCheckConfig c;
  c.f_1_hz = 1000;
  c.n_1f = 10;
  c.gate_timeout_ms = params::sc::gate_timeout_ms;
  c.oscillator_timeout_ms = 5;
  c.table = kTable;
  return c;
}

TwoCounterSpeedCheck MakeCheck(std::int64_t now_ms = 0) {
  auto created = TwoCounterSpeedCheck::Create(SmallConfig(), now_ms);
  EXPECT_EQ(created.error, SpeedCheckConfigError::kNone);
  return *created.check;
}

// Runs one gate that is already open at `t` with both counters at 0 (a pulse at t opened
// it): `ticks` oscillator ticks at t+1, t+2, ... and `pulses` TG pulses, the first
// pulses-1 spread over ticks 1..ticks-1 (so counter 1 <= ticks-1 at each), the last one
// after the last tick. Returns the result of the last pulse; t advances to its time.
GateResult Gate(TwoCounterSpeedCheck& c, std::int64_t& t, std::int64_t ticks,
                std::int64_t pulses) {
  GateResult last;
  std::int64_t sent = 0;
  for (std::int64_t i = 1; i <= ticks; ++i) {
    c.OnOscillatorTick(t + i);
    while (sent < pulses - 1 && i < ticks && (sent + 1) * (ticks - 1) <= i * (pulses - 1)) {
      last = c.OnTgPulse(t + i);
      EXPECT_FALSE(last.closed) << "gate closed early at tick " << i;
      ++sent;
    }
  }
  while (sent < pulses - 1) {  // ticks == 0 or rounding: the rest now
    last = c.OnTgPulse(t + ticks);
    ++sent;
  }
  t += ticks;
  last = c.OnTgPulse(t);
  return last;
}

// Selects 30 km/h (n_2E = 5) at t = 0 and opens the gate with a pulse at t = 0.
TwoCounterSpeedCheck OpenAt30(std::int64_t& t) {
  auto c = MakeCheck(0);
  t = 0;
  EXPECT_EQ(c.SelectCheckSpeed(30, t), SelectVerdict::kSelected);
  EXPECT_FALSE(c.OnTgPulse(t).closed);  // opens the gate
  EXPECT_TRUE(c.GateOpen());
  return c;
}

// OpenAt30, then one gate slower than the check speed (11 ticks, 5 pulses): a release
// decided at t = 11; the closing pulse opened the next gate.
TwoCounterSpeedCheck ReleasedAt30(std::int64_t& t) {
  auto c = OpenAt30(t);
  EXPECT_TRUE(Gate(c, t, 11, 5).closed);
  return c;
}

// ---- configuration (typed validation) -----------------------------------------------------

// @verifies REQ-SC-002 REQ-SC-003
TEST(SpeedCheckConfig, RejectsInvalidConfigurationsWithTypedErrors) {
  auto expect = [](SpeedCheckConfig c, SpeedCheckConfigError e, std::size_t entry = 0) {
    const auto r = TwoCounterSpeedCheck::Create(c, 0);
    EXPECT_EQ(r.error, e) << ToString(r.error);
    EXPECT_EQ(r.entry, entry);
    EXPECT_FALSE(r.check.has_value());
  };
  SpeedCheckConfig c = SmallConfig();
  c.f_1_hz = 0;
  expect(c, SpeedCheckConfigError::kOscillatorInvalid);
  c = SmallConfig();
  c.n_1f = 0;
  expect(c, SpeedCheckConfigError::kThresholdInvalid);
  c = SmallConfig();
  c.table = {};
  expect(c, SpeedCheckConfigError::kTableEmpty);
  std::array<CheckSpeedEntry, kMaxCheckSpeeds + 1> big{};
  for (std::size_t i = 0; i < big.size(); ++i) {
    big[i] = {static_cast<std::int64_t>(i + 1), 1};
  }
  c = SmallConfig();
  c.table = big;
  expect(c, SpeedCheckConfigError::kTableTooLarge);
  const std::array<CheckSpeedEntry, 3> dup{{{70, 12}, {30, 5}, {70, 3}}};
  c = SmallConfig();
  c.table = dup;
  expect(c, SpeedCheckConfigError::kCheckSpeedInvalid, 2);
  const std::array<CheckSpeedEntry, 2> neg{{{70, 12}, {0, 5}}};
  c.table = neg;
  expect(c, SpeedCheckConfigError::kCheckSpeedInvalid, 1);
  const std::array<CheckSpeedEntry, 2> n2e{{{70, 12}, {30, 0}}};
  c.table = n2e;
  expect(c, SpeedCheckConfigError::kN2eInvalid, 1);
  c = SmallConfig();
  c.gate_timeout_ms = 11;  // sampling (n_1F + 1) / f_1 = 11 ms
  expect(c, SpeedCheckConfigError::kGateTimeoutInvalid);
  c.gate_timeout_ms = 12;
  c.oscillator_timeout_ms = 12;
  EXPECT_EQ(TwoCounterSpeedCheck::Create(c, 0).error, SpeedCheckConfigError::kNone);
  c.oscillator_timeout_ms = 13;  // > gate timeout
  expect(c, SpeedCheckConfigError::kOscillatorTimeoutInvalid);
  c = SmallConfig();
  c.oscillator_timeout_ms = 0;
  expect(c, SpeedCheckConfigError::kOscillatorTimeoutInvalid);
  c.f_1_hz = 400;  // period 2.5 ms -> at least 3 ms
  c.oscillator_timeout_ms = 2;
  expect(c, SpeedCheckConfigError::kOscillatorTimeoutInvalid);
}

// @verifies REQ-SC-003
TEST(SpeedCheckGate, BrakesUntilTheFirstDecision) {
  auto c = MakeCheck(0);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kUnknownCheckSpeed);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.SelectCheckSpeed(30, 0), SelectVerdict::kSelected);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kNoDecision);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.N2e(), 5);
  EXPECT_EQ(c.CheckSpeedKmh(), std::optional<std::int64_t>{30});
}

// ---- gate logic (REQ-SC-001) ---------------------------------------------------------------

// @verifies REQ-SC-001
TEST(SpeedCheckGate, AtTheCheckSpeedItBrakes) {
  std::int64_t t = 0;
  auto c = OpenAt30(t);
  const GateResult g = Gate(c, t, 10, 5);  // n_1 = n_1F = 10 when counter 2 reaches 5
  ASSERT_TRUE(g.closed);
  EXPECT_FALSE(g.early);
  EXPECT_EQ(g.n_1, 10);
  EXPECT_EQ(g.n_2, 5);
  EXPECT_TRUE(g.brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kOverspeed);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.Decisions(), 1U);
}

// @verifies REQ-SC-001
TEST(SpeedCheckGate, FasterBrakesSlowerReleases) {
  std::int64_t t = 0;
  auto c = OpenAt30(t);
  GateResult g = Gate(c, t, 11, 5);  // one count more than n_1F: slower than the check speed
  ASSERT_TRUE(g.closed);
  EXPECT_FALSE(g.early);
  EXPECT_EQ(g.n_1, 11);
  EXPECT_FALSE(g.brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kRelease);
  EXPECT_FALSE(c.Output().brake);
  // the closing pulse opened the next gate (back to back)
  EXPECT_TRUE(c.GateOpen());
  EXPECT_EQ(c.Counter1(), 0);
  EXPECT_EQ(c.Counter2(), 0);
  g = Gate(c, t, 4, 5);  // much faster
  ASSERT_TRUE(g.closed);
  EXPECT_EQ(g.n_1, 4);
  EXPECT_TRUE(g.brake);
  EXPECT_TRUE(c.Output().brake);
  g = Gate(c, t, 9, 5);  // n_1F - 1
  EXPECT_TRUE(g.brake);
  g = Gate(c, t, 11, 5);  // and back below the check speed
  EXPECT_FALSE(g.brake);
  EXPECT_FALSE(c.Output().brake);
  EXPECT_EQ(c.Decisions(), 4U);
}

// @verifies REQ-SC-001
TEST(SpeedCheckGate, EarlyReleaseOnlyAtATgPulseAfterCounter1PassedN1f) {
  std::int64_t t = 0;
  auto c = OpenAt30(t);
  EXPECT_FALSE(c.OnTgPulse(1).closed);  // counter 2 = 1
  for (std::int64_t i = 1; i <= 30; ++i) {
    c.OnOscillatorTick(i);
  }
  EXPECT_EQ(c.Counter1(), 11);  // saturated at n_1F + 1
  EXPECT_EQ(c.Decisions(), 0U);  // no release without a TG pulse
  EXPECT_TRUE(c.Output().brake);
  const GateResult g = c.OnTgPulse(30);
  ASSERT_TRUE(g.closed);
  EXPECT_TRUE(g.early);
  EXPECT_FALSE(g.brake);
  EXPECT_EQ(g.n_2, 2);
  EXPECT_FALSE(c.Output().brake);
}

// ---- fail-safe (REQ-SC-003) ---------------------------------------------------------------

// @verifies REQ-SC-003
TEST(SpeedCheckFailSafe, SilentTgBrakesAfterTheGateTimeout) {
  std::int64_t t = 0;
  auto c = ReleasedAt30(t);
  ASSERT_FALSE(c.Output().brake);
  // the TG falls silent; the oscillator keeps running
  const std::int64_t timeout = params::sc::gate_timeout_ms;
  for (std::int64_t now = t + 1; now <= t + timeout; ++now) {
    c.OnOscillatorTick(now);
  }
  c.OnTime(t + timeout);
  EXPECT_FALSE(c.Output().brake) << "not yet: exactly gate_timeout_ms";
  c.OnOscillatorTick(t + timeout + 1);
  c.OnTime(t + timeout + 1);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kGateTimeout);
  // the next TG pulse closes the (long) gate early with a release decision: cleared
  const GateResult g2 = c.OnTgPulse(t + timeout + 2);
  EXPECT_TRUE(g2.closed);
  EXPECT_FALSE(c.Output().brake);
}

// @verifies REQ-SC-003
TEST(SpeedCheckFailSafe, StandstillBrakes) {
  auto c = MakeCheck(0);
  EXPECT_EQ(c.SelectCheckSpeed(30, 0), SelectVerdict::kSelected);
  for (std::int64_t now = 1; now <= 1001; ++now) {
    c.OnOscillatorTick(now);
  }
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kGateTimeout);
}

// @verifies REQ-SC-003
TEST(SpeedCheckFailSafe, StoppedOscillatorBrakes) {
  std::int64_t t = 0;
  auto c = ReleasedAt30(t);
  ASSERT_FALSE(c.Output().brake);
  c.OnTime(t + 5);  // last tick at t; timeout 5 ms
  EXPECT_FALSE(c.Output().brake);
  c.OnTime(t + 6);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kOscillatorStopped);
  // a TG pulse alone does not clear it
  (void)c.OnTgPulse(t + 7);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kOscillatorStopped);
  c.OnOscillatorTick(t + 8);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kRelease);
  // the gate that lost its ticks (n_1 = 1) counts too few and brakes by itself: the
  // method is fail-safe against a slow or stopped oscillator
  GateResult g;
  for (int k = 0; k < 4; ++k) {
    g = c.OnTgPulse(t + 9);
  }
  ASSERT_TRUE(g.closed);
  EXPECT_EQ(g.n_1, 1);
  EXPECT_TRUE(g.brake);
}

// @verifies REQ-SC-003
// @verifies REQ-SC-002
TEST(SpeedCheckFailSafe, UnknownCheckSpeedBrakes) {
  std::int64_t t = 0;
  auto c = ReleasedAt30(t);
  ASSERT_FALSE(c.Output().brake);
  EXPECT_EQ(c.SelectCheckSpeed(45, t), SelectVerdict::kUnknownCheckSpeed);
  EXPECT_TRUE(c.Output().brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kUnknownCheckSpeed);
  EXPECT_EQ(c.CheckSpeedKmh(), std::nullopt);
  EXPECT_EQ(c.N2e(), 0);
  // no gate runs
  EXPECT_FALSE(c.OnTgPulse(t + 1).closed);
  EXPECT_FALSE(c.GateOpen());
  // a known check speed again: no decision yet, still braking
  EXPECT_EQ(c.SelectCheckSpeed(70, t + 2), SelectVerdict::kSelected);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kNoDecision);
}

// @verifies REQ-SC-003
TEST(SpeedCheckFailSafe, ClockGoingBackwardsLatchesUntilReset) {
  std::int64_t t = 0;
  auto c = ReleasedAt30(t);
  c.OnTime(t - 1);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kClockFault);
  std::int64_t u = t + 1;
  (void)c.OnTgPulse(u);
  (void)Gate(c, u, 11, 5);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kClockFault);
  c.Reset(u);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kNoDecision);
  EXPECT_EQ(c.CheckSpeedKmh(), std::optional<std::int64_t>{30});
}

// ---- check speed selects n_2E (REQ-SC-002) -----------------------------------------------

// @verifies REQ-SC-002
TEST(SpeedCheckSelect, CheckSpeedChangeSelectsN2eAndRestartsTheGate) {
  std::int64_t t = 0;
  auto c = ReleasedAt30(t);
  ASSERT_FALSE(c.Output().brake);
  EXPECT_EQ(c.SelectCheckSpeed(30, t), SelectVerdict::kUnchanged);
  EXPECT_TRUE(c.GateOpen());
  // higher check speed: the release stays, the open gate is abandoned
  EXPECT_EQ(c.SelectCheckSpeed(70, t), SelectVerdict::kSelected);
  EXPECT_EQ(c.N2e(), 12);
  EXPECT_FALSE(c.GateOpen());
  EXPECT_FALSE(c.Output().brake);
  EXPECT_FALSE(c.OnTgPulse(t).closed);  // opens
  GateResult g = Gate(c, t, 10, 12);    // 12 pulses in 10 ms: above 70 -> brake
  ASSERT_TRUE(g.closed);
  EXPECT_EQ(g.n_2, 12);
  EXPECT_TRUE(g.brake);
  g = Gate(c, t, 11, 12);
  EXPECT_FALSE(g.brake);
  // lower check speed: brake until the first gate at 30 has decided
  EXPECT_EQ(c.SelectCheckSpeed(30, t), SelectVerdict::kSelected);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kNoDecision);
  EXPECT_EQ(c.N2e(), 5);
  EXPECT_FALSE(c.OnTgPulse(t).closed);
  g = Gate(c, t, 11, 5);
  EXPECT_FALSE(g.brake);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kRelease);
}

// @verifies REQ-SC-002
TEST(SpeedCheckSelect, HigherCheckSpeedKeepsABrakeDecision) {
  std::int64_t t = 0;
  auto c = OpenAt30(t);
  (void)Gate(c, t, 8, 5);
  ASSERT_EQ(c.Output().reason, SpeedCheckReason::kOverspeed);
  EXPECT_EQ(c.SelectCheckSpeed(70, t), SelectVerdict::kSelected);
  EXPECT_EQ(c.Output().reason, SpeedCheckReason::kOverspeed);
}

// ---- runtime rules ------------------------------------------------------------------------

// @verifies REQ-SC-001 REQ-SC-003
TEST(SpeedCheckRuntime, NoAllocationAndDeterministic) {
  auto a = MakeCheck(0);
  auto b = MakeCheck(0);
  testing::StartCountingAllocations();
  for (auto* c : {&a, &b}) {
    std::int64_t t = 0;
    (void)c->SelectCheckSpeed(30, t);
    (void)c->OnTgPulse(t);
    for (int k = 0; k < 200; ++k) {
      (void)Gate(*c, t, 6 + k % 6, 5);
      c->OnTime(t);
    }
    (void)c->SelectCheckSpeed(70, t);
    (void)c->SelectCheckSpeed(99, t);
    c->OnTime(t + 5000);
  }
  EXPECT_EQ(testing::StopCountingAllocations(), 0U);
  EXPECT_EQ(a.Decisions(), b.Decisions());
  EXPECT_EQ(a.Output().reason, b.Output().reason);
  EXPECT_EQ(a.Output().reason, SpeedCheckReason::kOscillatorStopped);
}

}  // namespace
}  // namespace railproof::br
