// Unit tests of the level-crossing controller (spec/design/lc.md §4, §5 step 2 and
// the clock rule): the sequence OPEN -> WARNING -> CLOSING -> CLOSED -> OPENING -> OPEN with
// the barrier timers at their boundaries, both barrier failures (not down, not up) and the
// loss of "down", two requesters, a request while opening, the alarm after max_warning_ms,
// the GNSS-time start time (stored, earlier always, later only before the warning, another
// departure, warning stop, late repetition), the clock (holdover boundary, fault -> warning at
// once, fault reported), typed errors, no heap in the cycle and determinism.
//
// Kills the seeded faults FAULT_LC_END_WITH_REQUESTER and FAULT_LC_LATER_UPDATE_WHILE_WARNING
// (ctest unit_fault_<F>: these tests against the schemata variant with the fault selected).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "railproof/testing/enum_names.hpp"
#include "railproof/testing/alloc_counter.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"

namespace railproof::lc::wayside {
namespace {

constexpr std::uint32_t kId = 11;
constexpr std::int64_t kLower = params::lc::barrier_lowering_ms;   // 8000
constexpr std::int64_t kTimeout = params::lc::barrier_timeout_ms;  // 15000
constexpr std::int64_t kMaxWarning = params::lc::max_warning_ms;
constexpr std::int64_t kHoldover = params::lc::holdover_max_ms;

constexpr std::array<std::uint32_t, 1> kTrainA{{101}};
constexpr std::array<std::uint32_t, 1> kTrainB{{102}};
constexpr std::array<std::uint32_t, 2> kTrainsAB{{101, 102}};

CrossingController Make() {
  auto created = CrossingController::Create(DefaultControllerConfig(kId));
  EXPECT_EQ(created.error, ControllerError::kNone);
  return std::move(*created.controller);
}

// Barriers up, no messages.
ControllerInput At(std::int64_t now) {
  ControllerInput in;
  in.now_ms = now;
  in.barrier_down = false;
  in.barrier_up = true;
  return in;
}

ControllerInput Down(std::int64_t now) {
  ControllerInput in = At(now);
  in.barrier_down = true;
  in.barrier_up = false;
  return in;
}

// Neither detected (barriers moving).
ControllerInput Moving(std::int64_t now) {
  ControllerInput in = At(now);
  in.barrier_up = false;
  return in;
}

// `in` with requests from, or withdrawals by, `trains`.
ControllerInput Requesting(ControllerInput in, std::span<const std::uint32_t> trains) {
  in.requests = trains;
  return in;
}
ControllerInput Withdrawing(ControllerInput in, std::span<const std::uint32_t> trains) {
  in.withdrawals = trains;
  return in;
}

// Requested by train A at 0 and closed at 9000 (ws = 0).
CrossingController ClosedByA() {
  CrossingController c = Make();
  EXPECT_EQ(c.Cycle(Requesting(At(0), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
  EXPECT_EQ(c.Cycle(Down(9'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  return c;
}

// @verifies REQ-LC-006
// @verifies REQ-LC-007
TEST(LcCrossingController, FullSequenceWithTimers) {
  CrossingController c = Make();
  ASSERT_EQ(c.Cycle(At(0)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kOpen);
  EXPECT_FALSE(c.Output().lights_on);
  EXPECT_FALSE(c.Output().barriers_down_commanded);

  ASSERT_EQ(c.Cycle(Requesting(At(1'000), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  EXPECT_EQ(c.Status().warning_start_ms, 1'000);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kWarning);
  EXPECT_EQ(c.Output().report.warning_start_ms, 1'000);
  EXPECT_TRUE(c.Output().lights_on);
  EXPECT_FALSE(c.Output().barriers_down_commanded);
  ASSERT_EQ(c.Status().Requesters().size(), 1U);

  ASSERT_EQ(c.Cycle(At(1'000 + kLower - 1)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  ASSERT_EQ(c.Cycle(Moving(1'000 + kLower)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosing);
  EXPECT_TRUE(c.Output().barriers_down_commanded);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kWarning);  // not closed before "down"

  ASSERT_EQ(c.Cycle(Down(12'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kClosed);
  EXPECT_EQ(c.Output().report.warning_start_ms, 1'000);
  EXPECT_EQ(c.Output().report.issued_ms, 12'000);
  EXPECT_EQ(c.Output().report.crossing_id, kId);
  ASSERT_EQ(c.Cycle(Down(12'500)), ControllerError::kNone);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kClosed);  // every cycle

  ASSERT_EQ(c.Cycle(Withdrawing(Down(13'000), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Output().WithdrawalAcks().size(), 1U);
  EXPECT_EQ(c.Output().WithdrawalAcks()[0], 101U);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kOpen);
  EXPECT_FALSE(c.Output().barriers_down_commanded);
  EXPECT_TRUE(c.Output().lights_on);
  ASSERT_EQ(c.Cycle(Moving(14'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Cycle(At(15'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  EXPECT_FALSE(c.Output().lights_on);
  EXPECT_EQ(c.Status().failure, FailureReason::kNone);
}

// Down must be detected by ws + barrier_lowering_ms + barrier_timeout_ms.
// @verifies REQ-LC-006
// @verifies REQ-LC-014
TEST(LcCrossingController, BarrierNotDownFailsAndNeverReportsClosed) {
  {
    CrossingController c = Make();
    ASSERT_EQ(c.Cycle(Requesting(At(0), kTrainA)), ControllerError::kNone);
    ASSERT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
    ASSERT_EQ(c.Cycle(Moving(kLower + kTimeout - 1)), ControllerError::kNone);
    EXPECT_EQ(c.State(), ControllerState::kClosing);
    ASSERT_EQ(c.Cycle(Down(kLower + kTimeout)), ControllerError::kNone);  // just in time
    EXPECT_EQ(c.State(), ControllerState::kClosed);
  }
  CrossingController c = Make();
  ASSERT_EQ(c.Cycle(Requesting(At(0), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Moving(kLower + kTimeout)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kFailed);
  EXPECT_EQ(c.Status().failure, FailureReason::kBarrierNotDown);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kFailed);
  EXPECT_TRUE(c.Output().lights_on);
  // a late "down" and the withdrawal do not make it closed or end the warning
  ASSERT_EQ(c.Cycle(Withdrawing(Down(kLower + kTimeout + 1'000), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kFailed);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kFailed);
  EXPECT_TRUE(c.Output().lights_on);
  EXPECT_EQ(c.Output().WithdrawalAcks().size(), 1U);
  c.MaintenanceReset();
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  EXPECT_EQ(c.Status().failure, FailureReason::kNone);
}

// Both detections at once are inconsistent: taken as neither.
// @verifies REQ-LC-006
TEST(LcCrossingController, InconsistentDetectionIsNotDown) {
  CrossingController c = Make();
  ASSERT_EQ(c.Cycle(Requesting(At(0), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
  ControllerInput in = Down(kLower + 1'000);
  in.barrier_up = true;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosing);
}

// @verifies REQ-LC-006
// @verifies REQ-LC-014
TEST(LcCrossingController, LossOfDownWhileClosedFails) {
  CrossingController c = ClosedByA();
  ASSERT_EQ(c.Cycle(Moving(9'500)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kFailed);
  EXPECT_EQ(c.Status().failure, FailureReason::kBarrierDownLost);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kFailed);
}

// Up must be detected within barrier_timeout_ms of the opening command.
// @verifies REQ-LC-006
// @verifies REQ-LC-007
TEST(LcCrossingController, BarrierNotUpFails) {
  CrossingController c = ClosedByA();
  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'000), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Cycle(Moving(10'000 + kTimeout - 1)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Cycle(Moving(10'000 + kTimeout)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kFailed);
  EXPECT_EQ(c.Status().failure, FailureReason::kBarrierNotUp);
  EXPECT_TRUE(c.Output().lights_on);
}

// The warning ends only when every requester withdrew.
// @verifies REQ-LC-007
TEST(LcCrossingController, TwoRequestersBothMustWithdraw) {
  CrossingController c = Make();
  ASSERT_EQ(c.Cycle(Requesting(At(0), kTrainsAB)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Down(9'000)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Status().Requesters().size(), 2U);

  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'000), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kClosed);
  ASSERT_EQ(c.Status().Requesters().size(), 1U);
  EXPECT_EQ(c.Status().Requesters()[0], 102U);
  // A repeats its withdrawal (lost ack): acknowledged again, still closed
  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'500), kTrainA)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().WithdrawalAcks().size(), 1U);

  ASSERT_EQ(c.Cycle(Withdrawing(Down(11'000), kTrainB)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpening);
}

// @verifies REQ-LC-006
// @verifies REQ-LC-007
TEST(LcCrossingController, RequestWhileOpeningRestartsTheWarning) {
  CrossingController c = ClosedByA();
  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'000), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Cycle(Requesting(Moving(11'000), kTrainB)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  EXPECT_EQ(c.Status().warning_start_ms, 11'000);
  EXPECT_EQ(c.Status().episode_start_ms, 0);  // the lights never went off
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kWarning);
}

// Warning longer than max_warning_ms: alarm, never the end of the warning.
// @verifies REQ-LC-007
TEST(LcCrossingController, AlarmAfterMaxWarningDoesNotEndIt) {
  CrossingController c = ClosedByA();
  ASSERT_EQ(c.Cycle(Down(kMaxWarning)), ControllerError::kNone);
  EXPECT_FALSE(c.Output().alarm);
  ASSERT_EQ(c.Cycle(Down(kMaxWarning + 1)), ControllerError::kNone);
  EXPECT_TRUE(c.Output().alarm);
  EXPECT_TRUE(c.Status().alarm);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kClosed);
  ASSERT_EQ(c.Cycle(Withdrawing(Down(kMaxWarning + 2), kTrainA)), ControllerError::kNone);
  EXPECT_TRUE(c.Output().alarm);
  ASSERT_EQ(c.Cycle(At(kMaxWarning + 3)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  EXPECT_FALSE(c.Output().alarm);
}

// A withdrawal of a train not held is acknowledged (repeated withdrawals) and changes nothing.
// @verifies REQ-LC-004
// @verifies REQ-LC-007
TEST(LcCrossingController, UnknownWithdrawalAcknowledged) {
  CrossingController c = Make();
  ASSERT_EQ(c.Cycle(Withdrawing(At(0), kTrainB)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  ASSERT_EQ(c.Output().WithdrawalAcks().size(), 1U);
  EXPECT_EQ(c.Output().WithdrawalAcks()[0], 102U);
  ASSERT_EQ(c.Cycle(At(100)), ControllerError::kNone);
  EXPECT_TRUE(c.Output().WithdrawalAcks().empty());  // acks are per cycle
}

// ---- GNSS-time start (REQ-LC-009..012) --------------------------------------------------------

ControllerInput WithStart(ControllerInput in, const std::array<StartTimeMessage, 1>& m) {
  in.start_times = m;
  return in;
}

// Departure 5's start time 100,000 stored at 0 (the crossing still open).
CrossingController StartStoredAt0() {
  CrossingController c = Make();
  EXPECT_EQ(c.Cycle(WithStart(At(0), {{{kId, 5, 100'000}}})), ControllerError::kNone);
  return c;
}

// @verifies REQ-LC-009
// @verifies REQ-LC-011
TEST(LcCrossingController, StoredStartTimeStartsTheWarning) {
  CrossingController c = Make();
  const std::array<StartTimeMessage, 1> st{{{kId, 5, 100'000}}};
  ASSERT_EQ(c.Cycle(WithStart(At(0), st)), ControllerError::kNone);
  ASSERT_EQ(c.Output().StartAcks().size(), 1U);
  EXPECT_EQ(c.Output().StartAcks()[0].departure_id, 5U);
  EXPECT_EQ(c.Output().StartAcks()[0].start_ms, 100'000);
  EXPECT_TRUE(c.Output().StartAcks()[0].stored);
  EXPECT_TRUE(c.Status().pending.present);
  ASSERT_EQ(c.Cycle(At(99'999)), ControllerError::kNone);  // no message needed any more
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  ASSERT_EQ(c.Cycle(At(100'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  EXPECT_EQ(c.Status().warning_start_ms, 100'000);
  EXPECT_TRUE(c.Status().pending.active);
  ASSERT_EQ(c.Cycle(Moving(100'000 + kLower)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Down(110'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  // without the warning stop the crossing stays closed
  ASSERT_EQ(c.Cycle(Down(300'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  // the warning stop of another departure does not end it; this departure's does
  const std::array<WarningStopMessage, 1> other{{{kId, 6}}};
  ControllerInput in = Down(301'000);
  in.warning_stops = other;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  ASSERT_EQ(c.Output().StopAcks().size(), 1U);
  const std::array<WarningStopMessage, 1> stop{{{kId, 5}}};
  in = Down(302'000);
  in.warning_stops = stop;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Output().StopAcks().size(), 1U);
  EXPECT_EQ(c.Output().StopAcks()[0].departure_id, 5U);
  EXPECT_FALSE(c.Status().pending.present);
  // a late repetition of the departure's start time does not re-arm the crossing
  ASSERT_EQ(c.Cycle(WithStart(At(303'000), st)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  EXPECT_FALSE(c.Status().pending.present);
  ASSERT_EQ(c.Output().StartAcks().size(), 1U);
  EXPECT_FALSE(c.Output().StartAcks()[0].stored);
  ASSERT_EQ(c.Cycle(At(304'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
}

// @verifies REQ-LC-010
TEST(LcCrossingController, EarlierAlwaysLaterOnlyBeforeTheWarning) {
  CrossingController c = StartStoredAt0();
  // later while open and not yet due: taken
  ASSERT_EQ(c.Cycle(WithStart(At(1'000), {{{kId, 5, 120'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.start_ms, 120'000);
  EXPECT_EQ(c.Output().StartAcks()[0].start_ms, 120'000);
  // earlier: taken
  ASSERT_EQ(c.Cycle(WithStart(At(2'000), {{{kId, 5, 90'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.start_ms, 90'000);
  // warning started at 90,000
  ASSERT_EQ(c.Cycle(At(90'000)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kWarning);
  // later while warning: refused, the earlier time stays in force and is acknowledged
  ASSERT_EQ(c.Cycle(WithStart(At(91'000), {{{kId, 5, 150'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.start_ms, 90'000);
  ASSERT_EQ(c.Output().StartAcks().size(), 1U);
  EXPECT_EQ(c.Output().StartAcks()[0].start_ms, 90'000);
  EXPECT_TRUE(c.Output().StartAcks()[0].stored);
  // earlier while warning: taken (the warning is already running)
  ASSERT_EQ(c.Cycle(WithStart(At(92'000), {{{kId, 5, 80'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.start_ms, 80'000);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
}

// A warning started by a request is "warning" too: a later start time is refused, so the
// stored time still starts a warning when the requester has gone.
// @verifies REQ-LC-010
// @verifies REQ-LC-014
TEST(LcCrossingController, LaterUpdateRefusedWhileWarningForARequest) {
  CrossingController c = StartStoredAt0();
  ASSERT_EQ(c.Cycle(Requesting(At(1'000), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kWarning);
  ASSERT_EQ(c.Cycle(WithStart(At(2'000), {{{kId, 5, 200'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.start_ms, 100'000);
  EXPECT_EQ(c.Output().StartAcks()[0].start_ms, 100'000);
  ASSERT_EQ(c.Cycle(Down(9'000)), ControllerError::kNone);  // closing
  ASSERT_EQ(c.Cycle(Down(9'500)), ControllerError::kNone);  // closed
  ASSERT_EQ(c.State(), ControllerState::kClosed);
  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'000), kTrainA)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kOpening);
  ASSERT_EQ(c.Cycle(At(11'000)), ControllerError::kNone);
  ASSERT_EQ(c.State(), ControllerState::kOpen);
  ASSERT_EQ(c.Cycle(At(100'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
}

// One pending departure: another departure's start time is not stored meanwhile.
// @verifies REQ-LC-009
// @verifies REQ-LC-014
TEST(LcCrossingController, AnotherDepartureWaitsForThePendingOne) {
  CrossingController c = StartStoredAt0();
  ASSERT_EQ(c.Cycle(WithStart(At(1'000), {{{kId, 6, 50'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Status().pending.departure_id, 5U);
  EXPECT_EQ(c.Status().pending.start_ms, 100'000);
  ASSERT_EQ(c.Output().StartAcks().size(), 1U);
  EXPECT_FALSE(c.Output().StartAcks()[0].stored);
  EXPECT_EQ(c.Output().StartAcks()[0].departure_id, 6U);
  // a message for another crossing is ignored
  ASSERT_EQ(c.Cycle(WithStart(At(2'000), {{{kId + 1, 5, 10'000}}})), ControllerError::kNone);
  EXPECT_EQ(c.Output().ignored_messages, 1U);
  EXPECT_TRUE(c.Output().StartAcks().empty());
  EXPECT_EQ(c.Status().pending.start_ms, 100'000);
}

// ---- clock (REQ-LC-013) --------------------------------------------------------------------

// @verifies REQ-LC-013
TEST(LcCrossingController, HoldoverThenFaultStartsTheWarningAtOnce) {
  CrossingController c = Make();
  ControllerInput in = At(0);
  in.clock = ClockInput::kNoGnss;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.Status().clock, ClockState::kHoldover);
  EXPECT_FALSE(c.Output().report.clock_fault);
  in.now_ms = kHoldover;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.Status().clock, ClockState::kHoldover);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
  in.now_ms = kHoldover + 1;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.Status().clock, ClockState::kFaulty);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  EXPECT_TRUE(c.Output().report.clock_fault);
  // GNSS back: the fault stays latched, the warning goes on (closed, never ended)
  ASSERT_EQ(c.Cycle(Moving(kHoldover + 1 + kLower)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Down(kHoldover + 20'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  ASSERT_EQ(c.Cycle(Down(kHoldover + 100'000)), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Status().clock, ClockState::kFaulty);
  EXPECT_TRUE(c.Output().report.clock_fault);
}

// @verifies REQ-LC-013
TEST(LcCrossingController, GnssBackBeforeTheLimitEndsTheHoldover) {
  CrossingController c = Make();
  ControllerInput in = At(0);
  in.clock = ClockInput::kNoGnss;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  in.now_ms = kHoldover;
  in.clock = ClockInput::kGnss;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.Status().clock, ClockState::kSynchronised);
  in.now_ms = kHoldover + 10;
  in.clock = ClockInput::kNoGnss;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.Status().clock, ClockState::kHoldover);
  EXPECT_EQ(c.Status().outage_start_ms, kHoldover + 10);
  EXPECT_EQ(c.State(), ControllerState::kOpen);
}

// @verifies REQ-LC-013
TEST(LcCrossingController, ClockHardwareFaultWarnsAtOnce) {
  CrossingController c = Make();
  ControllerInput in = At(5'000);
  in.clock = ClockInput::kFault;
  ASSERT_EQ(c.Cycle(in), ControllerError::kNone);
  EXPECT_EQ(c.State(), ControllerState::kWarning);
  EXPECT_EQ(c.Status().warning_start_ms, 5'000);
  EXPECT_TRUE(c.Output().report.clock_fault);
  EXPECT_STREQ(ToString(c.Status().clock), "FAULTY");
}

// ---- errors, names, no heap, determinism ------------------------------------------------------

// @verifies REQ-LC-006
TEST(LcCrossingController, TypedErrors) {
  ControllerConfig bad = DefaultControllerConfig(kId);
  bad.barrier_timeout_ms = 0;
  EXPECT_EQ(CrossingController::Create(bad).error, ControllerError::kConfigInvalid);
  const ControllerConfig d = DefaultControllerConfig(kId);
  EXPECT_EQ(d.barrier_lowering_ms, kLower);
  EXPECT_EQ(d.max_warning_ms, kMaxWarning);
  CrossingController c = ClosedByA();
  EXPECT_EQ(c.Cycle(Down(8'999)), ControllerError::kTimeWentBack);
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().report.status, CrossingStatus::kClosed);
  EXPECT_EQ(c.Cycle(Down(lc::kMaxClockMs + 1)), ControllerError::kTimeInvalid);
  std::vector<std::uint32_t> many(kMaxControllerMessages + 1, 5);
  ControllerInput in = Down(9'500);
  in.requests = many;
  EXPECT_EQ(c.Cycle(in), ControllerError::kTooManyMessages);
  EXPECT_EQ(c.Status().Requesters().size(), 1U);
  EXPECT_EQ(c.Cycle(WithStart(Down(9'500), {{{kId, 1, lc::kMaxClockMs + 1}}})),
            ControllerError::kTimeInvalid);
  railproof::testing::ExpectEnumNames<ControllerState>(std::array<const char*, 6>{"OPEN", "WARNING", "CLOSING", "CLOSED", "OPENING", "FAILED"});
  EXPECT_STREQ(ToString(FailureReason::kBarrierNotUp), "BARRIER_NOT_UP");
}

// More requesters than kMaxRequesters: the warning can then not end automatically.
// @verifies REQ-LC-003
// @verifies REQ-LC-007
// @verifies REQ-LC-014
TEST(LcCrossingController, RequesterOverflowKeepsWarning) {
  CrossingController c = Make();
  std::vector<std::uint32_t> trains;
  for (std::uint32_t t = 1; t <= kMaxRequesters + 1; ++t) {
    trains.push_back(t);
  }
  ASSERT_EQ(c.Cycle(Requesting(At(0), trains)), ControllerError::kNone);
  EXPECT_TRUE(c.Status().requester_overflow);
  ASSERT_EQ(c.Cycle(Moving(kLower)), ControllerError::kNone);
  ASSERT_EQ(c.Cycle(Down(9'000)), ControllerError::kNone);
  // the CLOSED report lists the stored requesters; the train beyond the capacity is not
  // listed, so it is never confirmed (design §4) and stops at its protection limit
  ASSERT_EQ(c.Output().report.status, CrossingStatus::kClosed);
  EXPECT_EQ(c.Output().report.requester_count, kMaxRequesters);
  EXPECT_TRUE(c.Output().report.Lists(1));
  EXPECT_TRUE(c.Output().report.Lists(static_cast<std::uint32_t>(kMaxRequesters)));
  EXPECT_FALSE(c.Output().report.Lists(static_cast<std::uint32_t>(kMaxRequesters + 1)));
  const std::span<const std::uint32_t> stored(trains.data(), kMaxRequesters);
  ASSERT_EQ(c.Cycle(Withdrawing(Down(10'000), stored)), ControllerError::kNone);
  EXPECT_TRUE(c.Status().Requesters().empty());
  EXPECT_EQ(c.State(), ControllerState::kClosed);
  EXPECT_EQ(c.Output().report.requester_count, 0U);
}

std::vector<std::int64_t> RunController(CrossingController& c) {
  std::vector<std::int64_t> trace;
  for (std::int64_t k = 0; k < 400; ++k) {
    const std::int64_t now = k * 500;
    ControllerInput in = (k % 7 == 3 || (k > 40 && k < 120)) ? Down(now) : At(now);
    if (k == 2) {
      in.requests = kTrainsAB;
    }
    if (k == 100) {
      in.withdrawals = kTrainA;
    }
    if (k == 150) {
      in.withdrawals = kTrainB;
    }
    EXPECT_EQ(c.Cycle(in), ControllerError::kNone);
    trace.push_back(static_cast<std::int64_t>(c.State()));
    trace.push_back(static_cast<std::int64_t>(c.Output().report.status));
    trace.push_back(c.Output().report.warning_start_ms);
  }
  return trace;
}

// @verifies REQ-LC-006
TEST(LcCrossingController, Deterministic) {
  CrossingController a = Make();
  CrossingController b = Make();
  EXPECT_EQ(RunController(a), RunController(b));
}

// @verifies REQ-LC-006
// @verifies REQ-LC-011
TEST(LcCrossingController, NoHeapInTheCycle) {
  CrossingController c = Make();
  const std::array<StartTimeMessage, 1> st{{{kId, 5, 100'000}}};
  const std::array<WarningStopMessage, 1> stop{{{kId, 5}}};
  testing::StartCountingAllocations();
  std::int64_t sum = 0;
  for (std::int64_t k = 0; k < 500; ++k) {
    ControllerInput in = (k % 3 == 0) ? Down(k * 500) : At(k * 500);
    if (k % 10 == 0) {
      in.requests = kTrainsAB;
      in.start_times = st;
    }
    if (k % 10 == 5) {
      in.withdrawals = kTrainsAB;
      in.warning_stops = stop;
    }
    sum += static_cast<std::int64_t>(c.Cycle(in));
    sum += static_cast<std::int64_t>(c.State());
  }
  const std::size_t allocations = testing::StopCountingAllocations();
  EXPECT_EQ(allocations, 0U);
  EXPECT_GE(sum, 0);
}

}  // namespace
}  // namespace railproof::lc::wayside
