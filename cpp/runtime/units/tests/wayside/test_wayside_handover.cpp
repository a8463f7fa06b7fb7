// Handover of a train between two wayside units at the system boundary: the train is known to
// both in the overlap, the accepting unit's limit governs past the boundary, the releasing unit
// removes the train once its rear has passed the boundary; a refused train stops at the
// boundary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <vector>

#include "wayside_test_support.hpp"

namespace railproof::units::test {
namespace {

constexpr std::int64_t kLen = 200'000;
constexpr std::uint32_t kTrain = 42;
constexpr std::uint16_t kRadio = 42;
// global chainage: unit A covers [0, 3 km) with its boundary at 2 km; unit B starts at 1.5 km
constexpr std::int64_t kBoundary = 2'000'000;
constexpr std::int64_t kOriginB = 1'500'000;
constexpr std::int64_t kStep = 20'000;  // the train runs at most 20 m per cycle (40 m/s)

struct TwoUnits {
  mb::wayside::test::LineData line_a = StraightLine(3'000'000);
  mb::wayside::test::LineData line_b = StraightLine(3'000'000);
  WaysideConfig config_a;
  std::unique_ptr<WaysideUnit> a;
  std::unique_ptr<WaysideUnit> b;
  TrainRadio to_a{kTrain, kRadio, 1};
  TrainRadio to_b{kTrain, kRadio, 2};
  std::int64_t now = 0;
  std::int64_t front = 1'000'000;  // global
  bool released = false;
  bool linked_b = false;
  bool seen_in_both = false;
  std::optional<std::int64_t> release_rear;
  std::vector<HandoverResponse> answers;  // B -> A, one cycle late
  std::vector<InputEvent> events_a;
  std::int64_t a_limit = 0;

  explicit TwoUnits(std::size_t per_station_b = kTrainsPerBaseStation, std::int64_t start_front = 1'000'000)
      : front(start_front) {
    line_a.boundary = kBoundary;
    config_a = BaseConfig(line_a);
    config_a.handover_zone_begin_mm = kOriginB;
    WaysideConfig cb = BaseConfig(line_b);
    cb.radio_id = 2;
    cb.origin_mm = kOriginB;
    cb.trains_per_base_station = per_station_b;
    a = std::move(WaysideUnit::Create(config_a).unit);
    b = std::move(WaysideUnit::Create(cb).unit);
    EXPECT_TRUE(a && b);
    EXPECT_EQ(a->Admit(kTrain, kRadio), AdmitStatus::kAdmitted);
    EXPECT_EQ(a->Register({kTrain, kLen, front, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
              RegisterStatus::kRegistered);
  }

  // One ground cycle of both units and the train's answer: it reports to each unit it is
  // linked to and runs up to the lowest limit it holds.
  void Step() {
    now += kGroundCycleMs;
    CycleInput in_a;
    in_a.from_next = answers;
    const CycleOutput& out_a = a->Cycle(now, in_a);
    for (const InputEvent& e : out_a.events) {
      events_a.push_back(e);
    }
    const std::vector<HandoverRequest> requests(out_a.handover_requests.begin(), out_a.handover_requests.end());
    for (const std::uint32_t id : out_a.released) {
      if (id == kTrain) {
        released = true;
        release_rear = front - kLen;
      }
    }
    const auto bundle_a = released ? messages::Bundle{} : to_a.Take(now, out_a);
    CycleInput in_b;
    in_b.from_previous = requests;
    const CycleOutput& out_b = b->Cycle(now, in_b);
    answers.assign(out_b.handover_responses.begin(), out_b.handover_responses.end());
    const auto bundle_b = to_b.Take(now, out_b);
    linked_b = linked_b || std::any_of(out_b.frames.begin(), out_b.frames.end(),
                                       [](const TrainFrame& f) { return f.train_id == kTrain; });
    seen_in_both = seen_in_both || (a->Ground().Train(kTrain) && b->Ground().Train(kTrain));
    // the train obeys every limit it holds (global chainage)
    std::optional<std::int64_t> limit;
    if (const auto* t = StopLimitOf(bundle_a)) {
      limit = t->limit_mm;
      a_limit = t->limit_mm;
      if (const auto* tb = StopLimitOf(bundle_b); tb != nullptr && t->limit_mm > kBoundary) {
        // past the boundary the releasing unit sends no more than the accepting unit
        EXPECT_LE(t->limit_mm, tb->limit_mm + kOriginB);
      }
    }
    if (const auto* t = StopLimitOf(bundle_b)) {
      limit = std::min(limit.value_or(t->limit_mm + kOriginB), t->limit_mm + kOriginB);
    }
    if (limit && *limit > front) {
      front += std::min(kStep, *limit - front);
    }
    if (!released) {
      (void)a->Receive(now, kTrain, to_a.Send(now, {ReportAt(*a, kTrain, front, kLen)}));
    }
    if (linked_b) {
      (void)b->Receive(now, kTrain, to_b.Send(now, {ReportAt(*b, kTrain, front - kOriginB, kLen)}));
    }
  }
  bool RefusedWith(HandoverVerdict v) const {
    return std::any_of(events_a.begin(), events_a.end(), [v](const InputEvent& e) {
      return e.status == InputStatus::kHandoverRefused && e.id == kTrain && e.verdict == v;
    });
  }
};

TEST(WaysideHandover, TrainCrossesTheBoundaryAndIsReleasedOnceItsRearHasPassed) {
  TwoUnits u;
  for (int k = 0; k < 400 && u.front < 2'600'000; ++k) {
    u.Step();
    if (!u.released) {
      // the releasing unit keeps the train until its rear has passed the boundary
      EXPECT_TRUE(u.a->Ground().Train(kTrain).has_value()) << "cycle " << k;
    }
  }
  EXPECT_TRUE(u.seen_in_both);
  EXPECT_TRUE(u.released);
  ASSERT_TRUE(u.release_rear.has_value());
  EXPECT_GE(*u.release_rear, kBoundary);
  EXPECT_FALSE(u.a->Ground().Train(kTrain).has_value());
  EXPECT_TRUE(u.b->Ground().Train(kTrain).has_value());
  EXPECT_GE(u.front, 2'600'000);  // the accepting unit's limits carried it on
}

// The accepting unit has no room: the train stops at the boundary minus its margin.
TEST(WaysideHandover, NoRoomInTheNextUnitStopsTheTrainAtTheBoundary) {
  TwoUnits u(1);
  ASSERT_EQ(u.b->Admit(7, 7), AdmitStatus::kAdmitted);
  ASSERT_EQ(u.b->Register({7, kLen, 2'500'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  for (int k = 0; k < 200; ++k) {
    u.Step();
  }
  EXPECT_TRUE(u.RefusedWith(HandoverVerdict::kNoRoom));
  EXPECT_FALSE(u.released);
  EXPECT_EQ(u.front, kBoundary - u.config_a.line.margins.system_boundary_mm);
  EXPECT_EQ(u.a->LastOutput().trains[0].kind, messages::Obstruction::kSystemBoundary);
  EXPECT_FALSE(u.b->Ground().Train(kTrain).has_value());
}

// The track is not clear for the accepting unit: its train detection reports an occupancy
// where the handed-over train would stand: refused, the train stops at the boundary.
TEST(WaysideHandover, TrackNotClearStopsTheTrainAtTheBoundary) {
  TwoUnits u(kTrainsPerBaseStation, 1'600'000);
  ASSERT_EQ(u.b->ReportUnequippedOccupancy({0, 600'000}).status, mb::wayside::CommandStatus::kAccepted);
  for (int k = 0; k < 200; ++k) {
    u.Step();
  }
  EXPECT_TRUE(u.RefusedWith(HandoverVerdict::kTrackNotClear));
  EXPECT_FALSE(u.released);
  EXPECT_LE(u.front, kBoundary - u.config_a.line.margins.system_boundary_mm);
  EXPECT_EQ(u.a_limit, kBoundary - u.config_a.line.margins.system_boundary_mm);
}

}  // namespace
}  // namespace railproof::units::test
