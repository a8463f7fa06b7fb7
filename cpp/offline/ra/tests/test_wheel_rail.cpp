// Unit tests of the wheel-rail simulator (cpp/src/sim/wheel_rail*.cpp): adhesion law
// (ASM-027, hand-computed values), vehicle physics on gradients, slips in the truth, IMU and
// TG streams, faults, determinism, the scenario loader and the odometry sections.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"
#include "railproof/testing/input_error.hpp"

namespace railproof::ra::analysis {
namespace {

constexpr double kG = kWheelRailGravity;

// A short scenario on one constant gradient; ideal IMU unless a test enables it.
nlohmann::json BaseScenario(double permille = 0.0) {
  return nlohmann::json{
      {"schema", "railproof/wheelrail-scenario/1"},
      {"name", "unit"},
      {"requirements", {"REQ-RA-001"}},
      {"duration_s", 10},
      {"seed", 7},
      {"initial_front_m", 500},
      {"vertical", {{"begin_m", 0}, {"end_m", 3000}, {"gradients", {{{"from_m", 0}, {"permille", permille}}}}}},
      {"rail", {{"condition", "dry"}}},
      {"imu", {{"enabled", false}}},
      {"driver", {{{"t_s", 0}, {"brake", 1.0}, {"ramp_s", 0}}}}};
}

WheelRailScenario Scenario(const nlohmann::json& j) { return ParseWheelRailScenario(j.dump(), "unit.json"); }

// Resistance off: the physics checks compare with gravity alone.
void NoResistance(nlohmann::json& j) {
  j["vehicle"]["resistance_a_n"] = 0;
  j["vehicle"]["resistance_b_ns_m"] = 0;
  j["vehicle"]["resistance_c_ns2_m2"] = 0;
}

// Mass factor of the vehicle: translational / (translational + rotating) mass.
double MassFactor(const VehicleSpec& v) {
  const double m = v.body_mass_kg + 2 * v.bogie_mass_kg + 4 * v.wheelset_mass_kg;
  const double r = v.wheel_diameter_m / 2;
  return m / (m + 4 * v.wheelset_inertia_kgm2 / (r * r));
}

double CycleMean(const ra::CycleInput& c, double ra::ImuSample::*f) {
  double s = 0.0;
  for (int k = 0; k < c.imu_count; ++k) {
    s += c.imu[static_cast<std::size_t>(k)].*f;
  }
  return s / c.imu_count;
}

// Mean of a cycle-mean IMU value over cycles [from, to).
double ImuMean(const WheelRailRun& r, std::size_t from, std::size_t to, double ra::ImuSample::*f) {
  double s = 0.0;
  for (std::size_t i = from; i < to; ++i) {
    s += CycleMean(r.cycles[i], f);
  }
  return s / static_cast<double>(to - from);
}

// ---- adhesion law --------------------------------------------------------------------------

// @verifies REQ-RA-003
TEST(WheelRailAdhesion, CurtiusKnifflerHandComputed) {
  // 7.5 / (v + 44) + 0.161
  EXPECT_NEAR(CurtiusKnifflerMu(0.0), 7.5 / 44.0 + 0.161, 1e-12);  // 0.3314545
  EXPECT_NEAR(CurtiusKnifflerMu(0.0), 0.3314545, 1e-7);
  EXPECT_NEAR(CurtiusKnifflerMu(36.0), 0.25475, 1e-12);     // 7.5/80 = 0.09375
  EXPECT_NEAR(CurtiusKnifflerMu(100.0), 0.2130833, 1e-7);   // 7.5/144 = 0.0520833
  EXPECT_NEAR(CurtiusKnifflerMu(-36.0), CurtiusKnifflerMu(36.0), 1e-15);
  const AdhesionLaw law;
  // 10 m/s = 36 km/h, at the peak creep: dry 0.25475, wet 0.55 x = 0.1401125
  EXPECT_NEAR(AdhesionCoefficient(0.01, 10.0, 1.0, law), 0.25475, 1e-12);
  EXPECT_NEAR(AdhesionCoefficient(0.01, 10.0, law.wet_factor, law), 0.1401125, 1e-12);
}

TEST(WheelRailAdhesion, CreepCurveShape) {
  const AdhesionLaw law;
  EXPECT_DOUBLE_EQ(CreepCurve(0.0, law), 0.0);
  EXPECT_NEAR(CreepCurve(0.005, law), 0.5, 1e-12);    // linear rise
  EXPECT_NEAR(CreepCurve(0.01, law), 1.0, 1e-12);     // peak at 1 %
  EXPECT_NEAR(CreepCurve(0.105, law), 0.85, 1e-12);   // halfway down: 1 - 0.3 * 0.095 / 0.19
  EXPECT_NEAR(CreepCurve(0.20, law), 0.70, 1e-12);    // 70 % of the peak at 20 %
  EXPECT_NEAR(CreepCurve(1.0, law), 0.70, 1e-12);     // locked wheel slides at 70 %
  EXPECT_NEAR(CreepCurve(-0.005, law), -0.5, 1e-12);  // odd
  EXPECT_NEAR(CreepCurve(-0.3, law), -0.7, 1e-12);
  // monotone up to the peak, then falling
  double prev = 0.0;
  for (int k = 1; k <= 20; ++k) {
    const double c = 0.0005 * k;
    EXPECT_GT(CreepCurve(c, law), prev) << c;
    prev = CreepCurve(c, law);
  }
  for (int k = 11; k <= 200; ++k) {
    const double c = 0.001 * k;
    EXPECT_LT(CreepCurve(c, law), prev + 1e-12) << c;
    prev = CreepCurve(c, law);
  }
  // low-speed creep definition: the floor of 0.5 m/s
  EXPECT_NEAR(CreepOf(10.1, 10.0, law), 0.01, 1e-12);
  EXPECT_NEAR(CreepOf(0.005, 0.0, law), 0.01, 1e-12);
  EXPECT_NEAR(CreepOf(0.0, -0.25, law), 0.5, 1e-12);
}

// ---- vehicle physics ---------------------------------------------------------------------------

TEST(WheelRailPhysics, BrakedVehicleStaysOnSteepestGradient) {
  for (const double g : {35.0, -35.0}) {
    auto j = BaseScenario(g);
    j["duration_s"] = 20;
    const auto sc = Scenario(j);
    const auto run = SimulateWheelRail(sc);
    ASSERT_EQ(run.truth.size(), 200U);
    EXPECT_NEAR(run.truth.back().front_m, 500.0, 0.002) << g;  // held by static friction
    EXPECT_EQ(run.cycles.back().tg.pulses, 0) << g;
    EXPECT_TRUE(run.events.empty());
  }
}

TEST(WheelRailPhysics, UnbrakedVehicleRollsDownhill) {
  auto j = BaseScenario(20.0);
  NoResistance(j);
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  const auto sc = Scenario(j);
  const auto run = SimulateWheelRail(sc);
  // rolls backwards (down the rising gradient) with -G sin(alpha) x mass factor
  const double expected = -kG * std::sin(std::atan(0.020)) * MassFactor(sc.vehicle);
  const double v = run.truth.back().speed_mps;
  EXPECT_LT(v, 0.0);
  EXPECT_NEAR(v / 10.0, expected, 0.02 * std::fabs(expected));
}

TEST(WheelRailPhysics, CoastingAccelerationIsGravityComponent) {
  for (const double g : {-25.0, 15.0, 35.0}) {
    auto j = BaseScenario(g);
    NoResistance(j);
    j["initial_speed_kmh"] = 60;
    j["start"] = "in_motion";  // the simulator alone: the run begins in motion
    j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
    const auto sc = Scenario(j);
    const auto run = SimulateWheelRail(sc);
    const double expected = -kG * std::sin(std::atan(g / 1000.0)) * MassFactor(sc.vehicle);
    // mean acceleration over 2..10 s (after the first cycles)
    const double a = (run.truth.back().speed_mps - run.truth[19].speed_mps) / 8.0;
    EXPECT_NEAR(a, expected, 0.02 * std::fabs(expected) + 0.002) << g;
    // and roughly -G g / 1000 as the brief states it (mass factor about 0.92)
    EXPECT_NEAR(a, -kG * g / 1000.0, 0.1 * kG * std::fabs(g) / 1000.0) << g;
    EXPECT_TRUE(run.events.empty()) << g;
  }
}

// @verifies REQ-RA-003
TEST(WheelRailPhysics, TorqueBeyondAdhesionSlipsAndTruthReportsIt) {
  auto j = BaseScenario(0.0);
  j["duration_s"] = 12;
  j["rail"]["condition"] = "wet";
  j["initial_speed_kmh"] = 30;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  // wet at 30 km/h: mu_peak = 0.55 x (7.5/74 + 0.161) = 0.1443, about 12.5 kN per axle;
  // the motored axles demand 17 kN at full notch
  j["driver"] = {{{"t_s", 0}, {"traction", 0.3}, {"ramp_s", 0}},
                 {{"t_s", 3}, {"traction", 1.0}, {"ramp_s", 0.5}},
                 {{"t_s", 6}, {"traction", 0.0}, {"ramp_s", 0.5}}};
  const auto sc = Scenario(j);
  const auto run = SimulateWheelRail(sc);
  ASSERT_FALSE(run.events.empty());
  bool motored_slip = false;
  for (const auto& e : run.events) {
    EXPECT_EQ(e.kind, SlipKind::kSlip);
    EXPECT_TRUE(sc.vehicle.motored[static_cast<std::size_t>(e.axle)]) << e.axle;
    EXPECT_GE(e.start_ms, 3000);
    EXPECT_GT(e.peak_creep, sc.truth.event_creep);
    EXPECT_GE(e.end_ms - e.start_ms, 200);
    motored_slip = true;
  }
  EXPECT_TRUE(motored_slip);
  // the TG axle (1, motored) slips: the TG wheel runs ahead of the car
  const auto& t = run.truth[55];
  EXPECT_GT(t.tg_wheel_speed_mps, t.speed_mps * 1.02);
  // no slip before the notch rises
  for (std::size_t i = 0; i < 29; ++i) {
    EXPECT_LT(std::fabs(run.truth[i].creep[1]), 0.02) << i;
  }
}

TEST(WheelRailPhysics, WetPeakAdhesionIs55PercentOfDry) {
  // The highest adhesion used (creep force / normal force) when the demand exceeds it,
  // divided by the Curtius-Kniffler value at that speed.
  auto peak_ratio = [](const char* condition) {
    auto j = BaseScenario(0.0);
    j["duration_s"] = 8;
    j["rail"]["condition"] = condition;
    j["initial_speed_kmh"] = 20;
    j["start"] = "in_motion";  // the simulator alone: the run begins in motion
    j["vehicle"]["max_traction_force_n"] = 40000;
    j["vehicle"]["max_power_w"] = 2000000;
    j["driver"] = {{{"t_s", 0}, {"traction", 0.0}, {"ramp_s", 0}}, {{"t_s", 1}, {"traction", 1.0}, {"ramp_s", 6}}};
    const auto run = SimulateWheelRail(Scenario(j));
    double best = 0.0;
    for (const auto& t : run.truth) {
      const double mu = t.creep_force_n[0] / t.normal_force_n[0];
      best = std::max(best, mu / CurtiusKnifflerMu(t.speed_mps * 3.6));
    }
    return best;
  };
  const double dry = peak_ratio("dry");
  const double wet = peak_ratio("wet");
  EXPECT_NEAR(dry, 1.0, 0.03);
  EXPECT_NEAR(wet, 0.55, 0.02);
  EXPECT_NEAR(wet / dry, 0.55, 0.02);
}

// ---- sensors ---------------------------------------------------------------------------------

// @verifies REQ-RA-001
TEST(WheelRailSensors, ImuStaticReadingsOnGradient) {
  for (const double g : {0.0, 35.0, -25.0}) {
    const auto run = SimulateWheelRail(Scenario(BaseScenario(g)));
    const double theta = std::atan(g / 1000.0);
    // after the suspension settled (2 s), ideal IMU
    EXPECT_NEAR(ImuMean(run, 20, 100, &ra::ImuSample::ax), kG * std::sin(theta), 0.002) << g;
    EXPECT_NEAR(ImuMean(run, 20, 100, &ra::ImuSample::az), kG * std::cos(theta), 0.01) << g;
    EXPECT_NEAR(ImuMean(run, 20, 100, &ra::ImuSample::ay), 0.0, 1e-9) << g;
    EXPECT_NEAR(ImuMean(run, 20, 100, &ra::ImuSample::wy), 0.0, 1e-4) << g;
    EXPECT_NEAR(run.truth.back().pitch_rad, theta, 0.0005) << g;
  }
}

// @verifies REQ-RA-001
TEST(WheelRailSensors, ImuErrorsWithinTheD1Budget) {
  // D1 §3 item 6: 0.015 m/s^2 after 3 s averaging; rate 0.0025 deg/s (the reference case)
  for (const std::uint64_t seed : {1U, 2U, 3U, 4U, 5U}) {
    auto j = BaseScenario(0.0);
    j["imu"] = nlohmann::json::object();
    j["seed"] = seed;
    j["duration_s"] = 30;
    const auto sc = Scenario(j);
    const auto run = SimulateWheelRail(sc);
    for (std::size_t from = 20; from + 30 <= run.cycles.size(); from += 30) {
      const double ax = ImuMean(run, from, from + 30, &ra::ImuSample::ax);
      const double az = ImuMean(run, from, from + 30, &ra::ImuSample::az);
      const double wy = ImuMean(run, from, from + 30, &ra::ImuSample::wy);
      EXPECT_LT(std::fabs(ax), 0.015) << seed;
      EXPECT_LT(std::fabs(az - kG), 0.015 + 0.005) << seed;  // plus the suspension's settling
      EXPECT_LT(std::fabs(wy) * 180.0 / std::numbers::pi, 0.0025) << seed;
    }
    // timestamps: 10 per cycle, every 10 ms, the last at the cycle time
    const auto& c = run.cycles[5];
    EXPECT_EQ(c.imu_count, 10);
    for (std::size_t k = 0; k < 10; ++k) {
      EXPECT_EQ(c.imu[k].time_us, c.time_ms * 1000 - 90000 + static_cast<std::int64_t>(k) * 10000);
    }
  }
}

// @verifies REQ-RA-005
TEST(WheelRailSensors, ImuInCantedCurveAtConstantSpeed) {
  auto j = BaseScenario(0.0);
  NoResistance(j);
  j["initial_speed_kmh"] = 72;  // 20 m/s
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  j["vehicle"]["roll_coefficient"] = 0.0;
  j["duration_s"] = 12;
  j["curves"] = {{{"begin_m", 600}, {"end_m", 1100}, {"radius_m", 500}, {"cant_mm", 90}, {"transition_m", 50}}};
  const auto sc = Scenario(j);
  const auto run = SimulateWheelRail(sc);
  // car centre at 490 + 20 t m: entry transition 600..650 m (5.5 .. 8 s), full curve after
  const auto& c = run.cycles[99];
  const double v = run.truth[99].speed_mps;
  ASSERT_NEAR(v, 20.0, 0.1);
  const double psi = -std::asin(90.0 / 1500.0);  // left curve: the left (inner) side is low
  EXPECT_NEAR(CycleMean(c, &ra::ImuSample::wz), v / 500.0 * std::cos(psi), 1e-4);
  EXPECT_NEAR(CycleMean(c, &ra::ImuSample::ay), v * v / 500.0 * std::cos(psi) + kG * std::sin(psi), 0.003);
  EXPECT_NEAR(run.truth[99].roll_rad, psi, 1e-9);
  // the odometry's roll initialisation: arctan((a_y - v w_z) / a_z) ~ psi
  const double ay = CycleMean(c, &ra::ImuSample::ay);
  const double az = CycleMean(c, &ra::ImuSample::az);
  const double wz = CycleMean(c, &ra::ImuSample::wz);
  EXPECT_NEAR(std::atan((ay - v * wz) / az), psi, 0.002);
  // the design's corrected pitch rate w_y + w_z sin(psi) is ~0 on level track in cant
  EXPECT_NEAR(CycleMean(c, &ra::ImuSample::wy) + wz * std::sin(psi), 0.0, 2e-4);
  // in the entry transition the roll rate is v dpsi/ds with dpsi/ds = psi / 50 m, and the
  // yaw rate grows linearly
  const double roll_rate = CycleMean(run.cycles[65], &ra::ImuSample::wx);
  EXPECT_NEAR(roll_rate, v * psi / 50.0, 0.05 * std::fabs(v * psi / 50.0));
  EXPECT_GT(CycleMean(run.cycles[65], &ra::ImuSample::wz), 0.0);
  EXPECT_LT(CycleMean(run.cycles[65], &ra::ImuSample::wz), v / 500.0);
  // straight track before the curve: no yaw, no roll
  EXPECT_NEAR(CycleMean(run.cycles[20], &ra::ImuSample::wz), 0.0, 1e-12);
  EXPECT_NEAR(CycleMean(run.cycles[20], &ra::ImuSample::wx), 0.0, 1e-12);
}

// @verifies REQ-RA-002
TEST(WheelRailSensors, TgPulsesMatchWheelRotation) {
  auto j = BaseScenario(0.0);
  j["duration_s"] = 20;
  j["initial_speed_kmh"] = 50;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  const auto sc = Scenario(j);
  const auto run = SimulateWheelRail(sc);
  const double p = std::numbers::pi * sc.vehicle.wheel_diameter_m / 90.0;
  EXPECT_NEAR(run.pulse_length_m, p, 1e-12);
  std::int64_t prev_pulses = 0, prev_edge = 0;
  for (std::size_t i = 0; i < run.cycles.size(); ++i) {
    const auto& c = run.cycles[i];
    EXPECT_EQ(c.tg.time_us, c.time_ms * 1000);
    EXPECT_GE(c.tg.pulses, prev_pulses);
    EXPECT_LE(c.tg.last_edge_us, c.tg.time_us);
    EXPECT_GE(c.tg.last_edge_us, prev_edge);
    if (c.tg.pulses > prev_pulses) {
      EXPECT_GT(c.tg.last_edge_us, c.tg.time_us - 100000);  // new pulses: an edge in this cycle
    }
    prev_pulses = c.tg.pulses;
    prev_edge = c.tg.last_edge_us;
  }
  // coasting, free rolling: the count is the rolled distance within one pulse and the creep
  const auto& t = run.truth.back();
  EXPECT_NEAR(static_cast<double>(run.cycles.back().tg.pulses) * p, t.distance_m, p + 1e-3 * t.distance_m);
  EXPECT_NEAR(t.tg_distance_m, static_cast<double>(run.cycles.back().tg.pulses) * p, 1e-9);
  // about 14 m/s over 20 s: 280 m, 1 pulse = 30 mm
  EXPECT_GT(run.cycles.back().tg.pulses, 8000);
}

TEST(WheelRailSensors, BaliseFixAtPassage) {
  auto j = BaseScenario(0.0);
  j["initial_speed_kmh"] = 36;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  j["balises"] = {{{"id", "B1"}, {"position_m", 540}}};
  const auto run = SimulateWheelRail(Scenario(j));
  int fixes = 0;
  for (std::size_t i = 0; i < run.cycles.size(); ++i) {
    if (run.cycles[i].balise) {
      ++fixes;
      EXPECT_TRUE(run.truth[i].balise);
      EXPECT_NEAR(static_cast<double>(run.cycles[i].balise->front_mm) / 1000.0, run.truth[i].front_m, 0.001);
      EXPECT_GE(run.truth[i].front_m, 540.0);
      EXPECT_LT(run.truth[i].front_m - 540.0, 1.1);  // within one cycle at 10 m/s
    }
  }
  EXPECT_EQ(fixes, 1);
}

// @verifies REQ-RA-013
TEST(WheelRailSensors, InjectedFaults) {
  auto j = BaseScenario(0.0);
  j["initial_speed_kmh"] = 36;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  j["faults"] = {{{"type", "imu_nan"}, {"from_s", 1.0}, {"to_s", 1.1}},
                 {{"type", "imu_gap"}, {"from_s", 2.0}, {"to_s", 2.1}, {"samples", 7}},
                 {{"type", "imu_timestamps"}, {"from_s", 3.0}, {"to_s", 3.1}},
                 {{"type", "imu_out_of_range"}, {"from_s", 4.0}, {"to_s", 4.1}, {"value", 80}},
                 {{"type", "cycle_time"}, {"from_s", 5.0}, {"to_s", 5.1}},
                 {{"type", "tg_dropout"}, {"from_s", 6.0}, {"to_s", 6.5}},
                 {{"type", "tg_edge_invalid"}, {"from_s", 8.0}, {"to_s", 8.1}},
                 {{"type", "tg_burst"}, {"from_s", 9.0}, {"to_s", 9.1}, {"pulses", 5000}}};
  const auto run = SimulateWheelRail(Scenario(j));
  auto at = [&](double t) { return static_cast<std::size_t>(std::llround(t * 10.0)) - 1; };  // cycle ending at t
  EXPECT_TRUE(std::isnan(run.cycles[at(1.0)].imu[4].ax));
  EXPECT_FALSE(std::isnan(run.cycles[at(1.1)].imu[4].ax));
  EXPECT_EQ(run.cycles[at(2.0)].imu_count, 7);
  EXPECT_EQ(run.cycles[at(2.1)].imu_count, 10);
  EXPECT_GT(run.cycles[at(3.0)].imu[4].time_us, run.cycles[at(3.0)].imu[5].time_us);
  EXPECT_DOUBLE_EQ(run.cycles[at(4.0)].imu[5].ax, 80.0);
  EXPECT_EQ(run.cycles[at(5.0)].time_ms, run.cycles[at(5.0) - 1].time_ms);  // repeated
  EXPECT_EQ(run.truth[at(5.0)].time_ms, 5000);                              // truth keeps the true time
  // dropout: the count falls to 0, then counts again from 0
  EXPECT_GT(run.cycles[at(5.9)].tg.pulses, 1000);
  EXPECT_EQ(run.cycles[at(6.0)].tg.pulses, 0);
  EXPECT_EQ(run.cycles[at(6.4)].tg.pulses, 0);
  EXPECT_GT(run.cycles[at(6.5)].tg.pulses, 0);
  EXPECT_LT(run.cycles[at(6.5)].tg.pulses, 50);
  EXPECT_GT(run.cycles[at(8.0)].tg.last_edge_us, run.cycles[at(8.0)].tg.time_us);
  EXPECT_GT(run.cycles[at(9.0)].tg.pulses - run.cycles[at(8.9)].tg.pulses, 5000);
  EXPECT_NE(run.truth[at(9.0)].faults & (1u << static_cast<unsigned>(SensorFaultKind::kTgBurst)), 0U);
}

TEST(WheelRailSensors, StuckTgLosesPulses) {
  auto j = BaseScenario(0.0);
  j["initial_speed_kmh"] = 36;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  j["faults"] = {{{"type", "tg_stuck"}, {"from_s", 3.0}, {"to_s", 5.0}}};
  const auto run = SimulateWheelRail(Scenario(j));
  EXPECT_EQ(run.cycles[29].tg.pulses, run.cycles[48].tg.pulses);  // frozen 3.0 .. 4.9 s
  EXPECT_GT(run.cycles[60].tg.pulses, run.cycles[48].tg.pulses);
  // about 2 s x 10 m/s / 30 mm lost, never counted back
  const double true_pulses = run.truth.back().tg_distance_m / run.pulse_length_m;
  EXPECT_NEAR(true_pulses - static_cast<double>(run.cycles.back().tg.pulses), 2.0 * 10.0 / run.pulse_length_m, 30.0);
}

TEST(WheelRailRun, DeterministicForASeed) {
  auto j = BaseScenario(25.0);
  j["imu"] = nlohmann::json::object();
  j["initial_speed_kmh"] = 40;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["rail"]["condition"] = "wet";
  j["driver"] = {{{"t_s", 0}, {"traction", 1.0}, {"ramp_s", 1}}};
  const auto sc = Scenario(j);
  const auto a = SimulateWheelRail(sc);
  const auto b = SimulateWheelRail(sc);
  ASSERT_EQ(a.cycles.size(), b.cycles.size());
  for (std::size_t i = 0; i < a.cycles.size(); ++i) {
    EXPECT_EQ(a.cycles[i].tg.pulses, b.cycles[i].tg.pulses);
    EXPECT_EQ(a.cycles[i].tg.last_edge_us, b.cycles[i].tg.last_edge_us);
    for (std::size_t k = 0; k < 10; ++k) {
      EXPECT_EQ(a.cycles[i].imu[k].ax, b.cycles[i].imu[k].ax);  // bit for bit
      EXPECT_EQ(a.cycles[i].imu[k].wy, b.cycles[i].imu[k].wy);
    }
    EXPECT_EQ(a.truth[i].front_m, b.truth[i].front_m);
  }
  EXPECT_EQ(WheelRailCsv(a), WheelRailCsv(b));
  j["seed"] = 8;
  const auto c = SimulateWheelRail(Scenario(j));
  EXPECT_NE(a.cycles[10].imu[0].ax, c.cycles[10].imu[0].ax);
}

// ---- loader ------------------------------------------------------------------------------------

void ExpectError(const std::function<void(nlohmann::json&)>& mutate, const std::vector<std::string>& fragments) {
  auto j = BaseScenario(0.0);
  mutate(j);
  testing::ExpectInputError([&] { (void)ParseWheelRailScenario(j.dump(), "bad.json"); }, "bad.json", fragments);
}

TEST(WheelRailLoader, RejectsBadScenarios) {
  ExpectError([](auto& j) { j["vertical"]["gradients"][0]["permille"] = 36; },
              {"vertical.gradients[0].permille", "beyond the maximum +-35"});
  ExpectError([](auto& j) { j["vertical"]["gradients"][0]["permille"] = -35.5; }, {"gradients[0].permille"});
  ExpectError([](auto& j) { j["duration_s"] = -5; }, {"duration_s", "(0, 3600]"});
  // unknown keys and the requirement ids are the schema's (railproof_testgen validate); the
  // loader guards the values
  ExpectError([](auto& j) { j["vehicle"] = {{"body_mass_kg", 1e300}}; }, {"vehicle.body_mass_kg", "outside [5000, 80000]"});
  ExpectError([](auto& j) { j["faults"] = {{{"type", "imu_nan"}, {"from_s", 3}, {"to_s", 2}}}; },
              {"faults[0].to_s", "negative or zero duration"});
  ExpectError([](auto& j) { j["faults"] = {{{"type", "imu_bogus"}, {"from_s", 1}, {"to_s", 2}}}; },
              {"faults[0].type", "unknown fault type"});
  ExpectError([](auto& j) { j["schema"] = "x"; }, {"schema", "railproof/wheelrail-scenario/1"});
  ExpectError([](auto& j) { j["rail"]["condition"] = "icy"; }, {"rail.condition", "'dry' or 'wet'"});
  ExpectError([](auto& j) { j["driver"][0]["ramp_s"] = -1; }, {"driver[0].ramp_s"});
  ExpectError([](auto& j) { j["driver"].push_back({{"t_s", -1}}); }, {"driver[1].t_s"});
  ExpectError([](auto& j) { j["initial_front_m"] = 5; }, {"initial_front_m", "inside the vertical alignment"});
  // 0 -> 30 permille at 30 m: the 90 m vertical curve would start before the alignment
  ExpectError([](auto& j) { j["vertical"]["gradients"].push_back({{"from_m", 30}, {"permille", 30}}); },
              {"vertical.gradients[1]", "vertical curve"});
  ExpectError([](auto& j) { j["step_ms"] = 3; }, {"step_ms", "divide"});
  ExpectError([](auto& j) { j["curves"] = {{{"begin_m", 10}, {"end_m", 100}, {"radius_m", 50}}}; },
              {"curves[0].radius_m"});
  testing::ExpectInputError([] { (void)LoadWheelRailScenario("/nonexistent/x.json"); }, "/nonexistent/x.json",
                            {"/nonexistent/x.json: cannot read"});
}

// How a run begins (REQ-RA-015): required in motion, consistent with the speed, and a
// lead-in must not cross an adhesion zone.
// @verifies REQ-RA-015
TEST(WheelRailLoader, StartOfTheRun) {
  ExpectError([](auto& j) { j["initial_speed_kmh"] = 40; }, {"missing key 'start'"});
  ExpectError([](auto& j) { j["start"] = "lead_in"; }, {"start", "at_rest is a start at speed 0"});
  ExpectError(
      [](auto& j) {
        j["initial_speed_kmh"] = 40;
        j["start"] = "at_rest";
      },
      {"start", "with initial_speed_kmh 40"});
  ExpectError(
      [](auto& j) {
        j["initial_speed_kmh"] = 40;
        j["start"] = "gliding";
      },
      {"start", "unknown start 'gliding'"});
  ExpectError(
      [](auto& j) {
        j["initial_speed_kmh"] = 40;
        j["start"] = "lead_in";
        j["rail"]["zones"] = {{{"begin_m", 300}, {"end_m", 310}, {"factor", 0.5}}};
      },
      {"start", "crosses the adhesion zone [300, 310)"});
}

// A lead-in: at rest for its standstill time, then up to the initial speed; the front reaches
// the initial front at the scenario's t = 0 (lead_in_ms) at about the initial speed; the
// first gradient is extended back over the lead-in.
// @verifies REQ-RA-015
TEST(WheelRailRun, LeadInEndsAtTheInitialFrontAndSpeed) {
  auto j = BaseScenario(0.0);
  j["duration_s"] = 5;
  j["initial_speed_kmh"] = 36;
  j["start"] = "lead_in";
  j["driver"] = {{{"t_s", 0}, {"traction", 0.5}, {"brake", 0.5}, {"hold_kmh", 36}, {"ramp_s", 0}}};
  const auto sc = Scenario(j);
  EXPECT_EQ(sc.start, ScenarioStart::kLeadIn);
  EXPECT_LT(sc.vertical.begin_m, sc.initial_front_m - LeadInDistanceM(sc.lead_in, 10.0) - sc.vehicle.length_m);
  EXPECT_EQ(sc.vertical.gradients.front().from_m, sc.vertical.begin_m);
  const auto run = SimulateWheelRail(sc);
  ASSERT_GT(run.lead_in_ms, 0);
  const auto t0 = static_cast<std::size_t>(run.lead_in_ms / 100 - 1);  // the cycle ending at t = 0
  ASSERT_LT(t0 + 1, run.truth.size());
  EXPECT_EQ(run.truth.size(), static_cast<std::size_t>((run.lead_in_ms + 5'000) / 100));
  for (std::size_t k = 0; k * 100 < static_cast<std::size_t>(sc.lead_in.standstill_s * 1000.0) - 100; ++k) {
    EXPECT_EQ(run.cycles[k].tg.pulses, run.cycles[0].tg.pulses) << k;  // no TG pulse at standstill
  }
  EXPECT_GE(run.truth[t0].front_m, sc.initial_front_m);
  EXPECT_LT(run.truth[t0].front_m, sc.initial_front_m + 1.5);
  EXPECT_NEAR(run.truth[t0].speed_mps, 10.0, 0.3);
}

// Curves and adhesion zones off the alignment (where the simulation has no track: they would
// silently never act), huge fault times and values (converted to integer microseconds), and a
// key twice: the whole message.
TEST(WheelRailLoader, RejectsSectionsOffTheAlignmentAndHugeValues) {
  ExpectError([](auto& j) { j["curves"] = {{{"begin_m", 2900}, {"end_m", 3100}, {"radius_m", 800}}}; },
              {"bad.json: curves[0]: curve [2900, 3100) m lies outside the vertical alignment [0, 3000) m"});
  ExpectError([](auto& j) { j["curves"] = {{{"begin_m", -1e300}, {"end_m", 100}, {"radius_m", 800}}}; },
              {"bad.json: curves[0]: curve [-1e+300, 100) m lies outside the vertical alignment [0, 3000) m"});
  ExpectError([](auto& j) { j["rail"]["zones"] = {{{"begin_m", 100}, {"end_m", 1e300}, {"factor", 0.3}}}; },
              {"bad.json: rail.zones[0]: adhesion zone [100, 1e+300) m lies outside the vertical alignment [0, 3000) m"});
  ExpectError([](auto& j) { j["faults"] = {{{"type", "imu_nan"}, {"from_s", 1}, {"to_s", 1e300}}}; },
              {"bad.json: faults[0].to_s: value 1e+300 is outside [0, 1e+06]"});
  ExpectError([](auto& j) { j["faults"] = {{{"type", "imu_out_of_range"}, {"from_s", 1}, {"to_s", 2}, {"value", -1e300}}}; },
              {"bad.json: faults[0].value: value -1e+300 is outside [-10000, 10000]"});
  testing::ExpectInputError(
      [] { (void)ParseWheelRailScenario(R"({"schema": "railproof/wheelrail-scenario/1", "vertical": {"end_m": 1, "end_m": 2}})",
                                        "bad.json"); },
      "bad.json", {"bad.json: vertical: duplicate key 'end_m'"});
}

TEST(WheelRailLoader, TrainLeavingTheAlignmentIsAnError) {
  auto j = BaseScenario(0.0);
  j["initial_front_m"] = 2990;
  j["initial_speed_kmh"] = 36;
  j["start"] = "in_motion";  // the simulator alone: the run begins in motion
  j["driver"] = {{{"t_s", 0}, {"brake", 0.0}, {"ramp_s", 0}}};
  EXPECT_THROW((void)SimulateWheelRail(Scenario(j)), offline::InputError);
}

// ---- odometry sections -------------------------------------------------------------------------

// @verifies REQ-RA-009
TEST(WheelRailSections, FromTheGradientProfile) {
  auto j = BaseScenario(0.0);
  j["vertical"]["vertical_curve_radius_m"] = 2000;
  j["vertical"]["gradients"] = {{{"from_m", 0}, {"permille", 0}},
                                {{"from_m", 1000}, {"permille", 25}},
                                {{"from_m", 2000}, {"permille", -35}}};
  j["odometry"] = {{"max_compensation_s", 15}};
  const auto sc = Scenario(j);
  const auto s = OdometrySectionsOf(sc);
  ASSERT_EQ(s.size(), 3U);
  EXPECT_EQ(s[0].begin_mm, 0);
  EXPECT_EQ(s[0].end_mm, 1'000'000);
  EXPECT_EQ(s[1].begin_mm, 1'000'000);
  EXPECT_EQ(s[2].end_mm, 3'000'000);
  // the first section contains the first half of the 0 -> 25 curve: up to 12.5 permille
  EXPECT_EQ(s[0].gradient_permille_x10, 125);
  EXPECT_EQ(s[1].gradient_permille_x10, 250);
  EXPECT_EQ(s[2].gradient_permille_x10, 350);
  for (const auto& x : s) {
    EXPECT_EQ(x.max_compensation_ms, 15000);
    EXPECT_EQ(x.margin_mm, 0);
  }
  EXPECT_NEAR(GradientPermilleAt(sc.vertical, 1000.0), 12.5, 1e-12);
  EXPECT_NEAR(GradientPermilleAt(sc.vertical, 975.0), 0.0, 1e-12);   // curve: 50 m long
  EXPECT_NEAR(GradientPermilleAt(sc.vertical, 1025.0), 25.0, 1e-12);
  EXPECT_NEAR(GradientPermilleAt(sc.vertical, 2000.0), -5.0, 1e-12);
  const auto cfg = OdometryConfigOf(sc, s);
  EXPECT_EQ(cfg.section_count, 3);
  EXPECT_EQ(cfg.sections, s.data());
  EXPECT_EQ(cfg.wheel_diameter_um, 860'000);
  EXPECT_EQ(cfg.initial_front_mm, 500'000);
  EXPECT_EQ(cfg.train_length_mm, 20'000);
  // Ta never below the gravity component of 35 permille plus the TG and IMU acceleration
  // errors (ASM-028): 9807 x 0.035 = 343.2 -> 344, + 21 + 15 = 380
  EXPECT_EQ(cfg.detect_threshold_mm_s2, 380);
  EXPECT_GE(cfg.detect_threshold_mm_s2, params::ra::detect_threshold_mm_s2);
}

}  // namespace
}  // namespace railproof::ra::analysis
