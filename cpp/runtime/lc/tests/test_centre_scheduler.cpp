// Unit tests of the centre scheduler of GNSS-time pre-armed crossings (spec/design/
// level-crossing.md §5): hand-computed start times st_i, re-sending until acknowledged, the
// departure clearance (a missing acknowledgement, an acknowledgement not stored, a clock
// fault, before t_dep), the recomputation from position reports (late departure, dwell,
// earlier), the passage with the tracking plausibility and the warning stop re-sent until
// acknowledged, typed errors, no heap in the cycle and determinism.
//
// Kills the seeded fault FAULT_LC_DEPART_WITHOUT_ALL_ACKS (ctest unit_fault_<F>: these tests
// against the schemata variant with the fault selected).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "railproof/testing/alloc_counter.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"

namespace railproof::lc::wayside {
namespace {

using core::RestrictionSegment;

constexpr std::uint32_t kTrain = 3;
constexpr std::uint32_t kDep = 77;
constexpr std::int64_t kTdep = 100'000;
constexpr std::int64_t kAllowance = params::lc::clock_allowance_ms;  // 2000

// 20 m/s line, 0.5 m/s^2. From rest at 0: crossing 1 (near 1000 m) in 70 s (40 s to 20 m/s
// over 400 m, 600 m at 20 m/s), crossing 2 (near 2000 m) in 120 s.
constexpr std::array<RestrictionSegment, 1> kProfile{{{0, 5'000'000, 20'000}}};
constexpr std::array<CrossingData, 2> kCrossings{
    {{1, 1'000'000, 1'006'000, 30'000}, {2, 2'000'000, 2'010'000, 35'000}}};
constexpr std::int64_t kSt1 = kTdep + 70'000 - 30'000 - kAllowance;   // 138,000
constexpr std::int64_t kSt2 = kTdep + 120'000 - 35'000 - kAllowance;  // 183,000

CentreScheduler Started(std::int64_t now = 0) {
  auto created = CentreScheduler::Create(DefaultSchedulerConfig(500));
  EXPECT_EQ(created.error, SchedulerError::kNone);
  CentreScheduler s = std::move(*created.scheduler);
  EXPECT_EQ(s.StartDeparture({kTrain, kDep, kTdep, 0}, kCrossings, kProfile, now), SchedulerError::kNone);
  return s;
}

SchedulerInput At(std::int64_t now) {
  SchedulerInput in;
  in.now_ms = now;
  in.restrictions = kProfile;
  return in;
}

SchedulerInput WithAcks(SchedulerInput in, const std::array<StartTimeAck, 2>& acks) {
  in.start_acks = acks;
  return in;
}

// Both crossings acknowledged the initial start times.
CentreScheduler Acked() {
  CentreScheduler s = Started();
  const std::array<StartTimeAck, 2> acks{{{1, kDep, kSt1, true}, {2, kDep, kSt2, true}}};
  EXPECT_EQ(s.Cycle(WithAcks(At(1'000), acks)), SchedulerError::kNone);
  EXPECT_TRUE(s.Find(1)->acked);
  EXPECT_TRUE(s.Find(2)->acked);
  return s;
}

// @verifies REQ-LC-008
TEST(LcCentreScheduler, StartTimesFromThePlannedDeparture) {
  const CentreScheduler s = Started();
  EXPECT_EQ(kSt1, 138'000);
  EXPECT_EQ(kSt2, 183'000);
  EXPECT_EQ(s.Find(1)->initial_start_ms, kSt1);
  EXPECT_EQ(s.Find(2)->initial_start_ms, kSt2);
  // the start time is no later than the earliest arrival minus warning time minus allowance
  const lc::EtaResult eta = lc::EarliestArrivalMs(0, 1'000'000, 0, 500, kProfile);
  EXPECT_EQ(eta.eta_ms, 70'000);
  EXPECT_EQ(s.Find(1)->initial_start_ms, kTdep + eta.eta_ms - 30'000 - kAllowance);
  ASSERT_EQ(s.Output().StartTimes().size(), 2U);
  EXPECT_EQ(s.Output().StartTimes()[0].crossing_id, 1U);
  EXPECT_EQ(s.Output().StartTimes()[0].departure_id, kDep);
  EXPECT_EQ(s.Output().StartTimes()[0].start_ms, kSt1);
  EXPECT_EQ(s.Output().StartTimes()[1].start_ms, kSt2);
  EXPECT_FALSE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().block, DepartureBlock::kMissingAck);
}

// @verifies REQ-LC-008
// @verifies REQ-LC-009
TEST(LcCentreScheduler, ResentUntilAcknowledged) {
  CentreScheduler s = Started();
  ASSERT_EQ(s.Cycle(At(500)), SchedulerError::kNone);  // acks lost
  EXPECT_EQ(s.Output().StartTimes().size(), 2U);
  const std::array<StartTimeAck, 2> one{{{2, kDep, kSt2, true}, {9, kDep, 0, true}}};
  ASSERT_EQ(s.Cycle(WithAcks(At(1'000), one)), SchedulerError::kNone);
  ASSERT_EQ(s.Output().StartTimes().size(), 1U);
  EXPECT_EQ(s.Output().StartTimes()[0].crossing_id, 1U);
  EXPECT_EQ(s.Output().ignored_messages, 1U);  // crossing 9 is not of this departure
}

// Departure signal only with every acknowledgement of this departure, no clock fault, now >= t_dep.
// @verifies REQ-LC-009
TEST(LcCentreScheduler, DepartureNeedsEveryAcknowledgement) {
  CentreScheduler s = Started();
  // one ack missing: not cleared even after t_dep
  const std::array<StartTimeAck, 2> one{{{1, kDep, kSt1, true}, {2, kDep + 1, kSt2, true}}};
  ASSERT_EQ(s.Cycle(WithAcks(At(kTdep), one)), SchedulerError::kNone);
  EXPECT_TRUE(s.Find(1)->acked);
  EXPECT_FALSE(s.Find(2)->acked);  // the ack names another departure
  EXPECT_FALSE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().block, DepartureBlock::kMissingAck);
  ASSERT_EQ(s.Cycle(At(kTdep + 10'000)), SchedulerError::kNone);
  EXPECT_FALSE(s.Output().departure_cleared);
  // an ack that was not stored (another departure pending at the controller) does not count
  const std::array<StartTimeAck, 2> refused{{{2, kDep, kSt2, false}, {2, kDep, kSt2 + 1, true}}};
  ASSERT_EQ(s.Cycle(WithAcks(At(kTdep + 10'500), refused)), SchedulerError::kNone);
  EXPECT_FALSE(s.Find(2)->acked);  // nor one with a later time in force than computed
  EXPECT_FALSE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().StartTimes().size(), 1U);
  const std::array<StartTimeAck, 2> good{{{2, kDep, kSt2, true}, {2, kDep, kSt2, true}}};
  ASSERT_EQ(s.Cycle(WithAcks(At(kTdep + 11'000), good)), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().block, DepartureBlock::kNone);
  EXPECT_TRUE(s.Output().StartTimes().empty());
}

// @verifies REQ-LC-009
TEST(LcCentreScheduler, NotBeforeThePlannedDeparture) {
  CentreScheduler s = Acked();
  ASSERT_EQ(s.Cycle(At(kTdep - 1)), SchedulerError::kNone);
  EXPECT_FALSE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().block, DepartureBlock::kBeforeDeparture);
  ASSERT_EQ(s.Cycle(At(kTdep)), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().departure_cleared);
}

// @verifies REQ-LC-013
TEST(LcCentreScheduler, ClockFaultBlocksTheDeparture) {
  CentreScheduler s = Acked();
  const std::array<CrossingReport, 1> fault{{{2, CrossingStatus::kWarning, 0, kTdep, true}}};
  SchedulerInput in = At(kTdep);
  in.reports = fault;
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Find(2)->clock_fault);
  EXPECT_FALSE(s.Output().departure_cleared);
  EXPECT_EQ(s.Output().block, DepartureBlock::kClockFault);
  ASSERT_EQ(s.Cycle(At(kTdep + 500)), SchedulerError::kNone);  // no new report: still faulty
  EXPECT_FALSE(s.Output().departure_cleared);
  const std::array<CrossingReport, 1> ok{{{2, CrossingStatus::kOpen, 0, kTdep + 1'000, false}}};
  in = At(kTdep + 1'000);
  in.reports = ok;
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().departure_cleared);
}

// A departure 5 s late: the start times move 5 s later (sent until acknowledged).
// @verifies REQ-LC-010
TEST(LcCentreScheduler, LaterStartTimesFromPositionReports) {
  CentreScheduler s = Acked();
  // departed at 105 s from rest: at 110 s it runs 2.5 m/s at 6.25 m
  SchedulerInput in = At(110'200);
  in.position = CentrePositionReport{kTrain, 110'000, 6'250, 0, 2'500};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_EQ(s.Find(1)->start_ms, kSt1 + 5'000);
  EXPECT_EQ(s.Find(2)->start_ms, kSt2 + 5'000);
  EXPECT_EQ(s.Find(1)->initial_start_ms, kSt1);
  ASSERT_EQ(s.Output().StartTimes().size(), 2U);
  EXPECT_EQ(s.Output().StartTimes()[0].start_ms, kSt1 + 5'000);
  EXPECT_EQ(s.TrackedFrontMm(), 6'250);
  // crossing 1 refuses (already warning: earlier time in force), crossing 2 stores it; both
  // end the re-sending
  const std::array<StartTimeAck, 2> acks{{{1, kDep, kSt1, true}, {2, kDep, kSt2 + 5'000, true}}};
  ASSERT_EQ(s.Cycle(WithAcks(At(110'500), acks)), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().StartTimes().empty());
  EXPECT_EQ(s.Find(1)->acked_start_ms, kSt1);
  EXPECT_EQ(s.Find(2)->acked_start_ms, kSt2 + 5'000);
  EXPECT_TRUE(s.Output().departure_cleared);  // the initial acks stay latched
}

// Standing at A before t_dep: the dwell-aware prediction gives the same start times.
// @verifies REQ-LC-005
// @verifies REQ-LC-010
TEST(LcCentreScheduler, StandingBeforeDepartureChangesNothing) {
  CentreScheduler s = Acked();
  SchedulerInput in = At(50'000);
  in.position = CentrePositionReport{kTrain, 50'000, 0, -100'000, 0};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_EQ(s.Find(1)->start_ms, kSt1);
  EXPECT_EQ(s.Find(2)->start_ms, kSt2);
  EXPECT_TRUE(s.Output().StartTimes().empty());
}

// A report further ahead than predicted (e.g. a position correction) sends an earlier time.
// @verifies REQ-LC-010
// @verifies REQ-LC-014
TEST(LcCentreScheduler, EarlierRecomputationIsSentToo) {
  CentreScheduler s = Acked();
  SchedulerInput in = At(110'000);
  in.position = CentrePositionReport{kTrain, 110'000, 50'000, -50'000, 10'000};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  // ETA from 50 m at 10 m/s: 20 s to 20 m/s over 300 m, 650 m cruising: 52.5 s
  EXPECT_EQ(s.Find(1)->start_ms, 110'000 + 52'500 - 30'000 - kAllowance);
  EXPECT_LT(s.Find(1)->start_ms, kSt1);
  EXPECT_EQ(s.Output().StartTimes().size(), 2U);
}

// @verifies REQ-LC-012
TEST(LcCentreScheduler, WarningStopAfterAPlausiblePassageUntilAcknowledged) {
  CentreScheduler s = Acked();
  SchedulerInput in = At(200'000);
  in.position = CentrePositionReport{kTrain, 199'000, 1'106'000, 1'005'999, 20'000};  // rear 1 mm short
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_FALSE(s.Find(1)->passed);
  EXPECT_TRUE(s.Output().WarningStops().empty());
  in = At(205'000);
  in.position = CentrePositionReport{kTrain, 204'500, 1'106'000, 1'006'000, 20'000};  // rear at far
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Find(1)->passed);
  ASSERT_EQ(s.Output().WarningStops().size(), 1U);
  EXPECT_EQ(s.Output().WarningStops()[0].crossing_id, 1U);
  EXPECT_EQ(s.Output().WarningStops()[0].departure_id, kDep);
  for (const StartTimeMessage& m : s.Output().StartTimes()) {
    EXPECT_NE(m.crossing_id, 1U);  // no start time for a passed crossing
  }
  ASSERT_EQ(s.Cycle(At(205'500)), SchedulerError::kNone);  // ack lost: re-sent
  EXPECT_EQ(s.Output().WarningStops().size(), 1U);
  const std::array<WarningStopAck, 2> acks{{{1, kDep + 1}, {1, kDep}}};
  in = At(206'000);
  in.stop_acks = acks;
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().WarningStops().empty());
  EXPECT_TRUE(s.Find(1)->stop_acked);
  EXPECT_EQ(s.Output().ignored_messages, 1U);
}

// A report whose front is behind the tracked front is not plausible: no passage from it.
// @verifies REQ-LC-012
// @verifies REQ-LC-014
TEST(LcCentreScheduler, ImplausibleReportGivesNoWarningStop) {
  CentreScheduler s = Acked();
  SchedulerInput in = At(200'000);
  in.position = CentrePositionReport{kTrain, 200'000, 900'000, 800'000, 20'000};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_EQ(s.TrackedFrontMm(), 900'000);
  in = At(201'000);
  in.position = CentrePositionReport{kTrain, 201'000, 899'999, 899'999 - 1, 20'000};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().report_rejected);
  // a report claiming the passage with its front behind the tracked front
  in = At(202'000);
  in.position = CentrePositionReport{kTrain, 202'000, 899'000, 899'000, 20'000};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  in.position = CentrePositionReport{kTrain, 202'000, 1'200'000 - 1, 1'100'000, 20'000};
  in.now_ms = 202'000;
  // time in the future: rejected as well
  in.position->time_ms = 202'001;
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_TRUE(s.Output().report_rejected);
  EXPECT_FALSE(s.Find(1)->passed);
  EXPECT_TRUE(s.Output().WarningStops().empty());
  EXPECT_EQ(s.TrackedFrontMm(), 900'000);
  // a report of another train is ignored
  in.position = CentrePositionReport{kTrain + 1, 202'000, 1'200'000, 1'100'000, 20'000};
  ASSERT_EQ(s.Cycle(in), SchedulerError::kNone);
  EXPECT_EQ(s.Output().ignored_messages, 1U);
  EXPECT_FALSE(s.Find(1)->passed);
}

// @verifies REQ-LC-008
TEST(LcCentreScheduler, TypedErrors) {
  EXPECT_EQ(CentreScheduler::Create(DefaultSchedulerConfig(0)).error, SchedulerError::kConfigInvalid);
  auto created = CentreScheduler::Create(DefaultSchedulerConfig(500));
  ASSERT_TRUE(created.scheduler.has_value());
  CentreScheduler& s = *created.scheduler;
  EXPECT_EQ(s.Config().clock_allowance_ms, kAllowance);
  EXPECT_EQ(s.Cycle(At(0)), SchedulerError::kNoDeparture);
  EXPECT_EQ(s.Output().block, DepartureBlock::kNoDeparture);
  const std::array<CrossingData, 2> bad{{{1, 1'000, 2'000, 30'000}, {2, 3'000, 3'000, 30'000}}};
  EXPECT_EQ(s.StartDeparture({kTrain, kDep, kTdep, 0}, bad, kProfile, 0), SchedulerError::kCrossingDataInvalid);
  EXPECT_EQ(s.CrossingError().error, lc::CrossingDataError::kExtentInvalid);
  EXPECT_EQ(s.CrossingError().entry, 1U);
  EXPECT_FALSE(s.CurrentDeparture().has_value());
  const std::array<RestrictionSegment, 1> badprofile{{{0, 10, 0}}};
  EXPECT_EQ(s.StartDeparture({kTrain, kDep, kTdep, 0}, kCrossings, badprofile, 0), SchedulerError::kProfileInvalid);
  ASSERT_EQ(s.StartDeparture({kTrain, kDep, kTdep, 0}, kCrossings, kProfile, 1'000), SchedulerError::kNone);
  EXPECT_EQ(s.Cycle(At(999)), SchedulerError::kTimeWentBack);
  SchedulerInput in = At(1'000);
  in.position = CentrePositionReport{kTrain, 1'000, 0, 1, 0};  // rear ahead of front
  EXPECT_EQ(s.Cycle(in), SchedulerError::kPositionInvalid);
  in.position = CentrePositionReport{kTrain, 1'000, 10, 0, -5};
  EXPECT_EQ(s.Cycle(in), SchedulerError::kSpeedInvalid);
  std::vector<StartTimeAck> flood(kMaxSchedulerMessages + 1);
  in = At(1'000);
  in.start_acks = flood;
  EXPECT_EQ(s.Cycle(in), SchedulerError::kTooManyMessages);
  EXPECT_EQ(s.Output().StartTimes().size(), 2U);  // still sending after refused cycles
  EXPECT_STREQ(ToString(DepartureBlock::kMissingAck), "MISSING_ACK");
  EXPECT_STREQ(ToString(SchedulerError::kNoDeparture), "NO_DEPARTURE");
}

std::vector<std::int64_t> RunDeparture(CentreScheduler& s) {
  std::vector<std::int64_t> trace;
  std::int64_t front = 0;
  std::int64_t v = 0;
  for (std::int64_t now = 0; now < 400'000; now += 500) {
    SchedulerInput in = At(now);
    std::array<StartTimeAck, 2> acks{};
    std::size_t n = 0;
    for (const StartTimeMessage& m : s.Output().StartTimes()) {
      acks[n++] = StartTimeAck{m.crossing_id, m.departure_id, m.start_ms, true};
    }
    in.start_acks = std::span<const StartTimeAck>(acks.data(), n);
    std::array<WarningStopAck, 2> stops{};
    std::size_t m = 0;
    for (const WarningStopMessage& w : s.Output().WarningStops()) {
      stops[m++] = WarningStopAck{w.crossing_id, w.departure_id};
    }
    in.stop_acks = std::span<const WarningStopAck>(stops.data(), m);
    if (now % 5'000 == 0) {
      in.position = CentrePositionReport{kTrain, now, front, front - 80'000, v};
    }
    EXPECT_EQ(s.Cycle(in), SchedulerError::kNone);
    if (s.Output().departure_cleared || v > 0) {
      front += v / 2;
      v = v + 250 > 20'000 ? 20'000 : v + 250;
    }
    for (const ScheduledCrossing& c : s.Crossings()) {
      trace.push_back(c.start_ms);
      trace.push_back(c.passed ? 1 : 0);
    }
    trace.push_back(s.Output().departure_cleared ? 1 : 0);
  }
  return trace;
}

// @verifies REQ-LC-008
// @verifies REQ-LC-012
TEST(LcCentreScheduler, DeterministicRunPassesEveryCrossing) {
  CentreScheduler a = Started();
  CentreScheduler b = Started();
  EXPECT_EQ(RunDeparture(a), RunDeparture(b));
  EXPECT_TRUE(a.Find(1)->stop_acked);
  EXPECT_TRUE(a.Find(2)->stop_acked);
  // the train departed on time at full acceleration: the start times never moved earlier
  EXPECT_GE(a.Find(1)->start_ms, kSt1);
}

// @verifies REQ-LC-008
// @verifies REQ-LC-010
TEST(LcCentreScheduler, NoHeapInTheCycle) {
  CentreScheduler s = Acked();
  testing::StartCountingAllocations();
  std::int64_t sum = 0;
  for (std::int64_t k = 0; k < 200; ++k) {
    SchedulerInput in = At(2'000 + k * 500);
    in.position = CentrePositionReport{kTrain, 2'000 + k * 500, k * 1'000, k * 1'000 - 80'000, 5'000};
    sum += static_cast<std::int64_t>(s.Cycle(in));
    sum += s.Find(1)->start_ms;
  }
  const std::size_t allocations = testing::StopCountingAllocations();
  EXPECT_EQ(allocations, 0U);
  EXPECT_NE(sum, 0);
}

}  // namespace
}  // namespace railproof::lc::wayside
