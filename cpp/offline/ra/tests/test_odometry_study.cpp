// Unit tests of the offline odometry study (analysis/odometry_study.hpp): the margin table
// at hand-computed points of the D1 error model, the former method's extension, the
// clearing-time formula, the train types' re-adhesion margins against the error model, and
// the run analysis (episodes, event matching, error against the bound, envelope check) on
// synthetic recorded runs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "railproof/testing/gen_data.hpp"
#include "railproof/ra/analysis/odometry_study.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::ra::analysis {
namespace {

using ra::Mode;
using ra::StopReason;
using testing::GenDir;
using testing::Train;

// D1 error model by hand: 1/2 (0.021 + 0.015 + G sin(w t) + G g/1000) t^2, G = 9.807.
//   16 permille, 32 s, 0.025 deg/s: sin(0.8 deg) = 0.0139622, G sin = 0.136927,
//   G g = 0.156912, Da = 0.329839 m/s^2, Dd = 0.329839 * 512 = 168.878 m (D1: about 169 m)
// @verifies REQ-RA-008
TEST(OdometryStudyMargins, ErrorModelAtHandComputedPoints) {
  EXPECT_NEAR(ImuMarginM(32.0, 16.0, 0.025), 168.8776, 1e-3);
  // 15.9 permille, 20 s, 0.0025 deg/s (emu3_d1 reference): 40.0979 m
  EXPECT_NEAR(ImuMarginM(20.0, 15.9, 0.0025), 40.0979, 1e-3);
  // level, 3 s, 0.0025 deg/s: 0.5 * (0.036 + 9.807 sin(0.0075 deg)) * 9 = 0.167777 m
  EXPECT_NEAR(ImuMarginM(3.0, 0.0, 0.0025), 0.167777, 1e-5);
  // 35 permille, 32 s, 0.025 deg/s: 264.280 m (the largest entry of the table)
  EXPECT_NEAR(ImuMarginM(32.0, 35.0, 0.025), 264.2801, 1e-3);
}

// @verifies REQ-RA-008
// @verifies REQ-RA-009
TEST(OdometryStudyMargins, TableCoversTheStudyGridAtBothRateErrors) {
  const auto times = StudyTimesS();
  const auto grads = StudyGradientsPermille();
  EXPECT_EQ(times, (std::vector<double>{3, 5, 10, 15, 20, 25, 32}));
  EXPECT_EQ(grads, (std::vector<double>{0, 10, 16, 25, 35}));
  EXPECT_DOUBLE_EQ(RateErrorFullDegS(), 0.025);
  EXPECT_DOUBLE_EQ(RateErrorTenthDegS(), 0.0025);
  const auto rows = MarginTable(times, grads, D1VehicleBounds());
  ASSERT_EQ(rows.size(), times.size() * grads.size());
  const MarginTableRow& r = rows[6 * grads.size() + 2];  // 32 s, 16 permille
  EXPECT_EQ(r.t_max_s, 32.0);
  EXPECT_EQ(r.gradient_permille, 16.0);
  EXPECT_NEAR(r.imu_margin_full_m, 168.8776, 1e-3);
  EXPECT_LT(r.imu_margin_tenth_m, r.imu_margin_full_m);
  // monotone in time and gradient
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    if (rows[i].t_max_s == rows[i + 1].t_max_s) {
      EXPECT_LT(rows[i].imu_margin_tenth_m, rows[i + 1].imu_margin_tenth_m);
      EXPECT_LT(rows[i].baseline.worst_m, rows[i + 1].baseline.worst_m);
    }
  }
}

// Former method (D1 §3.4.3, D1's figures 2.1/3.3 km/h/s and 3.5/5.2 km/h/s), 10 s: slip
// front 3.3 km/h/s, rear coasting: 0.916667 / 2 * 100 = 45.8333 m; slide front coasting,
// rear 5.2 km/h/s: 1.444444 / 2 * 100 = 72.2222 m, braked (-0.972222 + 1.444444) / 2 * 100 =
// 23.6111 m. At 25 permille each side adds G g = 0.245175 m/s^2: slip (0.916667 + 0.49035)
// * 50 = 70.3508 m.
// @verifies REQ-RA-014
TEST(OdometryStudyMargins, BaselineExtensionFormula) {
  const VehicleAccelBounds b = D1VehicleBounds();
  EXPECT_NEAR(b.accel_min, 2.1 / 3.6, 1e-12);
  EXPECT_NEAR(b.accel_max, 3.3 / 3.6, 1e-12);
  EXPECT_NEAR(b.decel_min, 3.5 / 3.6, 1e-12);
  EXPECT_NEAR(b.decel_max, 5.2 / 3.6, 1e-12);
  const BaselineExtension level = BaselineExtensionM(10.0, 0.0, b);
  EXPECT_NEAR(level.slip_m, 3.3 / 3.6 * 50.0, 1e-9);
  EXPECT_NEAR(level.slide_m, 5.2 / 3.6 * 50.0, 1e-9);
  EXPECT_NEAR(level.slide_braked_m, (5.2 - 3.5) / 3.6 * 50.0, 1e-9);
  EXPECT_NEAR(level.worst_m, 5.2 / 3.6 * 50.0, 1e-9);
  EXPECT_NEAR(level.slip_m, 45.8333, 1e-4);
  const BaselineExtension steep = BaselineExtensionM(10.0, 25.0, b);
  EXPECT_NEAR(steep.slip_front_accel, 3.3 / 3.6 + 0.245175, 1e-9);
  EXPECT_NEAR(steep.slip_rear_accel, -0.245175, 1e-9);
  EXPECT_NEAR(steep.slip_m, 70.3508, 1e-4);
  EXPECT_NEAR(steep.slide_m, (0.245175 + 5.2 / 3.6 + 0.245175) * 50.0, 1e-9);
  // symmetric in the sign of the gradient (steepest magnitude)
  EXPECT_DOUBLE_EQ(BaselineExtensionM(10.0, -25.0, b).slip_m, steep.slip_m);
}

// From rest at 0.58 m/s^2: 60 m train with 40.2 m margins on both sides:
// sqrt(2 * 140.4 / 0.58) - sqrt(2 * 60 / 0.58) = 22.00313 - 14.38390 = 7.61924 s.
// @verifies REQ-RA-009
TEST(OdometryStudyMargins, ClearingTimeFormula) {
  EXPECT_DOUBLE_EQ(ClearingAccelMS2(), 0.58);
  EXPECT_NEAR(ClearingTimeS(60.0, 0.58), 14.383899, 1e-6);
  EXPECT_NEAR(ClearingCostS(60.0, 40.2, 0.58), 7.619236, 1e-6);
  EXPECT_NEAR(ClearingCostS(40.0, 58.5, 0.58), 11.523155, 1e-6);
  EXPECT_DOUBLE_EQ(ClearingCostS(200.0, 0.0, 0.58), 0.0);
  EXPECT_THROW((void)ClearingTimeS(10.0, 0.0), offline::InputError);
}

// Every train type's readhesion_margin_mm covers the error model at 20 s, 0.0025 deg/s and
// the steepest gradient of its line (ASM-024: 15.9, 25, 30 permille; 40.098, 57.947,
// 67.754 m rounded up).
// @verifies REQ-RA-009
TEST(OdometryStudyMargins, TrainMarginsCoverTheErrorModel) {
  struct Expect {
    const char* train;
    const char* line;
    std::int64_t gradient_x10;
    std::int64_t model_mm;
  };
  for (const Expect& e : {Expect{"emu3_d1", "d1_test_line", 159, 40098}, Expect{"dmu2_d4", "d4_local_line", 250, 57947},
                          Expect{"emu10_d2", "d2_urban_line", 300, 67754}}) {
    SCOPED_TRACE(e.train);
    const TrainType t = Train(e.train);
    const auto line_path = LineOfTrain(t, GenDir() / "lines");
    EXPECT_EQ(line_path.stem().string(), e.line);
    const TrainMarginCheck c = CheckTrainMargin(t, offline::LoadLine(line_path));
    EXPECT_EQ(c.steepest_gradient_permille_x10, e.gradient_x10);
    EXPECT_EQ(c.max_compensation_ms, 20000);
    EXPECT_EQ(c.rate_error_udeg_s, 2500);
    EXPECT_EQ(c.error_model_mm, e.model_mm);
    EXPECT_TRUE(c.meets_target);
    EXPECT_EQ(c.headroom_mm, t.readhesion_margin_mm - e.model_mm);
  }
  // a margin below the model fails the row
  TrainType weak = Train("emu3_d1");
  weak.readhesion_margin_mm = 40000;
  const TrainMarginCheck c = CheckTrainMargin(weak, offline::LoadLine(LineOfTrain(weak, GenDir() / "lines")));
  EXPECT_FALSE(c.meets_target);
  EXPECT_EQ(c.headroom_mm, 40000 - 40098);
}

// @verifies REQ-RA-009
TEST(OdometryStudyMargins, TrainWithoutLineIsRejected) {
  TrainType t = Train("emu3_d1");
  t.name = "emu3_d9";
  EXPECT_THROW((void)LineOfTrain(t, GenDir() / "lines"), offline::InputError);
  t.name = "emu3_d2";  // d2 line's design train is 200 m, not 60 m
  EXPECT_THROW((void)LineOfTrain(t, GenDir() / "lines"), offline::InputError);
}

// ---- synthetic recorded runs ------------------------------------------------------------

// 10 m/s, front at 1000 m + 1 m per cycle, exact odometry with a 1 m envelope. Detection at
// cycle 40 (start point age 25, second start point 50), compensation until cycle 59,
// candidate 0 adopted in cycle 60 with the front 0.2 m ahead of the truth from then on.
std::vector<StudyCycle> SyntheticRun() {
  std::vector<StudyCycle> run(100);
  for (std::size_t k = 0; k < run.size(); ++k) {
    StudyCycle& c = run[k];
    c.time_ms = static_cast<std::int64_t>(k) * 100;
    c.true_front_m = 1000.0 + static_cast<double>(k);
    c.true_speed_m_s = 10.0;
    c.gradient_permille = k < 50 ? 5.0 : 10.0;
    c.out.time_ms = c.time_ms;
    c.out.front_mm = 1'000'000 + static_cast<std::int64_t>(k) * 1000 + (k >= 60 ? 200 : 0);
    c.out.front_error_mm = 1000;
    c.out.rear_error_mm = 1000;
    c.out.position_valid = true;
    c.machine.mode = Mode::kTg;
    if (k >= 40 && k < 60) {
      c.machine.mode = Mode::kCompensating;
      const auto dk = static_cast<std::int32_t>(k - 40);
      c.machine.candidates[0] = {true, 25 + dk, 0};
      c.machine.candidates[1] = {true, 50 + dk, 0};
      c.machine.max_compensation_cycles = 200;
    }
    if (k >= 40) {
      c.out.start_age_cycles = 25;
    }
  }
  run[40].machine.detected = true;
  run[60].machine.adopted = 0;
  return run;
}

// @verifies REQ-RA-008
// @verifies REQ-RA-010
TEST(OdometryStudyRun, EpisodeAndErrorAgainstTheBound) {
  const auto run = SyntheticRun();
  const auto eps = FindEpisodes(run);
  ASSERT_EQ(eps.size(), 1U);
  const Episode& ep = eps[0];
  EXPECT_EQ(ep.detect, 40U);
  EXPECT_EQ(ep.end, 60U);
  EXPECT_EQ(ep.outcome, EpisodeOutcome::kAdopted);
  EXPECT_EQ(ep.adopted, 0);
  EXPECT_EQ(ep.start_age_cycles, 25);
  EXPECT_EQ(ep.comp_cycles, 45);  // 25 + 19 compensating cycles after detection + adoption
  std::vector<double> tg(run.size());
  for (std::size_t k = 0; k < run.size(); ++k) {
    tg[k] = 1.1 * static_cast<double>(k);  // TG overreads by 10 % (slip)
  }
  const EpisodeError e = EvaluateEpisode(run, ep, 0.0025, tg);
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.start, 15U);
  EXPECT_EQ(e.stop, 60U);
  EXPECT_NEAR(e.comp_time_s, 4.5, 1e-12);
  EXPECT_EQ(e.gradient_permille, 10.0);  // steepest over cycles 15..60
  EXPECT_NEAR(e.true_distance_m, 45.0, 1e-9);
  EXPECT_NEAR(e.odometry_distance_m, 45.2, 1e-9);
  EXPECT_NEAR(e.error_m, 0.2, 1e-9);
  const double bound = ImuMarginM(4.5, 10.0, 0.0025);
  EXPECT_NEAR(e.bound_m, bound, 1e-12);
  EXPECT_NEAR(e.ratio, 0.2 / bound, 1e-9);
  EXPECT_NEAR(e.tg_error_m, 4.5, 1e-9);
  EXPECT_FALSE(e.balise_in_interval);
  EXPECT_EQ(e.worst_ratio_during, 0.0);  // exact during the compensation
}

// A balise fix inside the compensation interval re-established the position base: the error
// is taken from the fix (the nominal front before it, here 5 m off, is not the base the
// compensation continued from).
// @verifies REQ-RA-008
TEST(OdometryStudyRun, BaliseFixInsideTheIntervalIsTheReference) {
  auto run = SyntheticRun();
  for (std::size_t k = 15; k < 30; ++k) {
    run[k].out.front_mm += 5000;  // e.g. the front of a stopped odometry before the fix
  }
  run[30].balise = true;
  EXPECT_EQ(ErrorReference(run, 15, 60), 30U);
  EXPECT_EQ(ErrorReference(run, 31, 60), 31U);
  run[45].balise = true;
  run[45].out.position_valid = false;  // not accepted: no reference
  EXPECT_EQ(ErrorReference(run, 15, 60), 30U);
  const auto eps = FindEpisodes(run);
  const EpisodeError e = EvaluateEpisode(run, eps.at(0), 0.0025, {});
  ASSERT_TRUE(e.valid);
  EXPECT_TRUE(e.balise_in_interval);
  EXPECT_EQ(e.start, 15U);
  EXPECT_EQ(e.reference, 30U);
  EXPECT_NEAR(e.true_distance_m, 30.0, 1e-9);
  EXPECT_NEAR(e.error_m, 0.2, 1e-9);
  EXPECT_NEAR(e.bound_m, ImuMarginM(4.5, 10.0, 0.0025), 1e-12);  // still the full compensation time
}

// @verifies REQ-RA-007
TEST(OdometryStudyRun, TimeoutEpisode) {
  auto run = SyntheticRun();
  run[60].machine = {};
  run[60].machine.mode = Mode::kStopped;
  run[60].machine.stop_reason = StopReason::kMaxCompensationTime;
  run[60].machine.stop_demand = true;
  run[60].machine.position_valid = false;
  run[60].out.position_valid = false;
  const auto eps = FindEpisodes(run);
  ASSERT_EQ(eps.size(), 1U);
  EXPECT_EQ(eps[0].outcome, EpisodeOutcome::kTimeout);
  EXPECT_EQ(eps[0].adopted, -1);
  EXPECT_EQ(eps[0].comp_cycles, 44);  // candidate 0 in the last compensating cycle 59
  const EpisodeError e = EvaluateEpisode(run, eps[0], 0.0025, {});
  ASSERT_TRUE(e.valid);
  EXPECT_EQ(e.stop, 59U);
  EXPECT_EQ(e.start, 15U);
  EXPECT_NEAR(e.error_m, 0.0, 1e-9);
}

// @verifies REQ-RA-003
TEST(OdometryStudyRun, EventMatcher) {
  const auto run = SyntheticRun();
  const auto eps = FindEpisodes(run);
  const std::vector<TruthEvent> events{
      {1, "slip", 3000, 4500},   // detected at 4000 ms
      {2, "slip", 4500, 5000},   // starts while compensating: the same episode
      {3, "slide", 8500, 9000},  // no detection afterwards
      {4, "slide", 200, 300},    // ended long before the detection (window 3.4 s)
  };
  EXPECT_EQ(DefaultMatchWindowMs(), 3400);
  const auto m = MatchEvents(events, run, eps, DefaultMatchWindowMs());
  EXPECT_EQ(m, (std::vector<int>{0, 0, -1, -1}));
  // a longer window attributes the early event to the episode
  EXPECT_EQ(MatchEvents(events, run, eps, 4000)[3], 0);
}

// @verifies REQ-RA-012
TEST(OdometryStudyRun, EnvelopeCheckCatchesAViolation) {
  auto run = SyntheticRun();
  EnvelopeCheck c = CheckEnvelope(run);
  EXPECT_EQ(c.cycles_checked, 100);
  EXPECT_EQ(c.violations, 0);
  EXPECT_NEAR(c.min_rear_slack_m, 0.8, 1e-9);  // front 0.2 m ahead after adoption
  EXPECT_NEAR(c.min_front_slack_m, 1.0, 1e-9);
  // front 1.5 m ahead of the truth with a 1 m rear-side error: truth 0.5 m outside
  run[80].out.front_mm += 1300;
  // front 1.25 m behind the truth with a 1 m front error: 0.25 m outside
  run[90].out.front_mm -= 1450;
  // an invalid position is not checked
  run[95].out.position_valid = false;
  run[95].out.front_mm += 1'000'000;
  c = CheckEnvelope(run);
  EXPECT_EQ(c.cycles_checked, 99);
  EXPECT_EQ(c.violations, 2);
  EXPECT_NEAR(c.worst_excess_m, 0.5, 1e-9);
  EXPECT_EQ(c.first_violation_ms, 8000);
  EXPECT_NEAR(c.min_front_slack_m, -0.25, 1e-9);
  EXPECT_NEAR(c.min_rear_slack_m, -0.5, 1e-9);
}

}  // namespace
}  // namespace railproof::ra::analysis
