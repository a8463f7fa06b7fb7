// Unit tests of the odometry's configuration check and sensor stream validation
// (spec/design/ra.md §2, §6): every ConfigError, every InputError with its safe
// reaction (stop demand and invalid position in the same cycle, every compensation
// discarded, held until a balise fix), and that nothing of a rejected cycle is used.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "railproof/ra/odometry.hpp"
#include "test_odometry_util.hpp"

namespace railproof::ra::test {
namespace {

// ---- configuration --------------------------------------------------------------------------

ConfigError CreateWith(const std::function<void(OdometryConfig&, std::vector<OdometrySection>&)>& change) {
  std::vector<OdometrySection> sections = {{0, 1'000'000, 0, 20'000, 0}, {1'000'000, 5'000'000, 160, 32'000, 0}};
  OdometryConfig cfg = Config(sections);
  change(cfg, sections);
  cfg.sections = cfg.sections == nullptr ? nullptr : sections.data();
  auto od = std::make_unique<Odometry>();
  return Odometry::Create(cfg, *od);
}

// @verifies REQ-RA-009
// @verifies REQ-RA-007
TEST(OdometryConfigCheck, EveryReason) {
  using S = std::vector<OdometrySection>;
  EXPECT_EQ(CreateWith([](OdometryConfig&, S&) {}), ConfigError::kNone);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.wheel_diameter_um = 499'999; }), ConfigError::kWheelDiameter);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.wheel_diameter_um = 1'500'001; }), ConfigError::kWheelDiameter);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.train_length_mm = 999; }), ConfigError::kTrainLength);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.train_length_mm = 1'000'001; }), ConfigError::kTrainLength);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.detect_threshold_mm_s2 = 49; }), ConfigError::kThreshold);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.detect_threshold_mm_s2 = 2'001; }), ConfigError::kThreshold);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.start_points = 0; }), ConfigError::kStartPoints);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.start_points = 3; }), ConfigError::kStartPoints);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.start_points = 1; }), ConfigError::kNone);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.imu_rate_error_udeg_s = -1; }), ConfigError::kRateError);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.imu_rate_error_udeg_s = 1'000'001; }), ConfigError::kRateError);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.length_correction_ppm = -1; }), ConfigError::kLengthCorrection);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.length_correction_ppm = 100'001; }),
            ConfigError::kLengthCorrection);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.sections = nullptr; }), ConfigError::kSectionCount);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.section_count = 0; }), ConfigError::kSectionCount);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S& s) {
              s.resize(static_cast<std::size_t>(kMaxSections) + 1);
              for (std::size_t i = 0; i < s.size(); ++i) {
                const auto b = static_cast<std::int64_t>(i) * 100'000;
                s[i] = OdometrySection{b, b + 100'000, 0, 20'000, 0};
              }
              c.section_count = static_cast<int>(s.size());
            }),
            ConfigError::kSectionCount);
  // order: empty section, gap, overlap
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].end_mm = s[0].begin_mm; }), ConfigError::kSectionOrder);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[1].begin_mm = 1'000'001; }), ConfigError::kSectionOrder);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[1].begin_mm = 999'999; }), ConfigError::kSectionOrder);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[1].gradient_permille_x10 = -1; }), ConfigError::kSectionGradient);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[1].gradient_permille_x10 = 1'001; }),
            ConfigError::kSectionGradient);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].max_compensation_ms = 2'900; }), ConfigError::kSectionTime);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].max_compensation_ms = 32'100; }), ConfigError::kSectionTime);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].max_compensation_ms = 20'050; }), ConfigError::kSectionTime);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].max_compensation_ms = 3'000; }), ConfigError::kNone);
  // margin: the error model for 20 s level is 8912 mm
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].margin_mm = 8'911; }), ConfigError::kSectionMargin);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].margin_mm = 8'912; }), ConfigError::kNone);
  EXPECT_EQ(CreateWith([](OdometryConfig&, S& s) { s[0].margin_mm = -1; }), ConfigError::kSectionMargin);
  // 32 s at 16 permille with the full rate error 0.025 deg/s: 168878 mm
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S& s) {
              c.imu_rate_error_udeg_s = 25'000;
              s[1].margin_mm = 168'877;
            }),
            ConfigError::kSectionMargin);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) {
              c.method = Method::kMaxMinAcceleration;
              c.accel_max_mm_s2 = 0;
            }),
            ConfigError::kAccelBounds);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) {
              c.method = Method::kMaxMinAcceleration;
              c.decel_max_mm_s2 = -1;
            }),
            ConfigError::kAccelBounds);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.accel_max_mm_s2 = 0; }), ConfigError::kNone);  // IMU method
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.initial_front_mm = -1; }), ConfigError::kInitialOutside);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.initial_front_mm = 5'000'000; }), ConfigError::kInitialOutside);
  EXPECT_EQ(CreateWith([](OdometryConfig& c, S&) { c.initial_front_mm = 4'999'999; }), ConfigError::kNone);
}

// @verifies REQ-RA-013
TEST(OdometryConfigCheck, NamesAndAnUncreatedObject) {
  std::set<std::string> names;
  for (int e = 0; e <= static_cast<int>(ConfigError::kLengthCorrection); ++e) {
    names.insert(ToString(static_cast<ConfigError>(e)));
  }
  EXPECT_EQ(names.size(), static_cast<std::size_t>(ConfigError::kLengthCorrection) + 1);
  names.clear();
  for (int e = 0; e <= static_cast<int>(InputError::kImuOutOfRange); ++e) {
    names.insert(ToString(static_cast<InputError>(e)));
  }
  EXPECT_EQ(names.size(), static_cast<std::size_t>(InputError::kImuOutOfRange) + 1);
  EXPECT_STREQ(ToString(static_cast<InputError>(200)), "unknown");
  // a default-constructed object demands a stop until it is created
  Odometry od;
  const OdometryOutput& o = od.Step(Cycle(1'000, 0, 0));
  EXPECT_TRUE(o.stop_demand);
  EXPECT_FALSE(o.position_valid);
}

// ---- sensor stream ----------------------------------------------------------------------------

struct Injection {
  const char* name;
  InputError error;
  std::function<void(CycleInput&, const CycleInput& prev)> change;
  bool resync = false;  // the time base follows the bad time: the next cycle is a gap too
};

std::vector<Injection> Injections() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  return {
      {"repeated cycle time", InputError::kCycleTimeGap, [](CycleInput& in, const CycleInput& p) { in = p; }, true},
      {"time backwards", InputError::kCycleTimeGap,
       [](CycleInput& in, const CycleInput& p) { in.time_ms = p.time_ms - 100; }, true},
      {"pulses decreasing", InputError::kTgPulsesDecreasing,
       [](CycleInput& in, const CycleInput& p) { in.tg.pulses = p.tg.pulses - 1; }},
      {"edge after the sample", InputError::kTgEdgeInvalid,
       [](CycleInput& in, const CycleInput&) { in.tg.last_edge_us = in.tg.time_us + 1; }},
      {"edge not advanced with pulses", InputError::kTgEdgeInvalid,
       [](CycleInput& in, const CycleInput& p) { in.tg.last_edge_us = p.tg.last_edge_us; }},
      {"edge moved without a pulse", InputError::kTgEdgeInvalid,
       [](CycleInput& in, const CycleInput& p) {
         in.tg.pulses = p.tg.pulses;
         in.tg.last_edge_us = p.tg.last_edge_us + 5;
       }},
      {"TG sample outside the cycle", InputError::kTgEdgeInvalid,
       [](CycleInput& in, const CycleInput&) { in.tg.time_us -= 150'000; }},
      {"implausible pulse rate", InputError::kTgImplausibleRate,
       [](CycleInput& in, const CycleInput& p) { in.tg.pulses = p.tg.pulses + 279; }},
      {"negative count", InputError::kTgImplausibleRate, [](CycleInput& in, const CycleInput&) { in.tg.pulses = -5; }},
      {"nine IMU samples", InputError::kImuSampleCount, [](CycleInput& in, const CycleInput&) { in.imu_count = 9; }},
      {"IMU sample late", InputError::kImuTimestamps,
       [](CycleInput& in, const CycleInput&) { in.imu[5].time_us += 1'100; }},
      {"IMU samples shifted out of the cycle", InputError::kImuTimestamps,
       [](CycleInput& in, const CycleInput&) {
         for (auto& s : in.imu) s.time_us += 50'000;
       }},
      {"IMU NaN", InputError::kImuNotFinite, [nan](CycleInput& in, const CycleInput&) { in.imu[2].ay = nan; }},
      {"IMU inf", InputError::kImuNotFinite, [inf](CycleInput& in, const CycleInput&) { in.imu[9].wz = -inf; }},
      {"IMU acceleration out of range", InputError::kImuOutOfRange,
       [](CycleInput& in, const CycleInput&) { in.imu[0].ax = 50.001; }},
      {"IMU rate out of range", InputError::kImuOutOfRange,
       [](CycleInput& in, const CycleInput&) { in.imu[7].wx = -5.001; }},
  };
}

// Each reason is reported, and in the same cycle the position is invalid and a stop is
// demanded, with the stop reason of the failed sensor; the reaction is held on later valid
// cycles, also at a balise read while the train still runs, and ends at a balise fix with
// both sensors valid after the train has stood for the warm-up (REQ-RA-015).
// @verifies REQ-RA-013
// @verifies REQ-RA-007
// @verifies REQ-RA-015
TEST(OdometryInput, EveryReasonGivesTheSafeReaction) {
  for (const Injection& inj : Injections()) {
    SCOPED_TRACE(inj.name);
    auto od = Make(Config(LevelLine()));
    Stream s;
    RunUp(*od, s, 10.0);
    CycleInput prev;
    for (int k = 0; k < 50; ++k) {
      prev = s.Next();
      ASSERT_EQ(od->Step(prev).input_error, InputError::kNone);
    }
    CycleInput bad = s.Next();
    inj.change(bad, prev);
    const OdometryOutput o = od->Step(bad);
    EXPECT_EQ(o.input_error, inj.error) << ToString(o.input_error);
    EXPECT_TRUE(o.stop_demand);
    EXPECT_FALSE(o.position_valid);
    EXPECT_EQ(o.mode, Mode::kStopped);
    EXPECT_EQ(o.stop_reason, IsImuError(inj.error) ? StopReason::kImuFailure : StopReason::kTgFailure);
    if (inj.resync) {
      const OdometryOutput& q = od->Step(s.Next());
      EXPECT_EQ(q.input_error, InputError::kCycleTimeGap);
      EXPECT_TRUE(q.stop_demand);
    }
    // later valid cycles are accepted but the reaction holds
    for (int k = 0; k < 5; ++k) {
      const OdometryOutput& q = od->Step(s.Next());
      EXPECT_EQ(q.input_error, InputError::kNone) << k;
      EXPECT_TRUE(q.stop_demand);
      EXPECT_FALSE(q.position_valid);
    }
    const OdometryOutput& moving = od->Step(s.Next({}, {}, std::llround(s.TrueFrontMm())));
    EXPECT_TRUE(moving.stop_demand);  // a balise while running: not trusted yet
    EXPECT_EQ(moving.mode, Mode::kStopped);
    BrakeAndWarmUp(*od, s);
    const std::int64_t fix = std::llround(s.TrueFrontMm()) + 1'000;
    const OdometryOutput& r = od->Step(s.Next({}, {}, fix));
    EXPECT_EQ(r.mode, Mode::kTg);
    EXPECT_TRUE(r.position_valid);
    EXPECT_FALSE(r.stop_demand);
    EXPECT_EQ(r.stop_reason, StopReason::kNone);
    EXPECT_EQ(r.front_mm, fix);
    EXPECT_EQ(r.accumulated_error_mm, 0);
  }
}

// A TG counter that restarts from 0 (power loss): rejected once, then a new baseline; the
// position is re-established at the next balise fix after the warm-up at standstill
// (ASM-026, REQ-RA-015).
// @verifies REQ-RA-013
// @verifies REQ-RA-015
TEST(OdometryInput, RestartedCounterRecoversAtABalise) {
  auto od = Make(Config(LevelLine()));
  Stream s;
  RunUp(*od, s, 10.0);
  for (int k = 0; k < 50; ++k) (void)od->Step(s.Next());
  const std::int64_t offset = s.pulses();
  OdometryOutput o;
  CycleInput in = s.Next();
  in.tg.pulses -= offset;  // counting restarted
  in.tg.last_edge_us = 0;
  o = od->Step(in);
  EXPECT_EQ(o.input_error, InputError::kTgPulsesDecreasing);
  const std::int64_t front = o.front_mm;
  for (int k = 0; k < 5; ++k) {
    in = s.Next();
    in.tg.pulses -= offset;
    o = od->Step(in);
    EXPECT_EQ(o.input_error, InputError::kNone) << k;
    EXPECT_TRUE(o.stop_demand);
  }
  EXPECT_NEAR(static_cast<double>(o.front_mm - front), 4'000.0, 35.0);  // from the new baseline
  BrakeAndWarmUp(*od, s, [offset](CycleInput& c) { c.tg.pulses -= offset; });
  in = s.Next({}, {}, std::llround(s.TrueFrontMm()) + 1'000);
  in.tg.pulses -= offset;
  o = od->Step(in);
  EXPECT_EQ(o.mode, Mode::kTg);
  EXPECT_TRUE(o.position_valid);
  EXPECT_FALSE(o.stop_demand);
}

// A real gap (one cycle missing) and IMU and TG failing together (the IMU reason wins, as
// the state machine checks the IMU first).
// @verifies REQ-RA-013
TEST(OdometryInput, GapAndBothSensorsFailing) {
  auto od = Make(Config(LevelLine()));
  Stream s;
  RunUp(*od, s, 10.0);
  for (int k = 0; k < 50; ++k) (void)od->Step(s.Next());
  (void)s.Next();  // lost
  OdometryOutput o = od->Step(s.Next());
  EXPECT_EQ(o.input_error, InputError::kCycleTimeGap);
  EXPECT_EQ(o.stop_reason, StopReason::kTgFailure);
  o = od->Step(s.Next());
  EXPECT_EQ(o.input_error, InputError::kNone);  // the stream continues from the received time

  auto od2 = Make(Config(LevelLine()));
  Stream s2;
  RunUp(*od2, s2, 10.0);
  CycleInput prev;
  for (int k = 0; k < 50; ++k) (void)od2->Step(prev = s2.Next());
  CycleInput bad = s2.Next();
  bad.tg.pulses = prev.tg.pulses - 3;
  bad.imu[4].az = std::numeric_limits<double>::quiet_NaN();
  o = od2->Step(bad);
  EXPECT_EQ(o.input_error, InputError::kImuNotFinite);
  EXPECT_EQ(o.stop_reason, StopReason::kImuFailure);
  EXPECT_TRUE(o.stop_demand);
}

// A failure while compensating discards every candidate in the same cycle.
// @verifies REQ-RA-013
TEST(OdometryInput, FailureWhileCompensatingDiscardsTheCandidates) {
  auto od = Make(Config(LevelLine()));
  Stream s;
  RunUp(*od, s, 12.0);
  OdometryOutput o;
  for (int k = 0; k < 100 && o.mode != Mode::kCompensating; ++k) {
    o = od->Step(s.Next({0.0, k < 60 ? 0.0 : std::min(3.0, 0.3 * (k - 59))}));
  }
  ASSERT_EQ(o.mode, Mode::kCompensating);
  CycleInput bad = s.Next({0.0, 3.0});
  bad.imu_count = 11;
  o = od->Step(bad);
  EXPECT_EQ(o.input_error, InputError::kImuSampleCount);
  EXPECT_EQ(o.mode, Mode::kStopped);
  EXPECT_EQ(o.stop_reason, StopReason::kImuFailure);
  EXPECT_TRUE(o.stop_demand);
  EXPECT_FALSE(o.position_valid);
  EXPECT_FALSE(od->machine().state().candidates[0].active);
  EXPECT_FALSE(od->machine().state().candidates[1].active);
  EXPECT_EQ(o.v_comp[0], 0.0);
}

// Nothing of a rejected cycle is used: its balise fix does not re-establish the position,
// its pulses do not move the front, its IMU values do not enter the averages.
// @verifies REQ-RA-013
TEST(OdometryInput, NothingOfARejectedCycleIsUsed) {
  auto od = Make(Config(LevelLine()));
  Stream s;
  RunUp(*od, s, 10.0);
  CycleInput prev;
  for (int k = 0; k < 50; ++k) (void)od->Step(prev = s.Next());
  // a rejected cycle with a balise fix: still stopped
  CycleInput bad = s.Next({}, {}, 2'000'000);
  bad.imu[1].wx = 9.0;
  OdometryOutput o = od->Step(bad);
  EXPECT_EQ(o.input_error, InputError::kImuOutOfRange);
  EXPECT_NE(o.front_mm, 2'000'000);
  EXPECT_NE(o.last_balise_mm, 2'000'000);
  const std::int64_t front_before = o.front_mm;
  o = od->Step(s.Next());
  EXPECT_EQ(o.input_error, InputError::kNone);
  EXPECT_NEAR(static_cast<double>(o.front_mm - front_before), 2'000.0, 35.0);  // two cycles of 1 m
  const std::int64_t front_after = o.front_mm;
  // a rejected cycle with 1000 extra pulses: the front does not jump; the next accepted
  // cycle continues the TG distance from the last accepted cycle (two cycles of 1 m)
  bad = s.Next();
  bad.tg.pulses += 1'000;
  o = od->Step(bad);
  EXPECT_EQ(o.input_error, InputError::kTgImplausibleRate);
  EXPECT_EQ(o.front_mm, front_after);
  o = od->Step(s.Next());
  EXPECT_EQ(o.input_error, InputError::kNone);
  EXPECT_NEAR(static_cast<double>(o.front_mm - front_after), 2'000.0, 35.0);
  // a rejected cycle with a large (in range) a_x: the averages restart without it
  ImuValues m;
  m.ax = 30.0;
  bad = s.Next({}, m);
  bad.imu_count = 9;
  o = od->Step(bad);
  EXPECT_EQ(o.input_error, InputError::kImuSampleCount);
  o = od->Step(s.Next());
  EXPECT_EQ(o.input_error, InputError::kNone);
  EXPECT_EQ(o.ax_avg, 0.0);
  EXPECT_TRUE(o.stop_demand);
}

}  // namespace
}  // namespace railproof::ra::test
