// Unit tests of the ground moving-block unit (spec/design/mb.md §2, §3) with
// hand-computed values in mm / ms. The model's behaviour at unit resolution is covered by
// the conformance vectors; these tests cover every obstruction kind and margin, ties,
// strict/non-strict edges, the time rules, the interlocking, possessions, restrictions,
// the initial position, the D2 policy, validation and the runtime rules.
//
// Kills the seeded faults FAULT_MB_NO_TRAIN_MARGIN, FAULT_MB_ABNORMAL_RELEASED,
// FAULT_MB_LOCK_IGNORES_AUTHORITY, FAULT_MB_TIMEOUT_INCLUSIVE, FAULT_MB_POSSESSION_NO_CONFIRM,
// FAULT_MB_OCCUPANCY_NO_CORRECTION (the unit_fault_<F> ctest entries run these tests against the schemata variant).
#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "railproof/testing/alloc_counter.hpp"
#include "ground_test_line.hpp"
#include "railproof/generated/mb_params.hpp"
#include "railproof/mb/wayside/ground.hpp"

namespace railproof::mb::wayside {
namespace {

using test::AbnormalOf;
using test::kBlock;
using test::kEot;
using test::kLen;
using test::kTrainLen;
using test::LimitAndKind;
using test::LimitAndKindOf;
using test::LimitOf;
using test::MakeGround;
using test::MakeReport;
using test::Register;
using test::Report;
using test::SmallCapacity;
using test::TestLine;

// ---- configuration ------------------------------------------------------------------------

// @verifies REQ-MB-020
// @verifies REQ-MB-006
TEST(WaysideGroundConfig, DefaultsComeFromTheParameters) {
  namespace p = params::mb;
  const LineConfig c = DefaultLineParameters();
  EXPECT_EQ(c.margins.preceding_train_mm, p::margin_preceding_train_mm);
  EXPECT_EQ(c.margins.fixed_block_mm, p::margin_fixed_block_mm);
  EXPECT_EQ(c.margins.route_end_mm, p::margin_route_end_mm);
  EXPECT_EQ(c.margins.handover_mm, p::margin_handover_mm);
  EXPECT_EQ(c.margins.system_boundary_mm, p::margin_system_boundary_mm);
  EXPECT_EQ(c.margins.possession_mm, p::margin_possession_mm);
  EXPECT_EQ(c.margins.abnormal_train_mm, p::margin_abnormal_train_mm);
  EXPECT_EQ(c.margins.end_of_track_mm, p::margin_end_of_track_mm);
  EXPECT_EQ(c.tracking_timeout_ms, p::tracking_timeout_ms);
  EXPECT_EQ(c.authority_validity_ms, p::authority_validity_ms);
  EXPECT_EQ(c.ground_cycle_ms, p::ground_cycle_ms);
  EXPECT_EQ(c.setback_max_mm, p::setback_max_mm);
  EXPECT_EQ(c.d2.rate_ppm, p::d2_rate_ppm);
  EXPECT_EQ(c.d2.tau_ms, p::d2_tau_ms);
  EXPECT_EQ(c.d2.resolution_mm, p::d2_resolution_mm);
  const Capacity cap = DefaultCapacity();
  EXPECT_EQ(static_cast<std::int64_t>(cap.trains), p::max_trains);
  EXPECT_EQ(static_cast<std::int64_t>(cap.blocks), p::max_blocks);
  EXPECT_EQ(static_cast<std::int64_t>(cap.history_per_train), p::authority_validity_ms / p::ground_cycle_ms + 2);
}

struct BadConfigCase {
  const char* name;
  std::function<void(TestLine&, Capacity&)> mutate;
  ConfigError error;
  std::size_t entry;
};

// @verifies REQ-MB-020
// @verifies REQ-MB-021
TEST(WaysideGroundConfig, RejectsBadLineDataNamingTheEntry) {
  const std::vector<BadConfigCase> cases = {
      {"length 0", [](TestLine& l, Capacity&) { l.base.length_mm = 0; }, ConfigError::kLineLengthInvalid, 0},
      {"one boundary", [](TestLine& l, Capacity&) { l.blocks = {0}; }, ConfigError::kTooFewBlocks, 0},
      {"too many blocks", [](TestLine&, Capacity& c) { c.blocks = 39; }, ConfigError::kTooManyBlocks, 0},
      {"not from zero", [](TestLine& l, Capacity&) { l.blocks[0] = 1; }, ConfigError::kBlocksNotFromZero, 0},
      {"unsorted blocks", [](TestLine& l, Capacity&) { l.blocks[5] = l.blocks[4]; },
       ConfigError::kBlocksNotIncreasing, 5},
      {"blocks short of the end", [](TestLine& l, Capacity&) { l.blocks.pop_back(); },
       ConfigError::kBlocksNotToLineEnd, 39},
      {"too many no-stop sections",
       [](TestLine& l, Capacity& c) {
         c.sections = 1;
         l.no_stop = {{0, 10}, {20, 30}};
       },
       ConfigError::kTooManySections, 2},
      {"fixed blocks overlap", [](TestLine& l, Capacity&) { l.fixed = {{0, 100}, {99, 200}}; },
       ConfigError::kFixedBlockInvalid, 1},
      {"empty set-back section", [](TestLine& l, Capacity&) { l.setback = {{100, 100}}; },
       ConfigError::kSetBackSectionInvalid, 0},
      {"no-stop section off the line", [](TestLine& l, Capacity&) { l.no_stop = {{0, 10}, {kLen - 5, kLen + 1}}; },
       ConfigError::kNoStopSectionInvalid, 1},
      {"too many points", [](TestLine& l, Capacity& c) { c.points = 0; l.WithJunction(); },
       ConfigError::kTooManyPoints, 0},
      {"duplicate points", [](TestLine& l, Capacity&) {
         l.WithJunction();
         l.points.push_back(PointsConfig{10, Section{0, kBlock}});
       },
       ConfigError::kPointsIdDuplicate, 1},
      {"points without a block", [](TestLine& l, Capacity&) { l.points = {{1, {1'000, kBlock}}}; },
       ConfigError::kPointsNotOnBlockBoundaries, 0},
      {"points off the line", [](TestLine& l, Capacity&) { l.points = {{1, {kLen, kLen + kBlock}}}; },
       ConfigError::kPointsSectionInvalid, 0},
      {"route to unknown points", [](TestLine& l, Capacity&) {
         l.WithJunction();
         l.routes[1].points_index = 1;
       },
       ConfigError::kRouteUnknownPoints, 1},
      {"duplicate route id", [](TestLine& l, Capacity&) {
         l.WithJunction();
         l.routes[1].id = 1;
       },
       ConfigError::kRouteIdDuplicate, 1},
      {"empty route", [](TestLine& l, Capacity&) {
         l.WithJunction();
         l.routes[0].exit_mm = l.routes[0].entry_mm;
       },
       ConfigError::kRouteInvalid, 0},
      {"too many routes", [](TestLine& l, Capacity& c) {
         l.WithJunction();
         c.routes = 1;
       },
       ConfigError::kTooManyRoutes, 0},
      {"handovers unsorted", [](TestLine& l, Capacity&) { l.handovers = {{1, 800'000}, {2, 700'000}}; },
       ConfigError::kHandoverInvalid, 1},
      {"duplicate handover", [](TestLine& l, Capacity&) { l.handovers = {{1, 700'000}, {1, 800'000}}; },
       ConfigError::kHandoverIdDuplicate, 1},
      {"boundary off the line", [](TestLine& l, Capacity&) { l.boundary = kLen + 1; },
       ConfigError::kSystemBoundaryInvalid, 0},
      {"negative possession margin", [](TestLine& l, Capacity&) { l.base.margins.possession_mm = -1; },
       ConfigError::kMarginInvalid, 5},
      {"bad policy", [](TestLine& l, Capacity&) { l.base.policy = static_cast<MarginPolicy>(9); },
       ConfigError::kPolicyInvalid, 0},
      {"negative tau", [](TestLine& l, Capacity&) { l.base.d2.tau_ms = -1; }, ConfigError::kD2ParamsInvalid, 1},
      {"zero validity", [](TestLine& l, Capacity&) { l.base.authority_validity_ms = 0; }, ConfigError::kTimeInvalid,
       1},
      {"negative set-back", [](TestLine& l, Capacity&) { l.base.setback_max_mm = -1; },
       ConfigError::kSetBackMaxInvalid, 0},
      {"no trains", [](TestLine&, Capacity& c) { c.trains = 0; }, ConfigError::kCapacityInvalid, 0},
      {"history too small", [](TestLine&, Capacity& c) { c.history_per_train = 7; }, ConfigError::kHistoryTooSmall,
       0},
  };
  for (const auto& k : cases) {
    TestLine line;
    Capacity cap = SmallCapacity();
    k.mutate(line, cap);
    const auto created = Ground::Create(line.Config(), cap);
    EXPECT_EQ(created.error, k.error) << k.name << ": " << ToString(created.error);
    EXPECT_EQ(created.entry, k.entry) << k.name;
    EXPECT_EQ(created.ground, nullptr) << k.name;
  }
  // The minimum history (validity / cycle + 2 = 8) is accepted.
  Capacity cap = SmallCapacity();
  cap.history_per_train = 8;
  EXPECT_EQ(Ground::Create(TestLine().Config(), cap).error, ConfigError::kNone);
  EXPECT_EQ(Ground::Create(TestLine().Config(), cap, -1).error, ConfigError::kTimeInvalid);
}

// @verifies REQ-MB-021
TEST(WaysideGroundConfig, RuntimeCapacitiesGiveTypedRejections) {
  TestLine line;
  Capacity cap = SmallCapacity();
  cap.trains = 2;
  cap.possessions = 1;
  cap.restrictions = 1;
  cap.unequipped = 1;
  auto g = MakeGround(line, cap);
  EXPECT_EQ(Register(*g, 1, 200'000), RegisterStatus::kRegistered);
  EXPECT_EQ(Register(*g, 2, 400'000), RegisterStatus::kRegistered);
  EXPECT_EQ(Register(*g, 3, 600'000), RegisterStatus::kCapacityExceeded);
  EXPECT_EQ(g->RequestPossession({1'200'000, 1'300'000}).status, CommandStatus::kAccepted);
  EXPECT_EQ(g->RequestPossession({1'400'000, 1'500'000}).status, CommandStatus::kCapacityExceeded);
  EXPECT_EQ(g->RequestSpeedRestriction({0, 100'000}, 10'000).status, CommandStatus::kAccepted);
  EXPECT_EQ(g->RequestSpeedRestriction({0, 100'000}, 10'000).status, CommandStatus::kCapacityExceeded);
  EXPECT_EQ(g->ReportUnequippedOccupancy({1'500'000, 1'600'000}).status, CommandStatus::kAccepted);
  EXPECT_EQ(g->ReportUnequippedOccupancy({1'700'000, 1'800'000}).status, CommandStatus::kCapacityExceeded);
  // a removed train frees its slot
  EXPECT_EQ(g->RemoveTrain(1), CommandStatus::kAccepted);
  EXPECT_EQ(g->RemoveTrain(1), CommandStatus::kUnknownTrain);
  EXPECT_EQ(Register(*g, 3, 600'000), RegisterStatus::kRegistered);
  EXPECT_EQ(g->TrainCount(), 2U);
  EXPECT_EQ(g->TrainAt(0).train_id, 2U);  // registration order
  EXPECT_EQ(g->TrainAt(1).train_id, 3U);
}

// ---- position reports (REQ-MB-001, REQ-MB-005) ----------------------------------------------

// @verifies REQ-MB-001
TEST(WaysideGroundReport, RejectsWithTypedReasonInOrder) {
  auto g = MakeGround(TestLine(), {{1, 550'000}});
  const PositionReport good = MakeReport(*g, 1, 560'000);
  EXPECT_EQ(good.front_block, 11U);
  EXPECT_EQ(good.offset_mm, 10'000);

  auto with = [&](auto mutate) {
    PositionReport r = good;
    mutate(r);
    return g->OnReport(r);
  };
  EXPECT_EQ(with([](PositionReport& r) { r.train_id = 99; }), ReportStatus::kUnknownTrain);
  EXPECT_EQ(with([](PositionReport& r) { r.front_block = 40; }), ReportStatus::kBlockOutOfRange);
  EXPECT_EQ(with([](PositionReport& r) { r.offset_mm = -1; }), ReportStatus::kOffsetOutOfBlock);
  EXPECT_EQ(with([](PositionReport& r) { r.offset_mm = kBlock + 1; }), ReportStatus::kOffsetOutOfBlock);
  EXPECT_EQ(with([](PositionReport& r) { r.length_mm = kTrainLen - 1; }), ReportStatus::kLengthMismatch);
  EXPECT_EQ(with([](PositionReport& r) { r.correction_mm = -1; }), ReportStatus::kCorrectionOutOfRange);
  EXPECT_EQ(with([](PositionReport& r) { r.last_balise_mm = kLen + 1; }), ReportStatus::kBaliseOffLine);
  EXPECT_EQ(with([](PositionReport& r) { r.speed_mm_s = -1; }), ReportStatus::kSpeedOutOfRange);
  EXPECT_EQ(with([](PositionReport& r) { r.speed_mm_s = kMaxSpeedMmS + 1; }), ReportStatus::kSpeedOutOfRange);
  EXPECT_EQ(with([](PositionReport& r) { r.direction = Direction::kReverse; }), ReportStatus::kWrongDirection);
  // the first failing check is reported
  EXPECT_EQ(with([](PositionReport& r) {
              r.length_mm = 1;
              r.direction = Direction::kReverse;
            }),
            ReportStatus::kLengthMismatch);
  // nothing changed so far
  EXPECT_EQ(g->Extended(1)->end_mm, 550'000);
  // a front at the end of a block may be given as offset == block length
  EXPECT_EQ(with([](PositionReport& r) {
              r.front_block = 11;
              r.offset_mm = kBlock;
            }),
            ReportStatus::kAccepted);
  EXPECT_EQ(g->Extended(1)->end_mm, 600'000);
}

// @verifies REQ-MB-005
TEST(WaysideGroundReport, BackwardMovementOnlyInsideSetBackSectionAndBounded) {
  TestLine line;
  line.setback = {{500'000, 600'000}};
  auto g = MakeGround(line, {{1, 550'000}});
  EXPECT_EQ(Report(*g, 1, 549'000), ReportStatus::kAccepted);
  EXPECT_EQ(Report(*g, 1, 546'000), ReportStatus::kSetBackTooFar);  // 4000 > 3000 behind 550000
  EXPECT_EQ(Report(*g, 1, 547'000), ReportStatus::kAccepted);       // exactly 3000
  EXPECT_EQ(Report(*g, 1, 548'000), ReportStatus::kAccepted);       // forward
  EXPECT_EQ(Report(*g, 1, 547'000), ReportStatus::kAccepted);
  // the reference is the furthest front reached: repeated set-backs do not add up
  EXPECT_EQ(Report(*g, 1, 546'999), ReportStatus::kSetBackTooFar);
  EXPECT_EQ(g->Extended(1)->end_mm, 547'000);

  ASSERT_EQ(g->RemoveTrain(1), CommandStatus::kAccepted);

  // outside a set-back section
  ASSERT_EQ(Register(*g, 2, 300'000), RegisterStatus::kRegistered);
  EXPECT_EQ(Report(*g, 2, 299'999), ReportStatus::kBackwardMovement);
  // the front must stay inside (begin < front): front == begin is outside
  ASSERT_EQ(Register(*g, 3, 502'000), RegisterStatus::kRegistered);
  EXPECT_EQ(Report(*g, 3, 500'000), ReportStatus::kBackwardMovement);
  EXPECT_EQ(Report(*g, 3, 500'001), ReportStatus::kAccepted);
  ASSERT_EQ(g->RemoveTrain(3), CommandStatus::kAccepted);
  // front == end is inside; a furthest front beyond the end is not
  ASSERT_EQ(Register(*g, 4, 600'000), RegisterStatus::kRegistered);
  EXPECT_EQ(Report(*g, 4, 599'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->RemoveTrain(4), CommandStatus::kAccepted);
  ASSERT_EQ(Register(*g, 5, 600'001), RegisterStatus::kRegistered);
  EXPECT_EQ(Report(*g, 5, 600'000), ReportStatus::kBackwardMovement);
}

// @verifies REQ-MB-001
// @verifies REQ-MB-004
TEST(WaysideGroundReport, StampedWithTheLastCycleTime) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(g->LastCycleMs(), 500);
  ASSERT_EQ(Report(*g, 1, 510'000), ReportStatus::kAccepted);  // arrives at, say, 990 ms: stamped 500
  ASSERT_EQ(g->Cycle(3500), CycleStatus::kDone);               // 3000 after the stamp
  EXPECT_FALSE(AbnormalOf(*g, 1));
  ASSERT_EQ(g->Cycle(3501), CycleStatus::kDone);
  EXPECT_TRUE(AbnormalOf(*g, 1));
}

// @verifies REQ-MB-004
TEST(WaysideGroundReport, ValidReportOfAbnormalTrainRestoresTracking) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  ASSERT_EQ(g->Cycle(3001), CycleStatus::kDone);
  ASSERT_TRUE(AbnormalOf(*g, 1));
  EXPECT_TRUE(g->Telegrams().empty());
  // a rejected report does not restore it
  EXPECT_EQ(Report(*g, 1, 400'000), ReportStatus::kBackwardMovement);
  ASSERT_EQ(g->Cycle(3500), CycleStatus::kDone);
  EXPECT_TRUE(AbnormalOf(*g, 1));
  EXPECT_EQ(Report(*g, 1, 520'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(4000), CycleStatus::kDone);
  EXPECT_FALSE(AbnormalOf(*g, 1));
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  EXPECT_EQ(g->Telegrams().size(), 1U);
}

// ---- stop limits: each obstruction kind and its margin (REQ-MB-006) ---------------------------

// @verifies REQ-MB-006
// @verifies REQ-MB-023
TEST(WaysideGroundLimit, EndOfTrackMinusItsMargin) {
  auto g = MakeGround(TestLine(), {{1, 100'000}});
  EXPECT_FALSE(LimitOf(*g, 1).has_value());  // nothing issued before the first cycle
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'990'000, Obstruction::kEndOfTrack}));
}

// @verifies REQ-MB-006
// @verifies REQ-MB-007
// @verifies REQ-MB-003
// @verifies REQ-MB-018
TEST(WaysideGroundLimit, PrecedingTrainExtendedRearMinusTrainMargin) {
  auto g = MakeGround(TestLine());
  ASSERT_EQ(Register(*g, 1, 1'000'000, 1'000), RegisterStatus::kRegistered);
  ASSERT_EQ(Register(*g, 2, 500'000), RegisterStatus::kRegistered);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  // 1000000 - 100000 - 1000 - 20000
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{879'000, Obstruction::kPrecedingTrain}));
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  ASSERT_EQ(Report(*g, 1, 1'100'000, 2'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 2), 978'000);  // 1100000 - 100000 - 2000 - 20000
}

// @verifies REQ-MB-004
// @verifies REQ-MB-006
TEST(WaysideGroundLimit, AbnormalTrainLastKnownRearMinusAbnormalMargin) {
  auto g = MakeGround(TestLine(), {{1, 1'000'000}, {2, 500'000}});
  for (std::int64_t now = 500; now <= 3000; now += 500) {
    ASSERT_EQ(g->Cycle(now), CycleStatus::kDone);
    ASSERT_EQ(Report(*g, 2, 500'000), ReportStatus::kAccepted);
    EXPECT_FALSE(AbnormalOf(*g, 1)) << now;
    EXPECT_EQ(LimitOf(*g, 2), 880'000) << now;  // 900000 - 20000
  }
  ASSERT_EQ(g->Cycle(3500), CycleStatus::kDone);
  ASSERT_TRUE(AbnormalOf(*g, 1));
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{860'000, Obstruction::kAbnormalTrain}));  // 900000 - 40000
  // the abnormal train shows its frozen bound, kind NONE, and gets no telegram
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{kEot, Obstruction::kNone}));
  ASSERT_EQ(g->Telegrams().size(), 1U);
  EXPECT_EQ(g->Telegrams()[0].train_id, 2U);
}

// @verifies REQ-MB-006
TEST(WaysideGroundLimit, FixedBlockOccupiedByAnotherTrain) {
  TestLine line;
  line.fixed = {{500'000, 600'000}};
  auto g = MakeGround(line);
  ASSERT_EQ(Register(*g, 1, 680'000), RegisterStatus::kRegistered);  // [580000, 680000) in the platform
  ASSERT_EQ(Register(*g, 2, 300'000), RegisterStatus::kRegistered);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  // 500000 - 21000 < 580000 - 20000
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{479'000, Obstruction::kFixedBlock}));
  // front exactly at the block's begin: still applies (front <= begin), limit behind the
  // front (never clamped)
  ASSERT_EQ(Report(*g, 2, 500'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{479'000, Obstruction::kFixedBlock}));
  // one millimetre further: the train is in the block itself, only the train ahead counts
  ASSERT_EQ(Report(*g, 2, 500'001), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{560'000, Obstruction::kPrecedingTrain}));
  // once the leader has left the block (rear 600000 == end, half-open), it is free
  ASSERT_EQ(Report(*g, 1, 700'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->RemoveTrain(2), CommandStatus::kAccepted);
  ASSERT_EQ(Register(*g, 2, 300'000), RegisterStatus::kRegistered);
  ASSERT_EQ(g->Cycle(2000), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{580'000, Obstruction::kPrecedingTrain}));
}

// @verifies REQ-MB-006
TEST(WaysideGroundLimit, OwnOccupationOfAFixedBlockIsNoObstruction) {
  TestLine line;
  line.fixed = {{500'000, 600'000}, {700'000, 800'000}};
  auto g = MakeGround(line);
  // [399000, 501000): overlaps the first platform by its correction only
  ASSERT_EQ(Register(*g, 1, 500'000, 1'000), RegisterStatus::kRegistered);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  // an unequipped occupancy in the second platform: that one obstructs (occupied by another)
  ASSERT_EQ(g->ReportUnequippedOccupancy({790'000, 800'000}).status, CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  // 700000 - 21000 < 790000 - 40000
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{679'000, Obstruction::kFixedBlock}));
}

// @verifies REQ-MB-006
// @verifies REQ-MB-013
TEST(WaysideGroundLimit, EntranceOfUnsetAutomaticRoute) {
  TestLine line;
  line.WithJunction();
  auto g = MakeGround(line, {{1, 500'000}});
  ASSERT_EQ(g->RequestRoute(2), CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_TRUE(g->RouteSet(2));
  EXPECT_FALSE(g->RouteSet(1));
  EXPECT_TRUE(g->PointsReverse(0));
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{970'000, Obstruction::kRouteEnd}));  // 1000000 - 30000
  // protected 970000 == siding begin - margin: not in use (strict), so it is released
  EXPECT_EQ(g->FreeRoute(2), CommandStatus::kAccepted);
  EXPECT_FALSE(g->RouteSet(2));
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_TRUE(g->RouteSet(1));  // automatic: set again
  EXPECT_FALSE(g->PointsReverse(0));
  EXPECT_EQ(LimitOf(*g, 1), kEot);
}

// @verifies REQ-MB-017
TEST(WaysideGroundLimit, UnsecuredHandoverPointPerTrain) {
  TestLine line;
  line.handovers = {{7, 800'000}};
  auto g = MakeGround(line, {{1, 500'000}, {2, 300'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{778'000, Obstruction::kHandover}));  // 800000 - 22000
  EXPECT_EQ(LimitOf(*g, 2), 380'000);
  EXPECT_EQ(g->SecureHandover(1, 7), CommandStatus::kAccepted);
  EXPECT_EQ(g->SecureHandover(9, 7), CommandStatus::kUnknownTrain);
  EXPECT_EQ(g->SecureHandover(1, 8), CommandStatus::kUnknownHandover);
  EXPECT_TRUE(g->HandoverSecured(1, 7));
  EXPECT_FALSE(g->HandoverSecured(2, 7));
  ASSERT_EQ(Report(*g, 1, 900'000), ReportStatus::kAccepted);
  ASSERT_EQ(Report(*g, 2, 700'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  // not secured for train 2 (780000 from train 1)
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{778'000, Obstruction::kHandover}));
  // front exactly at the handover point: applies; one millimetre past it: not
  ASSERT_EQ(Report(*g, 2, 800'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 2), 778'000);
  ASSERT_EQ(Report(*g, 2, 800'001), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(2000), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{780'000, Obstruction::kPrecedingTrain}));
}

// @verifies REQ-MB-023
TEST(WaysideGroundLimit, SystemBoundaryUntilAccepted) {
  TestLine line;
  line.boundary = 1'900'000;
  auto g = MakeGround(line, {{1, 1'500'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'877'000, Obstruction::kSystemBoundary}));  // 1900000 - 23000
  EXPECT_EQ(g->AcceptAtBoundary(true), CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  EXPECT_EQ(g->AcceptAtBoundary(false), CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), 1'877'000);
  // no boundary configured
  auto plain = MakeGround(TestLine());
  EXPECT_EQ(plain->AcceptAtBoundary(true), CommandStatus::kNoSystemBoundary);
}

// @verifies REQ-MB-014
TEST(WaysideGroundLimit, PossessionStartFromTheRequestOn) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  const CommandResult p = g->RequestPossession({1'200'000, 1'300'000});
  ASSERT_EQ(p.status, CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'150'000, Obstruction::kPossession}));  // 1200000 - 50000
  EXPECT_EQ(g->Possession(p.id), PossessionState::kActive);  // nothing in use at the first cycle
  EXPECT_EQ(g->CancelPossession(p.id), CommandStatus::kAccepted);
  EXPECT_EQ(g->CancelPossession(p.id), CommandStatus::kUnknownId);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kNone);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
}

// @verifies REQ-MB-016
TEST(WaysideGroundLimit, UnequippedOccupancyProtectsOtherTrains) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  const CommandResult u = g->ReportUnequippedOccupancy({1'200'000, 1'300'000});
  ASSERT_EQ(u.status, CommandStatus::kAccepted);
  EXPECT_EQ(g->ReportUnequippedOccupancy({1'300'000, 1'300'000}).status, CommandStatus::kInvalidRange);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'160'000, Obstruction::kAbnormalTrain}));  // 1200000 - 40000
  EXPECT_FALSE(g->BlockOccupied(23));
  EXPECT_TRUE(g->BlockOccupied(24));
  EXPECT_TRUE(g->BlockOccupied(25));
  EXPECT_FALSE(g->BlockOccupied(26));
  EXPECT_EQ(g->ClearUnequippedOccupancy(u.id), CommandStatus::kAccepted);
  EXPECT_EQ(g->ClearUnequippedOccupancy(u.id), CommandStatus::kUnknownId);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  EXPECT_FALSE(g->BlockOccupied(24));
}

// ---- tie-breaking and edges ------------------------------------------------------------------

// @verifies REQ-MB-006
TEST(WaysideGroundLimit, TieKeepsTheKindConsideredFirst) {
  {  // PRECEDING_TRAIN (1) vs HANDOVER (5): 898000 - 100000 - 20000 == 800000 - 22000
    TestLine line;
    line.handovers = {{7, 800'000}};
    auto g = MakeGround(line, {{1, 898'000}, {2, 500'000}});
    ASSERT_EQ(g->SecureHandover(1, 7), CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{778'000, Obstruction::kPrecedingTrain}));
  }
  {  // END_OF_TRACK (initial) vs POSSESSION (7): 2000000 - 100000 == 1950000 - 50000
    TestLine line;
    line.base.margins.end_of_track_mm = 100'000;
    auto g = MakeGround(line, {{1, 500'000}});
    ASSERT_EQ(g->RequestPossession({1'950'000, 2'000'000}).status, CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'900'000, Obstruction::kEndOfTrack}));
  }
  {  // ROUTE_END (4) vs HANDOVER (5): 1000000 - 30000 == 992000 - 22000
    TestLine line;
    line.WithJunction();
    line.handovers = {{7, 992'000}};
    auto g = MakeGround(line, {{1, 500'000}});
    ASSERT_EQ(g->RequestRoute(2), CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{970'000, Obstruction::kRouteEnd}));
  }
  {  // POSSESSION (7) vs unequipped ABNORMAL_TRAIN (8): 1200000 - 50000 == 1190000 - 40000
    auto g = MakeGround(TestLine(), {{1, 500'000}});
    ASSERT_EQ(g->ReportUnequippedOccupancy({1'190'000, 1'195'000}).status, CommandStatus::kAccepted);
    ASSERT_EQ(g->RequestPossession({1'200'000, 1'300'000}).status, CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{1'150'000, Obstruction::kPossession}));
  }
  {  // ABNORMAL_TRAIN (2) vs FIXED_BLOCK (3): 1119000 - 100000 - 40000 == 1000000 - 21000
    TestLine line;
    line.fixed = {{1'000'000, 1'100'000}};
    auto g = MakeGround(line, {{1, 1'119'000}, {2, 500'000}});
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    ASSERT_EQ(Report(*g, 2, 500'000), ReportStatus::kAccepted);
    ASSERT_EQ(g->Cycle(3001), CycleStatus::kDone);
    ASSERT_TRUE(AbnormalOf(*g, 1));
    EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{979'000, Obstruction::kAbnormalTrain}));
  }
}

// @verifies REQ-MB-006
// @verifies REQ-MB-008
TEST(WaysideGroundLimit, OnlyTrainsWithAFrontStrictlyAheadObstruct) {
  auto g = MakeGround(TestLine(), {{1, 300'000}, {2, 500'000}, {3, 700'001}});
  ASSERT_EQ(Report(*g, 1, 500'000), ReportStatus::kAccepted);  // equal fronts (ranges overlap)
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), 580'001);  // train 3 only: 700001 - 100000 - 20000
  EXPECT_EQ(LimitOf(*g, 2), 580'001);
  EXPECT_EQ(LimitOf(*g, 3), kEot);
}

// @verifies REQ-MB-022
TEST(WaysideGroundLimit, NoStopSectionPullsTheLimitBackWithTheKindsMargin) {
  struct Case {
    std::int64_t possession_begin;
    std::int64_t expected;
  };
  // no-stop [1400000, 1460000) and [1500000, 1550000); possession margin 50000
  const Case cases[] = {
      {1'580'000, 1'350'000},  // 1530000 inside -> 1450000 inside the first -> 1350000
      {1'550'000, 1'350'000},  // 1500000 == begin: inside (half-open)
      {1'600'000, 1'550'000},  // 1550000 == end: outside, unchanged
      {1'520'000, 1'470'000},  // between the sections: unchanged
      {1'460'000, 1'350'000},  // 1410000 inside the first
  };
  for (const Case& c : cases) {
    TestLine line;
    line.no_stop = {{1'400'000, 1'460'000}, {1'500'000, 1'550'000}};
    auto g = MakeGround(line, {{1, 500'000}});
    ASSERT_EQ(g->RequestPossession({c.possession_begin, c.possession_begin + 10'000}).status,
              CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{c.expected, Obstruction::kPossession})) << c.possession_begin;
  }
}

// @verifies REQ-MB-024
// @verifies REQ-MB-015
TEST(WaysideGroundLimit, TelegramToEveryTrackedTrainEveryCycle) {
  auto g = MakeGround(TestLine(), {{5, 1'000'000}, {3, 500'000}});
  for (std::int64_t now = 500; now <= 1500; now += 500) {
    ASSERT_EQ(g->Cycle(now), CycleStatus::kDone);
    ASSERT_EQ(Report(*g, 5, 1'000'000), ReportStatus::kAccepted);
    ASSERT_EQ(Report(*g, 3, 500'000), ReportStatus::kAccepted);
    const auto telegrams = g->Telegrams();
    ASSERT_EQ(telegrams.size(), 2U);
    EXPECT_EQ(telegrams[0].train_id, 5U);  // registration order
    EXPECT_EQ(telegrams[0].limit_mm, kEot);
    EXPECT_EQ(telegrams[0].kind, Obstruction::kEndOfTrack);
    EXPECT_EQ(telegrams[0].issue_time_ms, now);
    EXPECT_EQ(telegrams[1].train_id, 3U);
    EXPECT_EQ(telegrams[1].limit_mm, 880'000);
    EXPECT_EQ(telegrams[1].kind, Obstruction::kPrecedingTrain);
    EXPECT_EQ(telegrams[1].issue_time_ms, now);
    EXPECT_EQ(telegrams[1].restriction_count, 0U);
  }
}

// ---- tracking (REQ-MB-004, REQ-MB-009) ---------------------------------------------------

// @verifies REQ-MB-004
TEST(WaysideGroundTracking, TimeoutIsStrict) {
  auto g = MakeGround(TestLine());
  ASSERT_EQ(Register(*g, 1, 500'000), RegisterStatus::kRegistered);  // stamped 0
  ASSERT_EQ(g->Cycle(3000), CycleStatus::kDone);
  EXPECT_FALSE(AbnormalOf(*g, 1));  // exactly the timeout: still tracked
  EXPECT_EQ(g->Telegrams().size(), 1U);
  ASSERT_EQ(g->Cycle(3001), CycleStatus::kDone);
  EXPECT_TRUE(AbnormalOf(*g, 1));  // one millisecond more: abnormal
  EXPECT_TRUE(g->Telegrams().empty());
}

// @verifies REQ-MB-004
// @verifies REQ-MB-009
// @verifies REQ-MB-014
TEST(WaysideGroundTracking, FrozenBoundIsTheLargestLimitStillValid) {
  auto g = MakeGround(TestLine(), {{1, 1'000'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  const CommandResult p = g->RequestPossession({1'200'000, 1'300'000});
  for (std::int64_t now = 1000; now <= 3000; now += 500) {
    ASSERT_EQ(g->Cycle(now), CycleStatus::kDone);
    EXPECT_EQ(LimitOf(*g, 1), 1'150'000);
    // the train may still use the 1990000 issued at 500: the possession is held
    EXPECT_EQ(g->Possession(p.id), PossessionState::kRequested) << now;
  }
  EXPECT_EQ(g->ProtectedAuthority(1), kEot);
  ASSERT_EQ(g->Cycle(3001), CycleStatus::kDone);
  ASSERT_TRUE(AbnormalOf(*g, 1));
  // frozen = protected = 1990000 (issued at 500, age 2501)
  EXPECT_EQ(LimitAndKindOf(*g, 1), (LimitAndKind{kEot, Obstruction::kNone}));
  const auto ext = g->Extended(1);
  ASSERT_TRUE(ext.has_value());
  EXPECT_EQ(ext->begin_mm, 900'000);
  EXPECT_EQ(ext->end_mm, kEot);  // max(frozen, front + correction)
  // the frozen bound stays (the history expires, the frozen bound does not)
  ASSERT_EQ(g->Cycle(10'000), CycleStatus::kDone);
  EXPECT_EQ(g->ProtectedAuthority(1), kEot);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kRequested);
  EXPECT_TRUE(g->BlockOccupied(39));
}

// @verifies REQ-MB-009
// @verifies REQ-MB-014
TEST(WaysideGroundTracking, IssuedLimitsExpireStrictlyAfterTheValidity) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);  // issues 1990000 at 500
  const CommandResult p = g->RequestPossession({1'200'000, 1'300'000});
  for (std::int64_t now = 1000; now <= 3500; now += 500) {
    ASSERT_EQ(g->Cycle(now), CycleStatus::kDone);
    ASSERT_EQ(Report(*g, 1, 500'000), ReportStatus::kAccepted);
    // 3500 - 500 == validity: the 1990000 is still protected
    EXPECT_EQ(g->Possession(p.id), PossessionState::kRequested) << now;
    EXPECT_EQ(g->ProtectedAuthority(1), kEot) << now;
  }
  ASSERT_EQ(g->Cycle(4000), CycleStatus::kDone);
  // dropped; protected 1150000 == begin - margin: not in use (strict)
  EXPECT_EQ(g->ProtectedAuthority(1), 1'150'000);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kActive);
}

// ---- occupancy (REQ-MB-010) -----------------------------------------------------------------

// @verifies REQ-MB-010
// @verifies REQ-MB-003
TEST(WaysideGroundOccupancy, BlocksOverlappedByTheExtendedRange) {
  auto g = MakeGround(TestLine());
  // [240000 - 100000 - 20000, 240000 + 20000) = [120000, 260000): blocks 2..5
  ASSERT_EQ(Register(*g, 1, 240'000, 20'000), RegisterStatus::kRegistered);
  // [110000, 250000) would end exactly on block 5's begin
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_FALSE(g->BlockOccupied(1));
  EXPECT_TRUE(g->BlockOccupied(2));
  EXPECT_TRUE(g->BlockOccupied(3));
  EXPECT_TRUE(g->BlockOccupied(4));
  EXPECT_TRUE(g->BlockOccupied(5));  // only through the correction
  EXPECT_FALSE(g->BlockOccupied(6));
  ASSERT_EQ(Report(*g, 1, 230'000, 20'000), ReportStatus::kBackwardMovement);
  ASSERT_EQ(g->RemoveTrain(1), CommandStatus::kAccepted);
  ASSERT_EQ(Register(*g, 2, 230'000, 20'000), RegisterStatus::kRegistered);  // [110000, 250000)
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_FALSE(g->BlockOccupied(1));
  EXPECT_TRUE(g->BlockOccupied(2));
  EXPECT_TRUE(g->BlockOccupied(4));
  EXPECT_FALSE(g->BlockOccupied(5));  // half-open: end 250000 does not enter block 5
  EXPECT_EQ(g->BlockCount(), 40U);
  EXPECT_FALSE(g->BlockOccupied(40));  // out of range: false
}

// ---- D2 safety buffers (REQ-MB-019) --------------------------------------------------------

// @verifies REQ-MB-019
// @verifies REQ-MB-002
TEST(WaysideGroundD2, BuffersRoundedUp) {
  TestLine line;
  line.base.policy = MarginPolicy::kD2Buffers;  // r = 1000 ppm, tau = 500 ms, l_c = 2000 mm
  auto g = MakeGround(line, {{1, 1'300'000}, {2, 500'000}});
  // x - x_m = 1234567 mm: r(x - x_m) = 1234.567 -> 1235; v tau = 22223 * 0.5 = 11111.5 -> 11112
  PositionReport r = MakeReport(*g, 1, 1'334'567);
  r.last_balise_mm = 100'000;
  r.speed_mm_s = 22'223;
  r.correction_mm = 1'000;  // below r(x - x_m): D2's rate governs
  ASSERT_EQ(g->OnReport(r), ReportStatus::kAccepted);
  auto ext = g->Extended(1);
  ASSERT_TRUE(ext.has_value());
  EXPECT_EQ(ext->begin_mm, 1'334'567 - 100'000 - (1235 + 2000));  // l_r = 3235
  EXPECT_EQ(ext->end_mm, 1'334'567 + (1235 + 11'112 + 2000));     // l_f = 14347
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 2), 1'231'332 - 20'000);
  // exact values: x - x_m = 1000000 -> 1000, v tau = 20000 * 0.5 = 10000
  r = MakeReport(*g, 1, 1'400'000);
  r.last_balise_mm = 400'000;
  r.speed_mm_s = 20'000;
  ASSERT_EQ(g->OnReport(r), ReportStatus::kAccepted);
  ext = g->Extended(1);
  EXPECT_EQ(ext->begin_mm, 1'400'000 - 100'000 - 3'000);
  EXPECT_EQ(ext->end_mm, 1'400'000 + 13'000);
  // one millimetre since the balise still counts one millimetre; at standstill no v tau
  r = MakeReport(*g, 1, 1'400'001);
  r.last_balise_mm = 1'400'000;
  r.speed_mm_s = 0;
  ASSERT_EQ(g->OnReport(r), ReportStatus::kAccepted);
  ext = g->Extended(1);
  EXPECT_EQ(ext->begin_mm, 1'400'001 - 100'000 - 2'001);
  EXPECT_EQ(ext->end_mm, 1'400'001 + 2'001);
  // the train's own bound above D2's rate (a compensating odometry): it governs both ends
  r = MakeReport(*g, 1, 1'400'010);
  r.last_balise_mm = 400'010;  // r(x - x_m) = 1000 mm
  r.speed_mm_s = 20'000;
  r.correction_mm = 7'500;
  ASSERT_EQ(g->OnReport(r), ReportStatus::kAccepted);
  ext = g->Extended(1);
  EXPECT_EQ(ext->begin_mm, 1'400'010 - 100'000 - (7'500 + 2'000));
  EXPECT_EQ(ext->end_mm, 1'400'010 + (7'500 + 10'000 + 2'000));
  // registration under D2: the uncertainty plus l_c at both ends
  ASSERT_EQ(Register(*g, 3, 200'000, 500), RegisterStatus::kRegistered);
  ext = g->Extended(3);
  EXPECT_EQ(ext->begin_mm, 200'000 - 100'000 - 2'500);
  EXPECT_EQ(ext->end_mm, 202'500);
}

// @verifies REQ-MB-002
// @verifies REQ-MB-003
TEST(WaysideGroundD2, ReportedCorrectionPolicyUsesTheReportedCorrection) {
  auto g = MakeGround(TestLine(), {{1, 1'300'000}});
  PositionReport r = MakeReport(*g, 1, 1'334'567, 1'234);
  r.last_balise_mm = 100'000;
  r.speed_mm_s = 22'223;
  ASSERT_EQ(g->OnReport(r), ReportStatus::kAccepted);
  const auto ext = g->Extended(1);
  EXPECT_EQ(ext->begin_mm, 1'334'567 - 100'000 - 1'234);
  EXPECT_EQ(ext->end_mm, 1'334'567 + 1'234);
  // the correction is reset at a balise: a smaller correction is accepted as reported
  ASSERT_EQ(Report(*g, 1, 1'340'000, 0), ReportStatus::kAccepted);
  EXPECT_EQ(g->Extended(1)->end_mm, 1'340'000);
}

// ---- interlocking (REQ-MB-011..013) --------------------------------------------------------

// @verifies REQ-MB-013
// @verifies REQ-MB-012
// @verifies REQ-MB-011
TEST(WaysideGroundInterlocking, ConflictingRequestWaitsWhileTheRouteIsInUse) {
  TestLine line;
  line.WithJunction();
  auto g = MakeGround(line, {{1, 500'000}});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_TRUE(g->RouteSet(1));  // automatic, nothing in use
  EXPECT_FALSE(g->PointsReverse(0));
  EXPECT_EQ(LimitOf(*g, 1), kEot);  // authority through the route
  ASSERT_EQ(g->RequestRoute(2), CommandStatus::kAccepted);
  EXPECT_TRUE(g->RouteRequested(2));
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  // the train may still use 1990000 > 1000000 - 30000: main stays set (approach locking),
  // the siding waits, the points do not move
  EXPECT_TRUE(g->RouteSet(1));
  EXPECT_FALSE(g->RouteSet(2));
  EXPECT_TRUE(g->RouteRequested(2));
  EXPECT_FALSE(g->PointsReverse(0));
  EXPECT_EQ(g->FreeRoute(1), CommandStatus::kRefusedInUse);
  EXPECT_TRUE(g->RouteSet(1));
  EXPECT_EQ(g->RequestRoute(3), CommandStatus::kUnknownRoute);
  EXPECT_EQ(g->FreeRoute(3), CommandStatus::kUnknownRoute);
  EXPECT_FALSE(g->RouteSet(3));
  // FreeRoute withdraws the pending request
  EXPECT_EQ(g->FreeRoute(2), CommandStatus::kAccepted);
  EXPECT_FALSE(g->RouteRequested(2));
}

// @verifies REQ-MB-013
TEST(WaysideGroundInterlocking, ApproachLockingEdgeIsStrict) {
  for (const std::int64_t begin : {std::int64_t{1'020'000}, std::int64_t{1'020'001}}) {
    TestLine line;
    line.WithJunction();
    auto g = MakeGround(line, {{1, 500'000}});
    ASSERT_EQ(g->RequestPossession({begin, begin + 10'000}).status, CommandStatus::kAccepted);
    ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
    ASSERT_TRUE(g->RouteSet(1));
    const std::int64_t limit = begin - 50'000;  // 970000 or 970001
    EXPECT_EQ(LimitOf(*g, 1), limit);
    // protected > 1000000 - 30000 ?
    EXPECT_EQ(g->FreeRoute(1), limit > 970'000 ? CommandStatus::kRefusedInUse : CommandStatus::kAccepted) << begin;
  }
}

// @verifies REQ-MB-011
TEST(WaysideGroundInterlocking, PointsMoveOnlyWhenTheirBlockIsFree) {
  TestLine line;
  line.WithJunction();
  auto g = MakeGround(line);
  ASSERT_EQ(Register(*g, 1, 1'040'000), RegisterStatus::kRegistered);  // [940000, 1040000) on the points
  ASSERT_EQ(g->RequestRoute(2), CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_FALSE(g->RouteSet(1));
  EXPECT_FALSE(g->RouteSet(2));
  EXPECT_FALSE(g->PointsReverse(0));
  EXPECT_TRUE(g->BlockOccupied(20));
  ASSERT_EQ(Report(*g, 1, 1'150'000), ReportStatus::kAccepted);  // rear 1050000: just off the points
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_TRUE(g->RouteSet(2));
  EXPECT_TRUE(g->PointsReverse(0));
  EXPECT_FALSE(g->RouteSet(1));
  EXPECT_FALSE(g->BlockOccupied(20));
}

// @verifies REQ-MB-011
// @verifies REQ-MB-016
TEST(WaysideGroundInterlocking, UnequippedOccupancyLocksThePoints) {
  TestLine line;
  line.WithJunction();
  auto g = MakeGround(line);
  const CommandResult u = g->ReportUnequippedOccupancy({1'010'000, 1'020'000});
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_FALSE(g->RouteSet(1));
  ASSERT_EQ(g->ClearUnequippedOccupancy(u.id), CommandStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_TRUE(g->RouteSet(1));
}

// ---- possessions (REQ-MB-014) --------------------------------------------------------------

// @verifies REQ-MB-014
TEST(WaysideGroundPossession, ActiveOnlyOnceFreeOfTrainsAndAuthority) {
  auto g = MakeGround(TestLine());
  ASSERT_EQ(Register(*g, 1, 1'250'000), RegisterStatus::kRegistered);  // inside the area
  ASSERT_EQ(Register(*g, 2, 500'000), RegisterStatus::kRegistered);
  const CommandResult p = g->RequestPossession({1'200'000, 1'300'000});
  ASSERT_EQ(p.status, CommandStatus::kAccepted);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kRequested);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kRequested);  // occupied: held
  // train 1's rear 1150000 - 20000 < 1200000 - 50000
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{1'130'000, Obstruction::kPrecedingTrain}));
  // train 1 leaves the area (rear 1300000 == end: half-open, free); train 2's authority
  // (1130000) ends before 1200000 - 50000: the possession is confirmed
  ASSERT_EQ(Report(*g, 1, 1'400'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kActive);
  EXPECT_EQ(LimitAndKindOf(*g, 2), (LimitAndKind{1'150'000, Obstruction::kPossession}));
  // active stays active; cancel removes the obstruction
  ASSERT_EQ(g->Cycle(1500), CycleStatus::kDone);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kActive);
  ASSERT_EQ(g->CancelPossession(p.id), CommandStatus::kAccepted);
  ASSERT_EQ(Report(*g, 2, 500'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(2000), CycleStatus::kDone);
  EXPECT_EQ(LimitOf(*g, 2), 1'280'000);
  EXPECT_EQ(g->Possession(p.id), PossessionState::kNone);
  EXPECT_EQ(g->Possession(12345), PossessionState::kNone);
}

// @verifies REQ-MB-014
TEST(WaysideGroundPossession, RejectsInvalidRanges) {
  auto g = MakeGround(TestLine());
  EXPECT_EQ(g->RequestPossession({100, 100}).status, CommandStatus::kInvalidRange);
  EXPECT_EQ(g->RequestPossession({-1, 100}).status, CommandStatus::kInvalidRange);
  EXPECT_EQ(g->RequestPossession({100, kLen + 1}).status, CommandStatus::kInvalidRange);
  const CommandResult a = g->RequestPossession({0, kLen});
  const CommandResult b = g->RequestPossession({0, kLen});
  EXPECT_EQ(a.status, CommandStatus::kAccepted);
  EXPECT_EQ(a.id, 1U);
  EXPECT_EQ(b.id, 2U);
}

// ---- temporary speed restrictions (REQ-MB-015) -------------------------------------------------

// @verifies REQ-MB-015
// @verifies REQ-MB-024
TEST(WaysideGroundRestriction, SentOnlyOnceConfirmedAndEveryCycleUntilTheRearHasLeft) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  const CommandResult r = g->RequestSpeedRestriction({600'000, 700'000}, 8'333);
  ASSERT_EQ(r.status, CommandStatus::kAccepted);
  EXPECT_EQ(g->RequestSpeedRestriction({600'000, 700'000}, 0).status, CommandStatus::kInvalidRange);
  EXPECT_EQ(g->RequestSpeedRestriction({700'000, 600'000}, 8'333).status, CommandStatus::kInvalidRange);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  ASSERT_EQ(g->Telegrams().size(), 1U);
  EXPECT_EQ(g->Telegrams()[0].restriction_count, 0U);  // entered, not confirmed
  EXPECT_FALSE(g->RestrictionConfirmed(r.id));
  EXPECT_EQ(g->ConfirmSpeedRestriction(r.id), CommandStatus::kAccepted);
  EXPECT_EQ(g->ConfirmSpeedRestriction(r.id), CommandStatus::kNotConfirmable);
  EXPECT_EQ(g->ConfirmSpeedRestriction(999), CommandStatus::kUnknownId);
  EXPECT_TRUE(g->RestrictionConfirmed(r.id));
  for (std::int64_t now = 1000; now <= 2000; now += 500) {  // re-sent every cycle
    ASSERT_EQ(g->Cycle(now), CycleStatus::kDone);
    const StopLimitTelegram& t = g->Telegrams()[0];
    ASSERT_EQ(t.restriction_count, 1U);
    EXPECT_EQ(t.restrictions[0].id, r.id);
    EXPECT_EQ(t.restrictions[0].begin_mm, 600'000);
    EXPECT_EQ(t.restrictions[0].end_mm, 700'000);
    EXPECT_EQ(t.restrictions[0].speed_mm_s, 8'333);
    EXPECT_FALSE(t.restrictions_truncated);
  }
  // rear 699999 < end: still sent; rear 700000 == end: left
  ASSERT_EQ(Report(*g, 1, 799'999), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(2500), CycleStatus::kDone);
  EXPECT_EQ(g->Telegrams()[0].restriction_count, 1U);
  ASSERT_EQ(Report(*g, 1, 800'000), ReportStatus::kAccepted);
  ASSERT_EQ(g->Cycle(3000), CycleStatus::kDone);
  EXPECT_EQ(g->Telegrams()[0].restriction_count, 0U);
  EXPECT_EQ(g->CancelSpeedRestriction(r.id), CommandStatus::kAccepted);
  EXPECT_EQ(g->CancelSpeedRestriction(r.id), CommandStatus::kUnknownId);
}

// @verifies REQ-MB-015
// @verifies REQ-MB-024
TEST(WaysideGroundRestriction, NearestFirstAndTruncatedAtTheTelegramMaximum) {
  auto g = MakeGround(TestLine(), {{1, 100'000}});
  std::vector<std::uint32_t> ids;
  for (std::int64_t k = 10; k > 0; --k) {  // entered furthest first
    const CommandResult r = g->RequestSpeedRestriction({k * 100'000, k * 100'000 + 50'000}, 10'000 + k);
    ASSERT_EQ(r.status, CommandStatus::kAccepted);
    ASSERT_EQ(g->ConfirmSpeedRestriction(r.id), CommandStatus::kAccepted);
  }
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  const StopLimitTelegram& t = g->Telegrams()[0];
  ASSERT_EQ(t.restriction_count, kTelegramRestrictionsMax);
  EXPECT_TRUE(t.restrictions_truncated);
  for (std::size_t i = 0; i < kTelegramRestrictionsMax; ++i) {
    EXPECT_EQ(t.restrictions[i].begin_mm, static_cast<std::int64_t>(i + 1) * 100'000);
  }
}

// ---- initial position (REQ-MB-016) -----------------------------------------------------------

// @verifies REQ-MB-016
TEST(WaysideGroundInitial, ProvisionalAndEntryBalisePositionsProtect) {
  auto g = MakeGround(TestLine());
  ASSERT_EQ(Register(*g, 1, 1'000'000, 5'000, InitialPosition::kStabledProvisional), RegisterStatus::kRegistered);
  ASSERT_EQ(Register(*g, 2, 200'000, 0, InitialPosition::kEntryBalise), RegisterStatus::kRegistered);
  ASSERT_EQ(g->Cycle(500), CycleStatus::kDone);
  EXPECT_TRUE(g->Train(1)->provisional);
  EXPECT_FALSE(g->Train(2)->provisional);
  EXPECT_EQ(LimitOf(*g, 2), 875'000);  // 1000000 - 100000 - 5000 - 20000
  EXPECT_EQ(LimitOf(*g, 1), kEot);
  ASSERT_EQ(Report(*g, 1, 1'000'000), ReportStatus::kAccepted);
  EXPECT_FALSE(g->Train(1)->provisional);
  EXPECT_FALSE(g->Train(99).has_value());
}

// @verifies REQ-MB-016
// @verifies REQ-MB-021
TEST(WaysideGroundInitial, RegistrationRejectsWithTypedReason) {
  TestLine line;
  auto g = MakeGround(line, {{1, 200'000}});
  EXPECT_EQ(Register(*g, 1, 400'000), RegisterStatus::kDuplicateId);
  EXPECT_EQ(Register(*g, 2, 400'000, 0, InitialPosition::kEntryBalise, 0), RegisterStatus::kLengthInvalid);
  EXPECT_EQ(Register(*g, 2, kLen + 1), RegisterStatus::kFrontOffLine);
  EXPECT_EQ(Register(*g, 2, -1), RegisterStatus::kFrontOffLine);
  EXPECT_EQ(Register(*g, 2, 400'000, -1), RegisterStatus::kCorrectionInvalid);
  EXPECT_EQ(Register(*g, 2, 400'000, 0, static_cast<InitialPosition>(7)), RegisterStatus::kInitialInvalid);
  EXPECT_EQ(g->TrainCount(), 1U);
  // [150000, 250000) overlaps train 1's [100000, 200000); touching (half-open) does not
  EXPECT_EQ(Register(*g, 4, 250'000), RegisterStatus::kPositionOccupied);
  EXPECT_EQ(Register(*g, 4, 300'000, 1), RegisterStatus::kPositionOccupied);  // by the correction
  EXPECT_EQ(Register(*g, 4, 300'000), RegisterStatus::kRegistered);
  ASSERT_EQ(g->ReportUnequippedOccupancy({500'000, 510'000}).status, CommandStatus::kAccepted);
  EXPECT_EQ(Register(*g, 5, 600'000), RegisterStatus::kPositionOccupied);
  EXPECT_EQ(Register(*g, 2, 0), RegisterStatus::kRegistered);  // at the very start of the line
  EXPECT_EQ(Register(*g, 3, kLen), RegisterStatus::kRegistered);
  EXPECT_EQ(g->LocateFront(0)->block, 0U);
  EXPECT_EQ(g->LocateFront(kLen)->block, 39U);
  EXPECT_EQ(g->LocateFront(kLen)->offset_mm, kBlock);
  EXPECT_EQ(g->LocateFront(kBlock)->block, 0U);
  EXPECT_EQ(g->LocateFront(kBlock + 1)->block, 1U);
  EXPECT_FALSE(g->LocateFront(kLen + 1).has_value());
}

// ---- runtime rules (REQ-MB-021) ------------------------------------------------------------

// Every kind of call after Create, with a junction, sections, handovers and a boundary.
void Exercise(Ground& g, std::uint32_t seed, std::vector<std::int64_t>* trace) {
  std::mt19937 engine(seed);
  const auto rng = [&engine]() { return static_cast<std::uint32_t>(engine()); };
  std::int64_t now = 0;
  std::int64_t fronts[6] = {100'000, 300'000, 550'000, 800'000, 1'100'000, 1'500'000};
  for (std::uint32_t i = 0; i < 6; ++i) {
    (void)Register(g, i + 1, fronts[i], 1'000, i % 2 == 0 ? InitialPosition::kEntryBalise
                                                          : InitialPosition::kStabledProvisional);
  }
  for (int step = 0; step < 200; ++step) {
    now += 500;
    const auto pick = static_cast<int>(rng() % 12);
    switch (pick) {
      case 0: (void)g.RequestRoute(1 + rng() % 2); break;
      case 1: (void)g.FreeRoute(1 + rng() % 2); break;
      case 2: (void)g.RequestPossession({1'700'000, 1'750'000}); break;
      case 3: (void)g.CancelPossession(1 + rng() % 4); break;
      case 4: (void)g.SecureHandover(1 + rng() % 6, 7); break;
      case 5: (void)g.AcceptAtBoundary(rng() % 2 == 0); break;
      case 6: {
        const CommandResult r = g.RequestSpeedRestriction({600'000, 650'000}, 5'000);
        (void)g.ConfirmSpeedRestriction(r.id);
        break;
      }
      case 7: (void)g.CancelSpeedRestriction(1 + rng() % 8); break;
      case 8: (void)g.ReportUnequippedOccupancy({1'850'000, 1'860'000}); break;
      case 9: (void)g.ClearUnequippedOccupancy(1 + rng() % 4); break;
      default: break;
    }
    for (std::uint32_t i = 0; i < 6; ++i) {
      if (rng() % 4 == 0) {
        continue;  // report lost
      }
      const auto limit = LimitOf(g, i + 1);
      const std::int64_t step_mm = static_cast<std::int64_t>(rng() % 20'000);
      if (limit.has_value() && fronts[i] + step_mm <= *limit) {
        fronts[i] += step_mm;
      }
      (void)Report(g, i + 1, fronts[i], static_cast<std::int64_t>(rng() % 3'000));
    }
    (void)g.Cycle(now);
    if (trace != nullptr) {
      for (std::size_t k = 0; k < g.TrainCount(); ++k) {
        const TrainOutput t = g.TrainAt(k);
        trace->push_back(t.train_id);
        trace->push_back(t.limit_mm.value_or(-1));
        trace->push_back(static_cast<std::int64_t>(t.kind));
        trace->push_back(t.abnormal ? 1 : 0);
        trace->push_back(g.ProtectedAuthority(t.train_id).value_or(-1));
      }
      for (const StopLimitTelegram& t : g.Telegrams()) {
        trace->push_back(t.issue_time_ms);
        trace->push_back(t.restriction_count);
      }
      trace->push_back(g.RouteSet(1) ? 1 : 0);
      trace->push_back(g.RouteSet(2) ? 1 : 0);
      trace->push_back(g.PointsReverse(0) ? 1 : 0);
      for (std::uint32_t p = 1; p <= 8; ++p) {
        trace->push_back(static_cast<std::int64_t>(g.Possession(p)));
      }
      for (std::size_t b = 0; b < g.BlockCount(); ++b) {
        trace->push_back(g.BlockOccupied(b) ? 1 : 0);
      }
    }
  }
}

TestLine FullLine() {
  TestLine line;
  line.WithJunction();
  line.fixed = {{500'000, 600'000}};
  line.setback = {{500'000, 600'000}};
  line.no_stop = {{1'300'000, 1'350'000}};
  line.handovers = {{7, 900'000}};
  line.boundary = 1'950'000;
  return line;
}

// @verifies REQ-MB-021
TEST(WaysideGroundRuntime, NoAllocationAfterCreate) {
  const TestLine line = FullLine();
  auto g = MakeGround(line);
  railproof::testing::StartCountingAllocations();
  Exercise(*g, 7, nullptr);
  const std::size_t allocations = railproof::testing::StopCountingAllocations();
  EXPECT_EQ(allocations, 0U);
  EXPECT_GT(g->TrainCount(), 0U);
  // the counter itself works
  railproof::testing::StartCountingAllocations();
  auto other = Ground::Create(line.Config(), SmallCapacity());
  EXPECT_GT(railproof::testing::StopCountingAllocations(), 0U);
}

// @verifies REQ-MB-021
TEST(WaysideGroundRuntime, DeterministicOutputs) {
  const TestLine line = FullLine();
  std::vector<std::int64_t> first;
  std::vector<std::int64_t> second;
  {
    auto g = MakeGround(line);
    Exercise(*g, 11, &first);
  }
  {
    auto g = MakeGround(line);
    Exercise(*g, 11, &second);
  }
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first, second);
}

// @verifies REQ-MB-021
TEST(WaysideGroundRuntime, ClockGoingBackIsRefused) {
  auto g = MakeGround(TestLine(), {{1, 500'000}});
  ASSERT_EQ(g->Cycle(1000), CycleStatus::kDone);
  EXPECT_EQ(g->Telegrams().size(), 1U);
  EXPECT_EQ(g->Cycle(999), CycleStatus::kClockWentBack);
  EXPECT_TRUE(g->Telegrams().empty());
  EXPECT_EQ(g->LastCycleMs(), 1000);
  EXPECT_EQ(g->Cycle(1000), CycleStatus::kDone);  // the same time again is allowed
}

}  // namespace
}  // namespace railproof::mb::wayside
