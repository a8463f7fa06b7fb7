// Follower control (REQ-FC-001..011): the buffers and the speed-limit start position against
// hand-computed values of D2's formulas, the approach point's optimality (Ipopt against the
// grid), trajectories within the limits and the braking curve to the leader's buffered rear at
// every step, the slowing rule meeting a required running time, the supervision overriding an
// aggressive follower command, and bad input of the study.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "railproof/br/patterns.hpp"
#include "railproof/br/supervisor.hpp"
#include "railproof/fc/follower.hpp"
#include "railproof/fc/headway.hpp"
#include "railproof/generated/fc_params.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/testing/gen_data.hpp"
#include "railproof/testing/input_error.hpp"

namespace railproof::fc {
namespace {

namespace fcp = railproof::params::fc;

const offline::Line& D2Line() {
  static const offline::Line line = offline::LoadLine(testing::GenDir() / "lines" / "d2_urban_line.json");
  return line;
}
const offline::TrainType& D2Type() {
  static const offline::TrainType t = testing::Train("emu10_d2");
  return t;
}
const Train& D2Train() {
  static const Train t = MakeD2Train(D2Type());
  return t;
}
const offline::RunningLine& Up() { return D2Line().Running("up"); }

// S1 (stop 515 m) over S2 (platform 1800-2020 m, stop 2015 m) to S3 (stop 3615 m).
constexpr double kS1 = 515.0, kEntry = 1800.0, kEnd = 2020.0, kS2 = 2015.0, kS3 = 3615.0;

// @verifies REQ-FC-001
TEST(Buffers, FrontAndRearAsD2States) {
  const BufferParams b = MakeBufferParams(D2Type());
  EXPECT_DOUBLE_EQ(b.rate, 0.001);  // 1000 ppm
  EXPECT_DOUBLE_EQ(b.tau_s, 0.5);
  EXPECT_DOUBLE_EQ(b.lc_m, 2.0);
  // 350 m past the balise at 20 m/s: 0.001 * 350 + 20 * 0.5 + 2 = 12.35 m; rear 2.35 m
  EXPECT_NEAR(FrontBuffer(b, 1000.0, 20.0, 650.0), 12.35, 1e-12);
  EXPECT_NEAR(RearBuffer(b, 1000.0, 650.0), 2.35, 1e-12);
  EXPECT_DOUBLE_EQ(LastBalise({150.0, 410.0, 1100.0}, 1099.0), 410.0);
  EXPECT_DOUBLE_EQ(LastBalise({150.0, 410.0}, 100.0), 0.0);
}

// @verifies REQ-FC-002
TEST(Buffers, SpeedLimitStartPositionByTheFormula) {
  const BufferParams b{0.001, 0.5, 2.0};
  // limit at 1150 m entered at 55 km/h; balises 150, 410, 1100 m: with x_m = 1100 the front
  // is (1150 - (15.2778 * 0.5 + 2) + 1.1) / 1.001 = 1141.32 m, past 1100 m: the largest valid
  const double v = 55.0 / 3.6;
  const double expected = (1150.0 - (v * 0.5 + 2.0) + 0.001 * 1100.0) / 1.001;
  EXPECT_NEAR(LimitStartFront(b, 1150.0, v, {150.0, 410.0, 1100.0}), expected, 1e-9);
  // a balise beyond the position it would give is not the one passed there: 1145 m gives
  // (1150 - 9.6389 + 1.145) / 1.001 = 1140.37 < 1145, so x_m = 1100 still holds
  EXPECT_NEAR(LimitStartFront(b, 1150.0, v, {150.0, 410.0, 1100.0, 1145.0}), expected, 1e-9);
  // the buffered front at that position is exactly x_s
  EXPECT_NEAR(expected + FrontBuffer(b, expected, v, 1100.0), 1150.0, 1e-9);
  // release: the buffered rear of a 200 m train leaves a limit ending at 1550 m
  const double end = LimitEndFront(b, 1550.0, 200.0, {150.0, 410.0, 1100.0, 1650.0});
  EXPECT_NEAR(end - 200.0 - RearBuffer(b, end, 1650.0), 1550.0, 1e-9);
}

// @verifies REQ-FC-002 REQ-FC-003
TEST(Corridor, LimitsActByTheBufferedFrontAndRear) {
  const Corridor c(Up(), kS1, kS3, D2Train(), Case::kSpeedLimits);
  // the 55 km/h limit from 1150 m acts before 1150 m (buffered front) and until the rear and
  // its buffer have left 1550 m
  EXPECT_NEAR(c.Limit(1135.0), 80.0 / 3.6, 1e-9);
  EXPECT_NEAR(c.Limit(1145.0), 55.0 / 3.6, 1e-9);
  EXPECT_NEAR(c.Limit(1750.0), 55.0 / 3.6, 1e-9);
  EXPECT_NEAR(c.Limit(1760.0), 80.0 / 3.6, 1e-9);
  const Corridor level(Up(), kS1, kS3, D2Train(), Case::kLevelNoLimits);
  EXPECT_NEAR(level.Limit(1145.0), 110.0 / 3.6, 1e-9);
  // on the level the safe speed is D2's sqrt(2 d beta) with d from the buffered front:
  // v tau + v^2 / (2 beta) = d - r (x - x_m) - l_c
  const double beta = D2Train().beta;
  const double x = 1200.0;
  const double v = level.SafeSpeed(x, 1500.0);
  const double d = 1500.0 - x - 0.001 * (x - 1100.0) - 2.0;
  EXPECT_NEAR(v, offline::CurveSpeed(d, beta, 0.5), 1e-6);
}

// @verifies REQ-FC-004
TEST(ApproachPoint, IpoptAgreesWithTheGrid) {
  for (const Case which : {Case::kLevelNoLimits, Case::kGradients}) {
    const Corridor c(Up(), kS1, kS3, D2Train(), which);
    const ApproachProblem p{&c, kEntry, kS2};
    const ApproachPoint a = FindApproachPoint(p, 0.01);
    EXPECT_NE(a.status.rfind("failed", 0), 0U) << a.status;
    EXPECT_NEAR(a.time_s, a.grid_time_s, static_cast<double>(fcp::approach_tolerance_ms) / 1000.0) << CaseName(which);
    // optimal: no neighbour does better, and the point lies on the braking curve to the entry
    EXPECT_LE(a.time_s, TimeFromApproach(p, a.v + 0.5) + 1e-9);
    EXPECT_LE(a.time_s, TimeFromApproach(p, a.v - 0.5) + 1e-9);
    EXPECT_NEAR(a.v, c.SafeSpeed(a.x, kEntry), 1e-3);
    // a train standing at the entry's buffered limit needs longer than from the approach point
    EXPECT_LT(a.time_s, TimeFromApproach(p, 1.0));
  }
}

// @verifies REQ-FC-006
TEST(OutsideStop, FullAccelerationReachesTheApproachPoint) {
  const Corridor c(Up(), kS1, kS3, D2Train(), Case::kLevelNoLimits);
  const ApproachPoint a = FindApproachPoint({&c, kEntry, kS2}, 0.05);
  const OutsideStop o = FindOutsideStop(c, a);
  ASSERT_LT(o.x, a.x);
  // stepping full traction from the stop reaches the approach point at its speed
  State s{0.0, o.x, 0.0};
  while (s.x < a.x) {
    s = StepTrain(c, s, c.train().perf.accel_mps2, 0.02);
  }
  EXPECT_NEAR(s.v, a.v, 0.05);
  EXPECT_NEAR(s.t, o.time_to_approach_s, 0.05);
}

// @verifies REQ-FC-007
TEST(SlowingRule, MeetsARequiredRunningTime) {
  const Corridor c(Up(), kS1, kS3, D2Train(), Case::kSpeedLimits);
  const State from{0.0, kS1, 0.0};
  const Plan fastest = FastestPlan(c, from, 1600.0, 12.0, 0.02);
  ASSERT_GE(fastest.sections.size(), 3U);  // 45, 80, 55, 80 km/h sections
  const double t_fast = PlanTime(c, from, fastest, 0.02);
  for (const double extra : {5.0, 20.0, 40.0}) {
    const SlowedResult r = SlowToRunningTime(c, from, 1600.0, 12.0, t_fast + extra, 0.02);
    EXPECT_NEAR(r.time_s, t_fast + extra, 0.1) << extra;
    EXPECT_GT(r.lambda, 0.0);
  }
  // the cruise goes first: a small slowing keeps every coast-start speed at the limit
  const SlowedResult small = SlowToRunningTime(c, from, 1600.0, 12.0, t_fast + 2.0, 0.02);
  EXPECT_LE(small.lambda, 1.0);
  for (const SectionPlan& s : small.plan.sections) {
    EXPECT_DOUBLE_EQ(s.coast_speed, c.Limit(s.begin));
  }
}

Scenario MakeScenario(const Corridor& c, double delay) {
  Scenario sc;
  sc.corridor = &c;
  sc.origin_stop = kS1;
  sc.station_entry = kEntry;
  sc.station_end = kEnd;
  sc.station_stop = kS2;
  sc.next_stop = kS3;
  sc.follower_depart = 100.0;
  const double run = std::ceil(FastestRunTime(c, kS1, kS2, 0.02));
  sc.leader_planned_departure = run + 40.0;
  sc.leader_delay = delay;
  sc.fixed_blocks = FixedBlocks(Up(), kS1, kS3, 400.0);
  sc.fixed_block_overlap = 50.0;
  sc.approach = FindApproachPoint({&c, kEntry, kS2}, 0.05);
  sc.outside = FindOutsideStop(c, sc.approach);
  return sc;
}

// Every step of the follower within the static ceiling and the braking curve from its buffered
// front to the leader's buffered rear (and the platform while the leader occupies it).
void ExpectWithinCeilings(const Corridor& c, const Scenario& sc, const fc::Run& r, Policy policy) {
  const Train& t = c.train();
  for (std::size_t k = 1; k < r.follower.size(); ++k) {
    const State& f = r.follower[k];
    const State& l = r.leader[k - 1];
    ASSERT_LE(f.v, c.StaticCeiling(f.x) + 1e-6) << PolicyName(policy) << " t=" << f.t;
    if (policy != Policy::kFixedBlockBaseline && l.x > f.x) {
      double limit = l.x - t.perf.length_m - RearBuffer(t.buffers, l.x, LastBalise(c.balises(), l.x));
      if (f.t - sc.dt < r.route_clear && r.follower[k - 1].x < sc.station_entry) {
        limit = std::min(limit, sc.station_entry);
      }
      ASSERT_LE(f.v, c.SafeSpeed(f.x, limit) + 1e-6) << PolicyName(policy) << " t=" << f.t;
    }
  }
}

// @verifies REQ-FC-003 REQ-FC-005 REQ-FC-006 REQ-FC-008
TEST(Simulation, LateLeaderWithinCeilingsAndSteeredToRouteClear) {
  const Corridor c(Up(), kS1, kS3, D2Train(), Case::kSpeedLimits);
  const Scenario sc = MakeScenario(c, 30.0);
  for (const Policy policy : {Policy::kMovingBlockBaseline, Policy::kFixedBlockBaseline, Policy::kControlled}) {
    const fc::Run r = Simulate(sc, policy);
    ASSERT_TRUE(r.follower_arrival.has_value()) << PolicyName(policy);
    EXPECT_LE(r.worst_excess, 1e-6) << PolicyName(policy);
    ExpectWithinCeilings(c, sc, r, policy);
  }
  const fc::Run ctrl = Simulate(sc, Policy::kControlled);
  const fc::Run base = Simulate(sc, Policy::kMovingBlockBaseline);
  // late by 30 s: the controlled follower stops at the outside stop, then passes the approach
  // point at the route-clear time and arrives earlier than the baseline
  EXPECT_TRUE(ctrl.stopped_outside);
  ASSERT_TRUE(ctrl.approach_passed.has_value());
  EXPECT_NEAR(*ctrl.approach_passed, ctrl.route_clear, 0.5);
  EXPECT_NEAR(ctrl.approach_passed_speed, sc.approach.v, 0.3);
  EXPECT_LT(*ctrl.follower_arrival, *base.follower_arrival);
}

// @verifies REQ-FC-010
TEST(Supervision, OverridesAnAggressiveFollowerCommand) {
  // The follower asks for full traction 60 m before its stop limit at 60 km/h; the runtime
  // supervision (br::PatternCalculator, br::Supervisor) on the same state brakes, and the
  // applied command is its brake, not the traction.
  const offline::TrainType& type = D2Type();
  auto created = br::PatternCalculator::Create(offline::ToTrainData(type), br::DefaultSupervisionParams());
  ASSERT_EQ(created.error, br::CreateError::kNone);
  br::PatternCalculator& calc = *created.calculator;
  ASSERT_EQ(calc.SetProfile(offline::GradientProfile(Up()), offline::PermittedProfile(Up(), type.MaxSpeedMmS())).verdict,
            br::ProfileVerdict::kAccept);
  const std::int64_t v = 16'667;  // 60 km/h
  const br::Evaluation e = calc.Evaluate({1'000'000, 0, 0, v, false}, 1'060'000);
  ASSERT_EQ(e.status, br::EvalStatus::kOk);
  br::Supervisor sup;
  const br::Decision d = sup.Step(e.speeds, {});
  ASSERT_NE(d.level, br::BrakeLevel::kNone);
  const offline::Control applied = ApplySupervision(D2Train().perf.accel_mps2, d, D2Train());
  EXPECT_EQ(applied.traction_mps2, 0.0);
  EXPECT_TRUE(applied.emergency || applied.brake_mps2 > 0.0);
  // without a brake level the follower's command passes unchanged; a stronger follower brake
  // is kept under a mild supervision brake
  EXPECT_EQ(ApplySupervision(0.5, br::Decision{}, D2Train()).traction_mps2, 0.5);
  br::Decision mild;
  mild.level = br::BrakeLevel::k4N;
  EXPECT_DOUBLE_EQ(ApplySupervision(-0.9, mild, D2Train()).brake_mps2, 0.9);
  br::Decision eb;
  eb.level = br::BrakeLevel::kEmergency;
  EXPECT_TRUE(ApplySupervision(0.8, eb, D2Train()).emergency);
}

// @verifies REQ-FC-011
TEST(Study, RefusesATimetableItCannotUse) {
  lc::analysis::Timetable tt = lc::analysis::LoadTimetable(testing::GenDir() / "timetables" / "d2_urban_line.json");
  const std::map<std::string, offline::TrainType> trains{{"emu10_d2", D2Type()}};
  StudyInput in{&D2Line(), &tt, &trains, {0.0}};
  tt.services[1].stops[0].station = "S9";
  testing::ExpectInputError([&] { RunStudy(in); }, tt.file, {"services[1]", "S9"});
  tt.services.pop_back();
  testing::ExpectInputError([&] { RunStudy(in); }, tt.file, {"services", "two services"});
  testing::ExpectInputError(
      [] { lc::analysis::ParseTimetable(R"({"schema": "railproof/timetable-json/1"})", "tt.json"); }, "tt.json",
      {"missing key"});
}

}  // namespace
}  // namespace railproof::fc
