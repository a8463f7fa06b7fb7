// Handover of a real on-board unit between two real wayside units at the system boundary: the
// train opens the next unit's link in the handover zone, reports to both in their own
// chainage, obeys the more restrictive limit, and drops the first link once the first unit
// has released it; a refused handover, or a next unit it cannot hear, stops it at the
// boundary.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <tuple>
#include <vector>

#include "onboard_rig.hpp"
#include "units/tests/wayside/wayside_test_support.hpp"

namespace railproof::units::test {
namespace {

// global chainage (the train's line): unit A covers [0, 3 km) with its boundary at 2 km, unit
// B starts at 1.5 km (the handover zone) and runs 2.5 km (its end of track, in its own
// chainage, lies before unit A's)
constexpr std::int64_t kBoundary = 2'000'000;
constexpr std::int64_t kOriginB = 1'500'000;
constexpr std::uint16_t kRadioA = 1;
constexpr std::uint16_t kRadioB = 2;
constexpr double kCruiseMps = 15.0;

struct Handover {
  Line line;
  std::vector<RadioArea> areas{{kRadioA, 0, kBoundary}, {kRadioB, kOriginB, std::nullopt}};
  mb::wayside::test::LineData line_a = StraightLine(3'000'000);
  mb::wayside::test::LineData line_b = StraightLine(2'500'000);
  WaysideConfig config_a;
  std::unique_ptr<WaysideUnit> a;
  std::unique_ptr<WaysideUnit> b;
  std::optional<OnboardUnit> unit;
  ra::test::Stream stream{0.0, 1'000};
  std::vector<HandoverRequest> requests;   // A -> B, one ground cycle late
  std::vector<HandoverResponse> answers;   // B -> A, one ground cycle late
  std::vector<std::vector<std::uint8_t>> from_a;  // frames of the units for the next cycle
  std::vector<std::vector<std::uint8_t>> from_b;
  double b_silent_from_mm = 1e12;  // unit B's telegrams stop reaching the train from here
  br::DriverInputs driver{};
  bool radio_brake_while_running = false;
  std::optional<std::int64_t> lowest_limit_past_boundary;  // supervised, front past the boundary
  bool released = false;

  explicit Handover(std::size_t per_station_b = kTrainsPerBaseStation) {
    line_a.boundary = kBoundary;
    config_a = BaseConfig(line_a);
    config_a.radio_id = kRadioA;
    config_a.handover_zone_begin_mm = kOriginB;
    WaysideConfig cb = BaseConfig(line_b);
    cb.radio_id = kRadioB;
    cb.origin_mm = kOriginB;
    cb.trains_per_base_station = per_station_b;
    a = std::move(WaysideUnit::Create(config_a).unit);
    b = std::move(WaysideUnit::Create(cb).unit);
    EXPECT_TRUE(a && b);
    EXPECT_EQ(a->Admit(kTrainId, static_cast<std::uint16_t>(kTrainId)), AdmitStatus::kAdmitted);
    EXPECT_EQ(a->Register({kTrainId, ra::test::kTrainLengthMm, ra::test::kInitialFrontMm, 0,
                           mb::wayside::InitialPosition::kEntryBalise})
                  .status,
              RegisterStatus::kRegistered);
    line.crossings.clear();  // the units hold no crossing
    OnboardConfig c = Config(line);
    c.radio.peer_id = kRadioA;
    c.link_key.emplace(KeyOf(kTrainId));
    c.radio_areas = areas;
    auto created = OnboardUnit::Create(c);
    EXPECT_EQ(created.check.error, OnboardConfigError::kNone) << ToString(created.check.error);
    unit.emplace(std::move(*created.unit));
  }

  const OnboardOutputs& Out() const { return unit->Outputs(); }
  double Front() const { return stream.TrueFrontMm(); }

  // One on-board cycle (the driver runs at kCruiseMps unless the unit brakes), then the ground
  // cycle when due: each unit's frame for the train goes to the link of its area.
  void Step() {
    const OnboardOutputs& last = Out();
    const double v = stream.speed();
    double accel = v < kCruiseMps ? 0.5 : 0.0;
    if (last.brake != BrakeDemand::kNone) {
      accel = std::max(-1.0, -v / 0.1);
    }
    driver = {};
    if (v <= 0.0 && last.brake == BrakeDemand::kEmergency) {
      driver.handle_emergency = true;
      driver.reset = true;
    }
    OnboardInputs in;
    ra::test::ImuValues imu;
    imu.ax = accel;  // the body's acceleration: no slip
    in.sensors = stream.Next({accel, 0.0}, imu);
    in.now_ms = in.sensors.time_ms;
    in.driver = driver;
    const bool b_first = last.radio_area == 1;
    const std::vector<std::span<const std::uint8_t>> spans_a(from_a.begin(), from_a.end());
    const std::vector<std::span<const std::uint8_t>> spans_b(from_b.begin(), from_b.end());
    in.frames = b_first ? spans_b : spans_a;
    if (!b_first && last.handover_area == std::optional<std::size_t>(1)) {
      in.handover_frames = spans_b;
    }
    const OnboardOutputs& out = unit->Cycle(in);
    from_a.clear();
    from_b.clear();
    radio_brake_while_running = radio_brake_while_running || (v > 0.0 && out.reason == BrakeReason::kRadioLink);
    if (Front() > static_cast<double>(kBoundary) && out.indications.limit_mm) {
      lowest_limit_past_boundary = std::min(lowest_limit_past_boundary.value_or(*out.indications.limit_mm),
                                            *out.indications.limit_mm);
    }
    const std::int64_t now = out.now_ms;
    const bool to_b_first = out.radio_area == 1;
    if (out.sent) {
      (void)(to_b_first ? Receive(*b, now, out.frame) : a->Receive(now, kTrainId, out.frame.View()));
    }
    if (out.handover_sent) {
      (void)Receive(*b, now, out.handover_frame);
    }
    if (now % kGroundCycleMs == 0) {
      GroundCycle(now);
    }
  }
  static ReceiveResult Receive(WaysideUnit& u, std::int64_t now, const tg::EncodedFrame& f) {
    return u.Receive(now, kTrainId, f.View());
  }
  void GroundCycle(std::int64_t now) {
    CycleInput in_a;
    in_a.from_next = answers;
    const CycleOutput& out_a = a->Cycle(now, in_a);
    requests.assign(out_a.handover_requests.begin(), out_a.handover_requests.end());
    for (const std::uint32_t id : out_a.released) {
      released = released || id == kTrainId;
    }
    Frames(out_a, from_a);
    CycleInput in_b;
    in_b.from_previous = requests;
    const CycleOutput& out_b = b->Cycle(now, in_b);
    answers.assign(out_b.handover_responses.begin(), out_b.handover_responses.end());
    if (Front() < b_silent_from_mm) {
      Frames(out_b, from_b);
    }
  }
  static void Frames(const CycleOutput& out, std::vector<std::vector<std::uint8_t>>& to) {
    for (const TrainFrame& f : out.frames) {
      if (f.train_id == kTrainId) {
        to.emplace_back(f.frame.View().begin(), f.frame.View().end());
      }
    }
  }
  // Runs until the true front reaches `front_mm` or the train has stood for 60 s after moving.
  void RunTo(double front_mm, int max_cycles = 6000) {
    int standing = 0;
    for (int k = 0; k < max_cycles && Front() < front_mm && standing < 600; ++k) {
      Step();
      standing = Front() > static_cast<double>(ra::test::kInitialFrontMm) + 1'000.0 && stream.speed() <= 0.0
                     ? standing + 1
                     : 0;
    }
  }
};

TEST(OnboardHandover, TrainCrossesTheBoundaryAndRunsOnTheNextUnitsLimits) {
  Handover h;
  h.RunTo(3'500'000.0);
  EXPECT_GE(h.Front(), 3'500'000.0);  // past unit A's line end: unit B's limits carried it
  EXPECT_TRUE(h.released);
  EXPECT_FALSE(h.a->Ground().Train(kTrainId).has_value());
  EXPECT_TRUE(h.b->Ground().Train(kTrainId).has_value());
  EXPECT_FALSE(h.radio_brake_while_running);
  const OnboardOutputs& out = h.Out();
  EXPECT_EQ(out.radio_area, 1U);  // the first link dropped, the second became the first
  EXPECT_FALSE(out.handover_area.has_value());
  EXPECT_EQ(out.link, tg::LinkState::kUp);
  ASSERT_TRUE(out.authority_limit_mm.has_value());
  // unit B's end-of-track limit in the train's chainage
  EXPECT_GT(*out.authority_limit_mm, kOriginB + 2'400'000);
  // past the boundary: unit A's end of track until it released the train, then unit B's
  ASSERT_TRUE(h.lowest_limit_past_boundary.has_value());
  EXPECT_GE(*h.lowest_limit_past_boundary, 2'900'000);
  EXPECT_EQ(out.indications.obstruction, messages::Obstruction::kEndOfTrack);
}

// The next unit has no room: unit A keeps its limit at the boundary and the train stops there;
// the link to the next unit, open but silent, does not brake it before.
TEST(OnboardHandover, RefusedHandoverStopsTheTrainAtTheBoundary) {
  Handover h(1);
  ASSERT_EQ(h.b->Admit(7, 7), AdmitStatus::kAdmitted);
  ASSERT_EQ(h.b->Register({7, 60'000, 2'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  h.RunTo(2'500'000.0);
  EXPECT_LE(h.Front(), static_cast<double>(kBoundary - h.config_a.line.margins.system_boundary_mm));
  EXPECT_GE(h.Front(), static_cast<double>(kBoundary - h.config_a.line.margins.system_boundary_mm - 100'000));
  EXPECT_FALSE(h.released);
  EXPECT_FALSE(h.radio_brake_while_running);
  EXPECT_EQ(h.Out().radio_area, 0U);
  EXPECT_EQ(h.Out().handover_area, std::optional<std::size_t>(1));
  EXPECT_EQ(h.Out().indications.obstruction, messages::Obstruction::kSystemBoundary);
  EXPECT_FALSE(h.b->Ground().Train(kTrainId).has_value());
}

// The train's link with unit B comes up in the zone, then unit B's telegrams stop reaching
// it: without a usable limit of the next unit it brakes for the boundary, not before (no
// radio-link brake while running) and not past it.
TEST(OnboardHandover, LostLinkToTheNextUnitBrakesAtTheBoundary) {
  Handover h;
  h.b_silent_from_mm = 1'700'000.0;
  h.RunTo(2'500'000.0);
  EXPECT_LE(h.Front(), static_cast<double>(kBoundary));
  EXPECT_GE(h.Front(), static_cast<double>(kBoundary - 100'000));
  EXPECT_FALSE(h.radio_brake_while_running);
  EXPECT_FALSE(h.released);
  const OnboardOutputs& out = h.Out();
  EXPECT_EQ(out.radio_area, 0U);
  EXPECT_EQ(out.handover_link, tg::LinkState::kLost);
  ASSERT_TRUE(out.indications.limit_mm.has_value());
  EXPECT_LE(*out.indications.limit_mm, kBoundary);
  EXPECT_EQ(out.indications.obstruction, messages::Obstruction::kSystemBoundary);
}

// A train starting in the handover zone starts with the unit before (the one protecting its
// front) and opens the next link once its position is valid; past the boundary it starts with
// the next unit alone.
TEST(OnboardHandover, TheFirstLinkIsTheUnitProtectingTheInitialFront) {
  Line line;
  const std::vector<RadioArea> areas{{kRadioA, 0, kBoundary}, {kRadioB, kOriginB, std::nullopt}};
  for (const auto& [front, first, next] : {std::tuple{1'700'000, 0U, std::optional<std::size_t>(1)},
                                           std::tuple{2'100'000, 1U, std::optional<std::size_t>()}}) {
    OnboardConfig c = Config(line);
    c.initial_front_mm = front;
    c.radio_areas = areas;
    auto created = OnboardUnit::Create(c);
    ASSERT_TRUE(created.unit.has_value());
    ra::test::Stream stream;
    for (int k = 0; k < ra::test::kWarmupCycles + 2; ++k) {
      OnboardInputs in;
      in.sensors = stream.Next();
      in.now_ms = in.sensors.time_ms;
      (void)created.unit->Cycle(in);
    }
    EXPECT_TRUE(created.unit->Outputs().position_valid);
    EXPECT_EQ(created.unit->Outputs().radio_area, first) << front;
    EXPECT_EQ(created.unit->Outputs().handover_area, next) << front;
  }
}

TEST(OnboardHandover, RefusesBadRadioAreasWithTheirReason) {
  const Line line;
  const auto check = [&](std::vector<RadioArea> areas, RadioAreaError e, std::size_t entry) {
    OnboardConfig c = Config(line);
    c.radio_areas = areas;
    const auto r = OnboardUnit::Create(c);
    EXPECT_EQ(r.check.error, OnboardConfigError::kRadioAreas);
    EXPECT_EQ(r.check.areas, e) << ToString(r.check.areas);
    EXPECT_EQ(r.check.entry, entry);
  };
  check({{1, 0, 2'000'000}, {2, 0, std::nullopt}}, RadioAreaError::kNotIncreasing, 1);
  check({{1, 0, 2'000'000}, {2, 1'550'000, std::nullopt}}, RadioAreaError::kOriginNotOnBlock, 1);
  check({{1, 0, 1'500'000}, {2, 1'500'000, std::nullopt}}, RadioAreaError::kBoundaryOutsideArea, 0);
  check({{1, 0, std::nullopt}, {2, 1'500'000, std::nullopt}}, RadioAreaError::kBoundaryOutsideArea, 0);
  check({{1, 0, 2'000'000}, {2, 1'500'000, 3'000'000}}, RadioAreaError::kBoundaryOutsideArea, 1);
  check({{1, 0, 2'000'000}, {1, 1'500'000, std::nullopt}}, RadioAreaError::kPeerTwice, 1);
  check({{static_cast<std::uint16_t>(kTrainId), 0, std::nullopt}}, RadioAreaError::kPeerTwice, 0);
}

}  // namespace
}  // namespace railproof::units::test
