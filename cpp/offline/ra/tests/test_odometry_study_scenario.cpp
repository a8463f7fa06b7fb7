// End-to-end unit tests of the odometry study on real Box2D wheel-rail runs
// (analysis/odometry_study.hpp StudyScenario): a short slip at 40 km/h on a contaminated
// patch and a scenario with injected sensor faults. They check the study's bookkeeping
// against an independent recomputation from the recorded cycles and the simulator's truth
// (phase grouping, detection, compensation interval, error and bound, envelope count, the
// three replayed configurations, the sensor-fault check), not the accuracy of the odometry,
// which is the study's result in the pipeline.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "railproof/ra/analysis/odometry_study.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {
namespace {

// 40 km/h with a light notch; full notch from 10 s; a 30 m patch at one fifth of the dry
// adhesion at 300 m makes the axles slip (no wheel-slip protection).
constexpr const char* kShortSlip = R"({
  "schema": "railproof/wheelrail-scenario/1",
  "name": "unit_short_slip",
  "description": "short slip at 40 km/h on a contaminated patch",
  "requirements": ["REQ-RA-003", "REQ-RA-008"],
  "duration_s": 40,
  "seed": 5,
  "initial_front_m": 100,
  "initial_speed_kmh": 40, "start": "lead_in",
  "vertical": {"begin_m": 0, "end_m": 1500, "gradients": [{"from_m": 0, "permille": 0}]},
  "rail": {"condition": "dry", "zones": [{"begin_m": 300, "end_m": 330, "factor": 0.2}]},
  "driver": [{"t_s": 0, "traction": 0.2, "ramp_s": 0}, {"t_s": 10, "traction": 1.0, "ramp_s": 1}]
})";

constexpr const char* kFaults = R"({
  "schema": "railproof/wheelrail-scenario/1",
  "name": "unit_faults",
  "description": "IMU NaN at 10 s, TG burst at 15 s",
  "requirements": ["REQ-RA-013"],
  "duration_s": 20,
  "initial_front_m": 100,
  "initial_speed_kmh": 40, "start": "lead_in",
  "vertical": {"begin_m": 0, "end_m": 1500, "gradients": [{"from_m": 0, "permille": 0}]},
  "rail": {"condition": "dry"},
  "driver": [{"t_s": 0, "traction": 0.3, "ramp_s": 0}],
  "faults": [{"type": "imu_nan", "from_s": 10.0, "to_s": 10.5}, {"type": "tg_burst", "from_s": 15.0, "to_s": 15.1}]
})";

const ScenarioStudy& ShortSlip() {
  static const ScenarioStudy st = StudyScenario(ra::analysis::ParseWheelRailScenario(kShortSlip, "unit_short_slip.json"));
  return st;
}

// @verifies REQ-RA-003
// @verifies REQ-RA-010
// @verifies REQ-RA-014
TEST(OdometryStudyScenario, ThreeConfigurationsOverOneSimulatedRun) {
  const ScenarioStudy& st = ShortSlip();
  const std::size_t n = st.sim.cycles.size();
  // the lead-in from rest (REQ-RA-015), then the scenario's 40 s
  ASSERT_GT(st.sim.lead_in_ms, 0);
  ASSERT_EQ(n, static_cast<std::size_t>((st.sim.lead_in_ms + 40'000) / 100));
  EXPECT_EQ(st.primary.cycles.size(), n);
  EXPECT_EQ(st.single.cycles.size(), n);
  EXPECT_EQ(st.baseline.cycles.size(), n);
  EXPECT_EQ(st.primary.config.method, ra::Method::kImu);
  EXPECT_EQ(st.primary.config.start_points, 2);
  EXPECT_EQ(st.single.config.method, ra::Method::kImu);
  EXPECT_EQ(st.single.config.start_points, 1);
  EXPECT_EQ(st.baseline.config.method, ra::Method::kMaxMinAcceleration);
  EXPECT_EQ(st.primary.label, "imu_2sp");
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(st.primary.cycles[k].time_ms, st.sim.truth[k].time_ms);
    EXPECT_EQ(st.primary.cycles[k].true_front_m, st.sim.truth[k].front_m);
  }
  // the per-axle events grouped into phases: every event in exactly one phase, phases ordered
  std::vector<int> seen(st.sim.events.size(), 0);
  for (std::size_t p = 0; p < st.phases.size(); ++p) {
    for (const int e : st.phases[p].events) {
      ++seen[static_cast<std::size_t>(e)];
      EXPECT_GE(st.sim.events[static_cast<std::size_t>(e)].start_ms, st.phases[p].start_ms);
      EXPECT_LE(st.sim.events[static_cast<std::size_t>(e)].end_ms, st.phases[p].end_ms);
    }
    if (p > 0) {
      EXPECT_GT(st.phases[p].start_ms, st.phases[p - 1].end_ms + kPhaseGapMs);
    }
  }
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int c) { return c == 1; }));
  // a slip phase on the TG axle after the notch-up, detected by every configuration
  const auto it = std::find_if(st.phases.begin(), st.phases.end(),
                               [](const SlipPhase& p) { return p.tg_axle && p.kind == "slip"; });
  ASSERT_NE(it, st.phases.end());
  const auto p = static_cast<std::size_t>(it->id);
  EXPECT_GT(it->start_ms, st.sim.lead_in_ms + 10000);
  for (const StudyRun* r : {&st.primary, &st.single, &st.baseline}) {
    SCOPED_TRACE(r->label);
    const int ep = r->event_episode[p];
    ASSERT_GE(ep, 0);
    const std::int64_t t = r->cycles[r->episodes[static_cast<std::size_t>(ep)].detect].time_ms;
    EXPECT_GE(t, it->start_ms);
    EXPECT_LE(t, it->end_ms + DefaultMatchWindowMs());
    EXPECT_EQ(r->episode_event[static_cast<std::size_t>(ep)], static_cast<int>(p));
  }
  EXPECT_EQ(st.baseline.baseline.size(), st.baseline.episodes.size());
  EXPECT_TRUE(st.primary.baseline.empty());
}

// @verifies REQ-RA-005
// @verifies REQ-RA-008
TEST(OdometryStudyScenario, ErrorAndBoundRecomputedFromTheRecord) {
  const ScenarioStudy& st = ShortSlip();
  const StudyRun& r = st.primary;
  ASSERT_FALSE(r.episodes.empty());
  const double rate = static_cast<double>(r.config.imu_rate_error_udeg_s) / 1e6;
  EXPECT_DOUBLE_EQ(rate, 0.0025);
  int adopted = 0;
  double worst = 0.0;
  for (std::size_t i = 0; i < r.episodes.size(); ++i) {
    const Episode& ep = r.episodes[i];
    const EpisodeError& e = r.errors[i];
    if (ep.outcome != EpisodeOutcome::kAdopted) {
      continue;
    }
    ++adopted;
    ASSERT_TRUE(e.valid);
    // compensation time: start-point age (+ spacing for the second) + cycles to re-adhesion
    const auto spacing = static_cast<std::int32_t>(
        ep.adopted == 1 ? params::ra::parallel_spacing_ms / params::ra::cycle_ms : 0);
    EXPECT_EQ(ep.comp_cycles, ep.start_age_cycles + spacing + static_cast<std::int32_t>(ep.end - ep.detect));
    ASSERT_EQ(e.stop, ep.end);
    ASSERT_EQ(e.start, ep.end - static_cast<std::size_t>(ep.comp_cycles));
    const double odo_dist = static_cast<double>(r.cycles[e.stop].out.front_mm - r.cycles[e.start].out.front_mm) / 1000.0;
    const double true_dist = st.sim.truth[e.stop].front_m - st.sim.truth[e.start].front_m;
    EXPECT_NEAR(e.error_m, odo_dist - true_dist, 1e-9);
    EXPECT_NEAR(e.tg_error_m,
                (st.sim.truth[e.stop].tg_distance_m - st.sim.truth[e.start].tg_distance_m) - true_dist, 1e-9);
    EXPECT_EQ(e.gradient_permille, 0.0);  // level scenario
    EXPECT_NEAR(e.bound_m, ra::ErrorBoundM(e.comp_time_s, 0.0, rate), 1e-12);
    EXPECT_NEAR(e.ratio, std::abs(e.error_m) / e.bound_m, 1e-12);
    worst = std::max(worst, e.ratio);
    // the compensation removed most of the TG error of the slip
    EXPECT_LT(std::abs(e.error_m), std::abs(e.tg_error_m));
  }
  EXPECT_GE(adopted, 1);
  EXPECT_DOUBLE_EQ(r.worst_ratio, worst);
}

// @verifies REQ-RA-012
TEST(OdometryStudyScenario, EnvelopeCountAndVerdictAreConsistent) {
  const ScenarioStudy& st = ShortSlip();
  for (const StudyRun* r : {&st.primary, &st.single, &st.baseline}) {
    int checked = 0, outside = 0;
    for (const StudyCycle& c : r->cycles) {
      if (!c.out.position_valid) {
        continue;
      }
      ++checked;
      const double lo = static_cast<double>(c.out.front_mm - c.out.rear_error_mm) / 1000.0;
      const double hi = static_cast<double>(c.out.front_mm + c.out.front_error_mm) / 1000.0;
      outside += (c.true_front_m < lo || c.true_front_m > hi) ? 1 : 0;
    }
    EXPECT_EQ(r->envelope.cycles_checked, checked) << r->label;
    EXPECT_EQ(r->envelope.violations, outside) << r->label;
  }
  const bool expect_pass =
      st.primary.worst_ratio <= 1.0 && st.primary.envelope.violations == 0 && st.single.envelope.violations == 0;
  EXPECT_EQ(st.Pass(), expect_pass);
  EXPECT_EQ(st.failures.empty(), std::all_of(st.checks.begin(), st.checks.end(), [](const ScenarioCheck& c) {
              return c.ok;
            }));
  // plots: four stacked panels
  const std::string svg = ScenarioPlotSvg(st);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0U);
  std::size_t panels = 0;
  for (std::size_t pos = svg.find("<svg y=\""); pos != std::string::npos; pos = svg.find("<svg y=\"", pos + 1)) {
    ++panels;
  }
  EXPECT_EQ(panels, 4U);
}

// @verifies REQ-RA-013
TEST(OdometryStudyScenario, SensorFaultsGiveTheTypedRejectionAndStop) {
  EXPECT_EQ(ExpectedInputError(ra::analysis::SensorFaultKind::kImuNan), ra::InputError::kImuNotFinite);
  EXPECT_EQ(ExpectedInputError(ra::analysis::SensorFaultKind::kTgBurst), ra::InputError::kTgImplausibleRate);
  EXPECT_EQ(ExpectedInputError(ra::analysis::SensorFaultKind::kTgStuck), ra::InputError::kNone);
  const ScenarioStudy st = StudyScenario(ra::analysis::ParseWheelRailScenario(kFaults, "unit_faults.json"));
  int fault_checks = 0;
  for (const ScenarioCheck& c : st.checks) {
    if (c.name.rfind("sensor_fault_", 0) == 0) {
      ++fault_checks;
      EXPECT_TRUE(c.ok) << c.name << ": " << c.detail;
    }
  }
  EXPECT_EQ(fault_checks, 2);
  // from the IMU failure (10 s after the lead-in) on the position stays invalid (no balise)
  for (const StudyCycle& c : st.primary.cycles) {
    if (c.time_ms >= st.sim.lead_in_ms + 10000) {
      EXPECT_FALSE(c.out.position_valid) << c.time_ms;
      EXPECT_TRUE(c.out.stop_demand) << c.time_ms;
    }
  }
  // a fault whose window holds no cycle instant is reported as never active
  ra::analysis::WheelRailScenario sc = ra::analysis::ParseWheelRailScenario(kFaults, "unit_faults.json");
  sc.faults.resize(1);
  sc.faults[0].from_s = 10.01;
  sc.faults[0].to_s = 10.05;
  const ScenarioStudy never = StudyScenario(sc);
  ASSERT_FALSE(never.Pass());
  EXPECT_NE(never.failures.front().find("never active"), std::string::npos);
}

}  // namespace
}  // namespace railproof::ra::analysis
