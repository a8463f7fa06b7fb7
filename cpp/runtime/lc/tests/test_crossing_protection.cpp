// Unit tests of the on-board level-crossing function (spec/design/lc.md §1-§3):
// the earliest arrival with hand-computed values (accelerate then cruise, above-limit speed,
// a restriction ahead, gaps, accelerate only, never, dwell), the crossing extent and data
// validation, the request boundary (ETA exactly warning_time + lead and 1 ms later), the
// clearance boundaries (warning time, confirmation age), re-protection on FAILED / OPEN /
// WARNING, the protection stop limit, the withdrawal boundary (rear exactly at far) with
// its acknowledgement, the dwell-aware request, typed input errors, no heap in the cycle
// and determinism.
//
// Kills the seeded faults FAULT_LC_CLEAR_WITHOUT_WARNING_TIME, FAULT_LC_STALE_CONFIRMATION and
// FAULT_LC_WITHDRAW_AT_FRONT (ctest unit_fault_<F>: these tests against the schemata variant
// with the fault selected).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "railproof/testing/enum_names.hpp"
#include "railproof/testing/alloc_counter.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"

namespace railproof::lc::onboard {
namespace {

using core::RestrictionSegment;

constexpr std::uint32_t kTrain = 7;
constexpr std::int64_t kLength = 100'000;  // 100 m
constexpr std::int64_t kW = 30'000;        // design warning time
constexpr std::int64_t kLead = params::lc::request_lead_ms;
// At a constant 20 m/s (20 mm/ms) the request distance is (warning + lead) x 20 mm/ms.
constexpr std::int64_t kRequestDistMm = (kW + kLead) * 20;

// Crossing 1 at [1,000,000, 1,006,000), crossing 2 at [2,000,000, 2,010,000).
constexpr CrossingData kLc1{1, 1'000'000, 1'006'000, kW};
constexpr CrossingData kLc2{2, 2'000'000, 2'010'000, 35'000};

CrossingProtection Make(std::int64_t accel = 0) {
  auto created = CrossingProtection::Create(DefaultProtectionConfig(kTrain, kLength, accel));
  EXPECT_EQ(created.error, ProtectionError::kNone);
  return std::move(*created.protection);
}

// A cycle at `now` with the front at `front` (no position errors), speed v, no messages.
ProtectionInput At(std::int64_t now, std::int64_t front, std::int64_t v) {
  ProtectionInput in;
  in.now_ms = now;
  in.front_mm = front;
  in.speed_mm_s = v;
  return in;
}

CrossingState StateOf(const CrossingProtection& p, std::uint32_t id) {
  const CrossingEntry* e = p.Find(id);
  EXPECT_NE(e, nullptr);
  return e == nullptr ? CrossingState::kDone : e->state;
}

// ---- earliest arrival (design §2) -------------------------------------------------------

// @verifies REQ-LC-001
TEST(LcEarliestArrival, AccelerateThenCruise) {
  // 10 m/s, 0.5 m/s^2 up to 20 m/s: 20 s accelerating over 300 m, 700 m cruising at 20 m/s
  // (35 s): 55 s.
  const std::array<RestrictionSegment, 1> profile{{{0, 2'000'000, 20'000}}};
  EtaResult r = EarliestArrivalMs(0, 1'000'000, 10'000, 500, profile);
  EXPECT_EQ(r.error, EtaError::kNone);
  EXPECT_EQ(r.eta_ms, 55'000);
  // one more millimetre is 0.05 ms: rounded down
  r = EarliestArrivalMs(0, 1'000'001, 10'000, 500, profile);
  EXPECT_EQ(r.eta_ms, 55'000);
  // 20 mm more is exactly 1 ms more
  r = EarliestArrivalMs(0, 1'000'020, 10'000, 500, profile);
  EXPECT_EQ(r.eta_ms, 55'001);
  // the same start position offset along the line gives the same time
  const std::array<RestrictionSegment, 1> shifted{{{500'000, 2'500'000, 20'000}}};
  EXPECT_EQ(EarliestArrivalMs(500'000, 1'500'000, 10'000, 500, shifted).eta_ms, 55'000);
}

// @verifies REQ-LC-001
TEST(LcEarliestArrival, AboveTheLimitTheTrainRunsAsFastAsItIs) {
  // 30 m/s in a 20 m/s section: never assumed to brake, never to accelerate above 30 m/s.
  const std::array<RestrictionSegment, 1> profile{{{0, 2'000'000, 20'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 600'000, 30'000, 500, profile).eta_ms, 20'000);  // not 30 s
  // also through a lower restriction further ahead
  const std::array<RestrictionSegment, 2> two{{{0, 300'000, 20'000}, {300'000, 2'000'000, 10'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 600'000, 30'000, 500, two).eta_ms, 20'000);
}

// @verifies REQ-LC-001
TEST(LcEarliestArrival, RestrictionAheadIsTakenAtItsLimit) {
  // 5 m/s up to 20 m/s over [0, 500 m): 30 s over 375 m, 125 m at 20 m/s (6.25 s) = 36.25 s;
  // then [500 m, 1000 m) at 10 m/s (entered at its limit: instant slowing is the earliest
  // case): 50 s. Total 86.25 s.
  const std::array<RestrictionSegment, 2> profile{
      {{0, 500'000, 20'000}, {500'000, 2'000'000, 10'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 1'000'000, 5'000, 500, profile).eta_ms, 86'250);
}

// @verifies REQ-LC-001
TEST(LcEarliestArrival, GapsAreUnboundedAndPiecesRoundDownSeparately) {
  // a = 0: cruise at 10 m/s; the restriction [200 m, 300 m) at 10 m/s does not slow it.
  const std::array<RestrictionSegment, 1> one{{{200'000, 300'000, 10'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 1'000'000, 10'000, 0, one).eta_ms, 100'000);
  // 3 pieces of 15 mm at 10,000 mm/s: 1.5 ms each, rounded down per piece: 1 + 1 + 1
  const std::array<RestrictionSegment, 1> mid{{{15, 30, 10'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 45, 10'000, 0, mid).eta_ms, 3);
  // without the restriction cut the same run is one piece: floor(4.5) = 4
  EXPECT_EQ(EarliestArrivalMs(0, 45, 10'000, 0, {}).eta_ms, 4);
}

// @verifies REQ-LC-001
TEST(LcEarliestArrival, AccelerateOnly) {
  // from rest at 1 m/s^2 over 100 m without a limit: sqrt(200) s = 14.1421... s
  EXPECT_EQ(EarliestArrivalMs(0, 100'000, 0, 1'000, {}).eta_ms, 14'142);
  // 2 m/s^2 over 1 m from rest: 1 s exactly
  EXPECT_EQ(EarliestArrivalMs(0, 1'000, 0, 2'000, {}).eta_ms, 1'000);
  // the end speed carried on is rounded up: 1 m at 2 m/s^2 reaches 2000 mm/s exactly, then
  // 2 m at the limit 2000 mm/s is 1 s
  const std::array<RestrictionSegment, 1> lim{{{1'000, 10'000, 2'000}}};
  EXPECT_EQ(EarliestArrivalMs(0, 3'000, 0, 2'000, lim).eta_ms, 2'000);
}

// @verifies REQ-LC-001
TEST(LcEarliestArrival, ReachedNeverAndErrors) {
  EXPECT_EQ(EarliestArrivalMs(5'000, 5'000, 0, 0, {}).eta_ms, 0);
  EXPECT_EQ(EarliestArrivalMs(6'000, 5'000, 0, 0, {}).eta_ms, 0);
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, 0, 0, {}).eta_ms, kEtaNeverMs);
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, -1, 500, {}).error, EtaError::kSpeedInvalid);
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, core::kMaxMeasuredSpeedMmS + 1, 500, {}).error,
            EtaError::kSpeedInvalid);
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, 0, -1, {}).error, EtaError::kAccelerationInvalid);
  EXPECT_EQ(EarliestArrivalMs(0, core::kMaxPositionMm + 1, 0, 1, {}).error,
            EtaError::kPositionInvalid);
  const std::array<RestrictionSegment, 2> overlap{{{0, 100, 10}, {50, 200, 10}}};
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, 0, 1, overlap).error, EtaError::kProfileInvalid);
  const std::array<RestrictionSegment, 1> empty{{{100, 100, 10}}};
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, 0, 1, empty).error, EtaError::kProfileInvalid);
  const std::array<RestrictionSegment, 1> zero{{{0, 100, 0}}};
  EXPECT_EQ(EarliestArrivalMs(0, 5'000, 0, 1, zero).error, EtaError::kProfileInvalid);
  // the profile is checked even when the target is reached
  EXPECT_EQ(EarliestArrivalMs(0, 0, 0, 0, zero).error, EtaError::kProfileInvalid);
  EXPECT_STREQ(ToString(EtaError::kProfileInvalid), "PROFILE_INVALID");
}

// @verifies REQ-LC-005
TEST(LcEarliestArrival, DwellAddsTheRemainingDwell) {
  // 30 s to the departure, then 14.142 s from rest (sqrt(200) s)
  EXPECT_EQ(EarliestArrivalAfterDwellMs(1'000, 31'000, 0, 100'000, 1'000, {}).eta_ms, 44'142);
  // departure time already past: the run from rest only
  EXPECT_EQ(EarliestArrivalAfterDwellMs(40'000, 31'000, 0, 100'000, 1'000, {}).eta_ms, 14'142);
  EXPECT_EQ(EarliestArrivalAfterDwellMs(0, 10, 0, 100'000, 0, {}).eta_ms, kEtaNeverMs);
  EXPECT_EQ(EarliestArrivalAfterDwellMs(kMaxClockMs + 1, 0, 0, 1, 1, {}).error, EtaError::kTimeInvalid);
}

// ---- crossing data (design §1) -----------------------------------------------------------

// @verifies REQ-LC-003
// @verifies REQ-LC-004
TEST(LcCrossingData, ExtentRoundsOutwards) {
  EXPECT_EQ(CrossingExtentOf(2'850'000, 6'000).near_mm, 2'847'000);
  EXPECT_EQ(CrossingExtentOf(2'850'000, 6'000).far_mm, 2'853'000);
  EXPECT_EQ(CrossingExtentOf(100, 5).near_mm, 97);
  EXPECT_EQ(CrossingExtentOf(100, 5).far_mm, 103);
}

// @verifies REQ-LC-001
TEST(LcCrossingData, InvalidCrossingsAreRefused) {
  CrossingProtection p = Make();
  EXPECT_EQ(p.AddCrossing({9, 500, 500, kW}), ProtectionError::kCrossingExtentInvalid);
  EXPECT_EQ(p.AddCrossing({9, 600, 500, kW}), ProtectionError::kCrossingExtentInvalid);
  EXPECT_EQ(p.AddCrossing({9, 500, 600, 0}), ProtectionError::kCrossingWarningTimeInvalid);
  EXPECT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  EXPECT_EQ(p.AddCrossing({1, 3'000'000, 3'001'000, kW}), ProtectionError::kCrossingDuplicateId);
  EXPECT_EQ(p.AddCrossing({3, 900'000, 901'000, kW}), ProtectionError::kCrossingUnsorted);
  EXPECT_EQ(p.AddCrossing({3, 1'005'000, 1'010'000, kW}), ProtectionError::kCrossingOverlap);
  EXPECT_EQ(p.Entries().size(), 1U);

  const std::array<CrossingData, 2> dup{{kLc1, {1, 3'000'000, 3'001'000, kW}}};
  EXPECT_EQ(ValidateCrossings(dup).error, CrossingDataError::kDuplicateId);
  EXPECT_EQ(ValidateCrossings(dup).entry, 1U);
  EXPECT_EQ(p.LoadCrossings(dup), ProtectionError::kCrossingDuplicateId);
  EXPECT_TRUE(p.Entries().empty());  // nothing held after a refused load

  std::vector<CrossingData> many;
  for (std::uint32_t i = 0; i <= kMaxCrossings; ++i) {
    many.push_back({i + 1, 1'000 * i, 1'000 * i + 10, kW});
  }
  EXPECT_EQ(p.LoadCrossings(many), ProtectionError::kTooManyCrossings);
  many.pop_back();
  EXPECT_EQ(p.LoadCrossings(many), ProtectionError::kNone);
  EXPECT_EQ(p.AddCrossing({999, 10'000'000, 10'000'010, kW}), ProtectionError::kTooManyCrossings);
}

// @verifies REQ-LC-001
TEST(LcCrossingProtection, ConfigurationErrors) {
  EXPECT_EQ(CrossingProtection::Create(DefaultProtectionConfig(kTrain, 0, 500)).error,
            ProtectionError::kTrainLengthInvalid);
  EXPECT_EQ(CrossingProtection::Create(DefaultProtectionConfig(kTrain, kLength, -1)).error,
            ProtectionError::kAccelerationInvalid);
  ProtectionConfig c = DefaultProtectionConfig(kTrain, kLength, 500);
  EXPECT_EQ(c.request_lead_ms, params::lc::request_lead_ms);
  EXPECT_EQ(c.confirmation_max_age_ms, params::lc::confirmation_max_age_ms);
  EXPECT_EQ(c.protection_offset_mm, params::lc::protection_offset_mm);
  EXPECT_EQ(c.lookahead_mm, params::lc::crossing_lookahead_mm);
  c.lookahead_mm = 0;
  EXPECT_EQ(CrossingProtection::Create(c).error, ProtectionError::kParameterInvalid);
  railproof::testing::ExpectEnumNames<CrossingState>(std::array<const char*, 5>{"APPROACHING", "REQUESTED", "CLEARED", "PASSED", "DONE"});
  EXPECT_STREQ(ToString(CrossingStatus::kClosed), "CLOSED");
  EXPECT_STREQ(ToString(ProtectionError::kTimeWentBack), "TIME_WENT_BACK");
}

// ---- request (REQ-LC-002) ---------------------------------------------------------------------

// Constant 20 m/s, no acceleration: ETA = distance / 20 ms; requested at warning + lead.
// @verifies REQ-LC-002
TEST(LcCrossingProtection, RequestExactlyAtWarningTimePlusLead) {
  CrossingProtection p = Make();
  ASSERT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  // ETA warning + lead + 1 ms: not yet
  ASSERT_EQ(p.Cycle(At(0, 1'000'000 - kRequestDistMm - 20, 20'000)), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kW + kLead + 1);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kApproaching);
  EXPECT_TRUE(p.Output().Requests().empty());
  // ETA exactly warning + lead: requested, and the request is sent in the same cycle
  ASSERT_EQ(p.Cycle(At(1, 1'000'000 - kRequestDistMm, 20'000)), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kW + kLead);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  ASSERT_EQ(p.Output().Requests().size(), 1U);
  EXPECT_EQ(p.Output().Requests()[0], 1U);
  // repeated every cycle, also when the train stops
  ASSERT_EQ(p.Cycle(At(2, 1'000'000 - kRequestDistMm, 0)), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kEtaNeverMs);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  EXPECT_EQ(p.Output().Requests().size(), 1U);
}

// The envelope front (front + front error) is the one predicted.
// @verifies REQ-LC-001
// @verifies REQ-LC-002
TEST(LcCrossingProtection, RequestUsesTheFrontOfTheEnvelope) {
  CrossingProtection p = Make();
  ASSERT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  ProtectionInput in = At(0, 1'000'000 - kRequestDistMm - 20, 20'000);
  in.front_error_mm = 20;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
}

// @verifies REQ-LC-001
// @verifies REQ-LC-002
TEST(LcCrossingProtection, NoRequestBeyondTheLookahead) {
  ProtectionConfig c = DefaultProtectionConfig(kTrain, kLength, 0);
  c.lookahead_mm = 500'000;
  auto created = CrossingProtection::Create(c);
  ASSERT_TRUE(created.protection.has_value());
  CrossingProtection& p = *created.protection;
  ASSERT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  // 600 m ahead at 100 m/s: ETA 6 s but beyond the 500 m look-ahead
  ASSERT_EQ(p.Cycle(At(0, 400'000, 100'000)), ProtectionError::kNone);
  EXPECT_FALSE(p.Find(1)->within_lookahead);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kApproaching);
  EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - c.protection_offset_mm);  // protected anyway
  ASSERT_EQ(p.Cycle(At(1, 500'000, 100'000)), ProtectionError::kNone);
  EXPECT_TRUE(p.Find(1)->within_lookahead);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
}

// ---- clearance (REQ-LC-003) ---------------------------------------------------------------------

// Requested at ETA 30 s (now 10,000, front 400 m before near at 20 m/s: ETA 20,000 ms).
CrossingProtection Requested(std::int64_t now = 10'000) {
  CrossingProtection p = Make();
  EXPECT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  EXPECT_EQ(p.Cycle(At(now, 600'000, 20'000)), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, 20'000);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  return p;
}

// A controller report of crossing `id` listing this train among the requesters (unless
// `listed` is false: a report held for other trains only).
CrossingReport Rep(std::uint32_t id, CrossingStatus status, std::int64_t ws, std::int64_t issued, bool listed = true) {
  CrossingReport r{id, status, ws, issued, false};
  if (listed) {
    r.requesters[0] = kTrain;
    r.requester_count = 1;
  }
  return r;
}

ProtectionInput WithReport(ProtectionInput in, const std::array<CrossingReport, 1>& r) {
  in.reports = r;
  return in;
}

// ws + warning_time <= now + ETA: with now 10,000 and ETA 20,000, ws <= 0.
// @verifies REQ-LC-003
TEST(LcCrossingProtection, ClearanceNeedsTheWarningTimeBeforeArrival) {
  {
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> late{{Rep(1, CrossingStatus::kClosed, 1, 10'000)}};
    ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), late)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);  // ws 1 ms too late
    EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - params::lc::protection_offset_mm);
    EXPECT_EQ(p.Output().limiting_crossing_id, 1U);
  }
  {
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> exact{{Rep(1, CrossingStatus::kClosed, 0, 10'000)}};
    ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), exact)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
    EXPECT_EQ(p.Find(1)->cleared_ws_ms, 0);
    EXPECT_FALSE(p.Output().stop_limit_mm.has_value());
    EXPECT_EQ(p.Output().Requests().size(), 1U);  // still requested every cycle
  }
}

// @verifies REQ-LC-003
// @verifies REQ-LC-014
TEST(LcCrossingProtection, ClearanceNeedsAFreshConfirmation) {
  const std::int64_t max_age = params::lc::confirmation_max_age_ms;
  {
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> stale{{Rep(1, CrossingStatus::kClosed, -10'000, 13'000 - max_age - 1)}};
    ASSERT_EQ(p.Cycle(WithReport(At(13'000, 660'000, 20'000), stale)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
    EXPECT_TRUE(p.Output().stop_limit_mm.has_value());
  }
  {
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> fresh{{Rep(1, CrossingStatus::kClosed, -10'000, 13'000 - max_age)}};
    ASSERT_EQ(p.Cycle(WithReport(At(13'000, 660'000, 20'000), fresh)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
  }
  {
    // a report stamped in the future is ignored
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> future{{Rep(1, CrossingStatus::kClosed, -10'000, 13'001)}};
    ASSERT_EQ(p.Cycle(WithReport(At(13'000, 660'000, 20'000), future)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
    EXPECT_EQ(p.Output().ignored_messages, 1U);
  }
}

// @verifies REQ-LC-003
TEST(LcCrossingProtection, OnlyAClosedReportOfThisCrossingClears) {
  CrossingProtection p = Requested();
  const std::array<CrossingReport, 3> reports{{Rep(1, CrossingStatus::kWarning, -20'000, 10'000),
                                               Rep(1, CrossingStatus::kFailed, -20'000, 10'000),
                                               Rep(5, CrossingStatus::kClosed, -20'000, 10'000)}};
  ProtectionInput in = At(10'000, 600'000, 20'000);
  in.reports = reports;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  EXPECT_EQ(p.Output().ignored_messages, 1U);  // crossing 5 is not held
}

// A closure confirmation is used only in kRequested: not before the request.
// @verifies REQ-LC-003
TEST(LcCrossingProtection, NoClearanceWhileApproaching) {
  CrossingProtection p = Make();
  ASSERT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, -100'000, 0)}};
  ASSERT_EQ(p.Cycle(WithReport(At(0, 0, 20'000), closed)), ProtectionError::kNone);  // ETA 50 s
  EXPECT_EQ(StateOf(p, 1), CrossingState::kApproaching);
}

// @verifies REQ-LC-003
// @verifies REQ-LC-014
TEST(LcCrossingProtection, FailedOpenOrWarningReportReprotects) {
  for (const CrossingStatus s : {CrossingStatus::kFailed, CrossingStatus::kOpen, CrossingStatus::kWarning}) {
    CrossingProtection p = Requested();
    const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, -20'000, 10'000)}};
    ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), closed)), ProtectionError::kNone);
    ASSERT_EQ(StateOf(p, 1), CrossingState::kCleared);
    const std::array<CrossingReport, 1> bad{{Rep(1, s, -20'000, 10'500)}};
    ASSERT_EQ(p.Cycle(WithReport(At(10'500, 610'000, 20'000), bad)), ProtectionError::kNone);
    EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested) << ToString(s);
    EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - params::lc::protection_offset_mm);
    EXPECT_EQ(p.Output().Requests().size(), 1U);
  }
}

// A crossing closed for other trains is no confirmation for this one (its own requests may
// have been lost; the warning ends when those trains withdraw): a CLOSED report clears only
// if it lists this train, and a cleared crossing whose CLOSED report no longer lists the
// train is protected again (design §3 item 3; model mutant MUTANT_CLEAR_ON_ANY_CLOSED).
// @verifies REQ-LC-003
// @verifies REQ-LC-014
TEST(LcCrossingProtection, ClosedReportClearsOnlyATrainItLists) {
  CrossingProtection p = Requested();
  CrossingReport other = Rep(1, CrossingStatus::kClosed, -20'000, 10'000, false);
  other.requesters[0] = kTrain + 1;
  other.requester_count = 1;
  const std::array<CrossingReport, 1> for_other{{other}};
  ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), for_other)), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - params::lc::protection_offset_mm);

  CrossingReport both = other;
  both.requesters[1] = kTrain;
  both.requester_count = 2;
  const std::array<CrossingReport, 1> listed{{both}};
  ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), listed)), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);

  // the controller lost this train's request (e.g. a restart): CLOSED, listing only the other
  ASSERT_EQ(p.Cycle(WithReport(At(10'500, 610'000, 20'000), for_other)), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  EXPECT_EQ(p.Output().Requests().size(), 1U);  // the request is sent again
}

// A requester count above the report's capacity is read as the capacity (no read past it).
// @verifies REQ-LC-003
TEST(LcCrossingProtection, RequesterCountAboveCapacityIsBounded) {
  CrossingReport r = Rep(1, CrossingStatus::kClosed, 0, 0, false);
  r.requester_count = messages::kMaxReportRequesters + 5;
  EXPECT_FALSE(r.Lists(kTrain));
  r.requesters[messages::kMaxReportRequesters - 1] = kTrain;
  EXPECT_TRUE(r.Lists(kTrain));
}

// The most restrictive limit of the uncleared crossings is given.
// @verifies REQ-LC-003
TEST(LcCrossingProtection, MostRestrictiveProtectionLimit) {
  CrossingProtection p = Make();
  const std::array<CrossingData, 2> both{{kLc1, kLc2}};
  ASSERT_EQ(p.LoadCrossings(both), ProtectionError::kNone);
  const std::int64_t off = params::lc::protection_offset_mm;
  EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - off);  // given from the load on
  ASSERT_EQ(p.Cycle(At(10'000, 600'000, 20'000)), ProtectionError::kNone);
  EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - off);
  EXPECT_EQ(p.Output().limiting_crossing_id, 1U);
  const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, -20'000, 10'000)}};
  ASSERT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), closed)), ProtectionError::kNone);
  EXPECT_EQ(p.Output().stop_limit_mm, kLc2.near_mm - off);
  EXPECT_EQ(p.Output().limiting_crossing_id, 2U);
}

// ---- withdrawal (REQ-LC-004) -----------------------------------------------------------------

// Cleared crossing 1, the train running through it.
CrossingProtection Cleared() {
  CrossingProtection p = Requested();
  const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, -20'000, 10'000)}};
  EXPECT_EQ(p.Cycle(WithReport(At(10'000, 600'000, 20'000), closed)), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
  return p;
}

// rear_min = front - length - rear_error must reach far (1,006,000).
// @verifies REQ-LC-004
TEST(LcCrossingProtection, WithdrawalOnlyWhenTheRearPassedTheFarEdge) {
  CrossingProtection p = Cleared();
  // front beyond far, rear on the crossing: no withdrawal (not even with the front error)
  ProtectionInput in = At(40'000, 1'050'000, 20'000);
  in.front_error_mm = 1'000;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
  EXPECT_TRUE(p.Output().Withdrawals().empty());
  // rear_min = 1,106,000 - 100,000 - 1 = 1,005,999: one millimetre short
  in = At(41'000, 1'106'000, 20'000);
  in.rear_error_mm = 1;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
  EXPECT_TRUE(p.Output().Withdrawals().empty());
  EXPECT_EQ(p.Output().Requests().size(), 1U);
  // rear exactly at far: passed, withdrawal sent instead of the request
  in = At(42'000, 1'106'001, 20'000);
  in.rear_error_mm = 1;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kPassed);
  ASSERT_EQ(p.Output().Withdrawals().size(), 1U);
  EXPECT_EQ(p.Output().Withdrawals()[0], 1U);
  EXPECT_TRUE(p.Output().Requests().empty());
  EXPECT_FALSE(p.Output().stop_limit_mm.has_value());
}

// @verifies REQ-LC-004
TEST(LcCrossingProtection, WithdrawalRepeatedUntilAcknowledged) {
  CrossingProtection p = Cleared();
  ASSERT_EQ(p.Cycle(At(42'000, 1'200'000, 20'000)), ProtectionError::kNone);
  ASSERT_EQ(StateOf(p, 1), CrossingState::kPassed);
  ASSERT_EQ(p.Cycle(At(42'500, 1'210'000, 20'000)), ProtectionError::kNone);  // ack lost
  EXPECT_EQ(StateOf(p, 1), CrossingState::kPassed);
  EXPECT_EQ(p.Output().Withdrawals().size(), 1U);
  // acks of another train or another crossing do not count
  const std::array<WithdrawalAck, 2> other{{{1, kTrain + 1}, {9, kTrain}}};
  ProtectionInput in = At(43'000, 1'220'000, 20'000);
  in.acks = other;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kPassed);
  EXPECT_EQ(p.Output().ignored_messages, 2U);
  const std::array<WithdrawalAck, 1> ack{{{1, kTrain}}};
  in = At(43'500, 1'230'000, 20'000);
  in.acks = ack;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kDone);
  EXPECT_TRUE(p.Output().Withdrawals().empty());
  EXPECT_TRUE(p.Output().Requests().empty());
  p.DropDone();
  EXPECT_TRUE(p.Entries().empty());
}

// An acknowledgement arriving in the cycle of the passage is not for a withdrawal sent: the
// withdrawal is still sent once.
// @verifies REQ-LC-004
TEST(LcCrossingProtection, AckBeforeAnyWithdrawalIsNotTaken) {
  CrossingProtection p = Cleared();
  const std::array<WithdrawalAck, 1> ack{{{1, kTrain}}};
  ProtectionInput in = At(42'000, 1'200'000, 20'000);
  in.acks = ack;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kPassed);
  EXPECT_EQ(p.Output().Withdrawals().size(), 1U);
}

// ---- dwell-aware request (REQ-LC-005) ------------------------------------------------------

// Standing 100 m before the crossing at a stop, departure at t_dep = 100 s, accel 1 m/s^2:
// the run from rest takes 14,142 ms; the request comes when (t_dep - now) + 14,142 <= warning
// + lead, i.e. at now >= t_req = t_dep + 14,142 - (warning + lead); without dwell awareness
// (speed 0, never) it would never come, and a prediction ignoring the dwell (departing now)
// would request (t_dep - t_req) too early.
// @verifies REQ-LC-005
TEST(LcCrossingProtection, DwellAwareRequest) {
  constexpr std::int64_t kDep = 100'000;
  constexpr std::int64_t kRun = 14'142;
  constexpr std::int64_t kReq = kDep + kRun - (kW + kLead);
  static_assert(kReq > 0 && kReq < kDep);
  CrossingProtection p = Make(1'000);
  ASSERT_EQ(p.AddCrossing(kLc1), ProtectionError::kNone);
  ProtectionInput in = At(kReq - 1, 900'000, 0);
  in.dwell = true;
  in.departure_ms = kDep;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kDep - (kReq - 1) + kRun);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kApproaching);
  EXPECT_EQ(p.Output().stop_limit_mm, kLc1.near_mm - params::lc::protection_offset_mm);
  in.now_ms = kReq;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kW + kLead);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kRequested);
  // the clearance is judged against the dwell-aware ETA too: at now = t_dep + 14,142 - 30 s a
  // warning started then is exactly sufficient (ws + 30 s = now + ETA)
  constexpr std::int64_t kNow = kDep + kRun - kW;
  const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, kNow, kNow)}};
  in.now_ms = kNow;
  in.reports = closed;
  ASSERT_EQ(p.Cycle(in), ProtectionError::kNone);
  EXPECT_EQ(p.Find(1)->eta_ms, kDep - kNow + kRun);
  EXPECT_EQ(StateOf(p, 1), CrossingState::kCleared);
}

// ---- input errors, no heap, determinism ---------------------------------------------------

// @verifies REQ-LC-014
TEST(LcCrossingProtection, InvalidInputsRefuseTheCycleAndKeepProtecting) {
  CrossingProtection p = Requested(10'000);
  const auto before = p.Find(1)->state;
  EXPECT_EQ(p.Cycle(At(9'999, 600'000, 20'000)), ProtectionError::kTimeWentBack);
  EXPECT_EQ(p.Cycle(At(10'000, 600'000, -1)), ProtectionError::kSpeedInvalid);
  ProtectionInput in = At(10'000, 600'000, 20'000);
  in.front_error_mm = -1;
  EXPECT_EQ(p.Cycle(in), ProtectionError::kPositionInvalid);
  in = At(10'000, 600'000, 20'000);
  in.dwell = true;
  EXPECT_EQ(p.Cycle(in), ProtectionError::kDwellWhileMoving);
  in = At(kMaxClockMs + 1, 600'000, 20'000);
  EXPECT_EQ(p.Cycle(in), ProtectionError::kTimeInvalid);
  const std::array<RestrictionSegment, 1> bad{{{10, 5, 100}}};
  in = At(10'000, 600'000, 20'000);
  in.restrictions = bad;
  EXPECT_EQ(p.Cycle(in), ProtectionError::kProfileInvalid);
  std::vector<CrossingReport> flood(kMaxMessagesPerCycle + 1);
  in = At(10'000, 600'000, 20'000);
  in.reports = flood;
  EXPECT_EQ(p.Cycle(in), ProtectionError::kTooManyMessages);
  EXPECT_EQ(p.Find(1)->state, before);
  EXPECT_EQ(p.LastCycleMs(), 10'000);
  EXPECT_EQ(p.Output().Requests().size(), 1U);  // still requested and protected
  EXPECT_TRUE(p.Output().stop_limit_mm.has_value());
}

// A journey: approach, request, clearance, passage, withdrawal, done (two crossings).
std::vector<std::int64_t> Journey(CrossingProtection& p) {
  std::vector<std::int64_t> trace;
  const std::array<CrossingData, 2> both{{kLc1, kLc2}};
  EXPECT_EQ(p.LoadCrossings(both), ProtectionError::kNone);
  std::int64_t front = 0;
  std::int64_t v = 0;
  for (std::int64_t now = 0; now <= 200'000; now += 500) {
    std::array<CrossingReport, 2> reports{};
    std::size_t n = 0;
    for (const std::uint32_t id : p.Output().Requests()) {
      reports[n++] = Rep(id, CrossingStatus::kClosed, now - 40'000, now);
    }
    std::array<WithdrawalAck, 2> acks{};
    std::size_t m = 0;
    for (const std::uint32_t id : p.Output().Withdrawals()) {
      acks[m++] = WithdrawalAck{id, kTrain};
    }
    ProtectionInput in = At(now, front, v);
    in.front_error_mm = 50;
    in.rear_error_mm = 50;
    in.reports = std::span<const CrossingReport>(reports.data(), n);
    in.acks = std::span<const WithdrawalAck>(acks.data(), m);
    EXPECT_EQ(p.Cycle(in), ProtectionError::kNone);
    for (const CrossingEntry& e : p.Entries()) {
      trace.push_back(static_cast<std::int64_t>(e.state));
      trace.push_back(e.eta_ms);
    }
    trace.push_back(p.Output().stop_limit_mm.value_or(-1));
    front += v / 2;
    v = v + 250 > 30'000 ? 30'000 : v + 250;
  }
  return trace;
}

// @verifies REQ-LC-001
// @verifies REQ-LC-004
TEST(LcCrossingProtection, DeterministicJourneyEndsDone) {
  CrossingProtection a = Make(500);
  CrossingProtection b = Make(500);
  const std::vector<std::int64_t> ta = Journey(a);
  const std::vector<std::int64_t> tb = Journey(b);
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(StateOf(a, 1), CrossingState::kDone);
  EXPECT_EQ(StateOf(a, 2), CrossingState::kDone);
}

// @verifies REQ-LC-001
// @verifies REQ-LC-003
TEST(LcCrossingProtection, NoHeapInTheCycle) {
  CrossingProtection p = Make(500);
  const std::array<CrossingData, 2> both{{kLc1, kLc2}};
  ASSERT_EQ(p.LoadCrossings(both), ProtectionError::kNone);
  std::vector<RestrictionSegment> profile;
  for (std::int64_t i = 0; i < 200; ++i) {
    profile.push_back({i * 20'000, i * 20'000 + 10'000, 15'000 + (i % 4) * 5'000});
  }
  const std::array<CrossingReport, 1> closed{{Rep(1, CrossingStatus::kClosed, 0, 30'000)}};
  testing::StartCountingAllocations();
  std::int64_t sum = 0;
  for (std::int64_t k = 0; k < 100; ++k) {
    ProtectionInput in = At(30'000 + k * 100, 500'000 + k * 2'000, 20'000);
    in.restrictions = profile;
    in.reports = closed;
    sum += static_cast<std::int64_t>(p.Cycle(in));
    sum += p.Output().stop_limit_mm.value_or(0);
    sum += EarliestArrivalMs(0, 3'000'000, 10'000, 500, profile).eta_ms;
  }
  const std::size_t allocations = testing::StopCountingAllocations();
  EXPECT_EQ(allocations, 0U);
  EXPECT_NE(sum, 0);
}

}  // namespace
}  // namespace railproof::lc::onboard
