// Scenario runs of the system simulation on the 10 km test line (data/sim_test_line.json, one
// level crossing) with the real on-board and wayside units: invariants hold on a lossy channel,
// runs are deterministic, a follower settles behind a slow leader, faults stop the trains they
// should stop, and the invariant checks fire on a seeded failure (a train whose brakes are
// weaker than its unit's braking data).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "railproof/offline/line.hpp"
#include "railproof/testing/input_error.hpp"
#include "railproof/sim/scenario.hpp"
#include "railproof/sim/simulation.hpp"
#include "sim_test_data.hpp"

namespace railproof::sim {
namespace {

// The on-board data of the test's 100 m trains (the form of spec/trains/*.yaml).
TrainType TestType() {
  TrainType t;
  t.name = "test100";
  t.length_mm = 100'000;
  t.max_speed_kmh = 100;
  t.accel_max_mm_s2 = 800;
  t.emergency_pattern_mm_s2 = 1000;
  t.service_pattern_mm_s2 = 850;
  t.emergency_free_running_ms = {500, 1500};
  t.service_free_running_ms = {1000, 2500};
  t.emergency_overspeed_kmh = 5;
  t.speed_error_ppm = 2500;
  t.speed_error_abs_mm_s = 174;
  t.emergency_deceleration_mm_s2 = {1100, 1400};
  t.service_deceleration_mm_s2 = {900, 1200};
  t.odometry_ppm = 1000;
  t.readhesion_margin_mm = 40'000;
  return t;
}

nlohmann::json TrainJson(int id, double front_m, double depart_s) {
  return nlohmann::json{{"id", id},
                        {"length_m", 100},
                        {"max_speed_kmh", 100},
                        {"accel_mps2", 0.8},
                        {"service_decel_mps2", 0.9},
                        {"emergency_decel_mps2", 1.1},
                        {"initial_front_m", front_m},
                        {"depart_s", depart_s}};
}

nlohmann::json ScenarioJson(double duration_s) {
  return nlohmann::json{{"schema", "railproof/scenario/1"},
                        {"name", "unit"},
                        {"line", "sim_test_line"},
                        {"running_line", "up"},
                        {"duration_s", duration_s},
                        {"step_ms", 100},
                        {"seed", 3},
                        {"channel", {{"loss_probability", 0.05}, {"max_delay_ms", 300}, {"corrupt_probability", 0.02}}},
                        {"trains", nlohmann::json::array()}};
}

Simulation Make(const nlohmann::json& j) {
  return Simulation(ParseScenario(j.dump(), "unit.json"), TestLine(), {TestType()});
}

std::string Describe(const Simulation& sim) {
  std::string s;
  for (const auto& v : sim.Violations()) {
    s += std::to_string(v.t_ms) + " " + v.requirement + ": " + v.detail + "\n";
  }
  return s;
}

// Runs the scenario to its end; no invariant may be violated. Returns the summary.
nlohmann::ordered_json RunWithoutViolations(Simulation& sim) {
  sim.Run();
  EXPECT_TRUE(sim.Violations().empty()) << Describe(sim);
  return sim.Summary();
}

// Steps to t_ms; train `id` must stand there. Returns its state.
TrainView StandingAt(Simulation& sim, std::int64_t t_ms, std::uint16_t id) {
  while (sim.NowMs() < t_ms) {
    sim.Step();
  }
  const auto t = sim.Train(id);
  EXPECT_TRUE(t.has_value()) << "train " << id;
  EXPECT_EQ(t.value_or(TrainView{}).speed_mps, 0.0) << "train " << id;
  return t.value_or(TrainView{});
}

// @verifies REQ-MB-008
// @verifies REQ-MB-009
// @verifies REQ-MB-024
TEST(SimRun, ShortScenarioWithLossyRadioHasNoViolations) {
  auto j = ScenarioJson(300);
  j["trains"].push_back(TrainJson(2, 1000, 0));
  j["trains"].push_back(TrainJson(3, 600, 5));
  j["trains"].push_back(TrainJson(4, 300, 10));
  Simulation sim = Make(j);
  const auto s = RunWithoutViolations(sim);
  EXPECT_EQ(s["result"], "PASS");
  EXPECT_GT(s["radio"]["uplink"]["accepted"].get<int>(), 600);
  EXPECT_GT(s["radio"]["downlink"]["accepted"].get<int>(), 1200);
  EXPECT_GT(s["radio"]["uplink"]["lost_random"].get<int>(), 0);
  EXPECT_GT(s["radio"]["downlink"]["corrupted"].get<int>(), 0);
  EXPECT_GT(s["checks"]["REQ-MB-008"]["checks"].get<int>(), 2900);
  const auto reqs = s["requirements"];
  EXPECT_NE(std::find(reqs.begin(), reqs.end(), "REQ-MB-008"), reqs.end());
  EXPECT_NE(std::find(reqs.begin(), reqs.end(), "REQ-MB-024"), reqs.end());
  for (const auto& t : sim.Trains()) {
    EXPECT_GT(t.front_m, 1500.0) << "train " << t.id << " made no progress";
  }
}

TEST(SimRun, IsDeterministic) {
  auto j = ScenarioJson(120);
  j["trains"].push_back(TrainJson(2, 1000, 0));
  j["trains"].push_back(TrainJson(3, 600, 0));
  Simulation a = Make(j);
  Simulation b = Make(j);
  a.Run();
  b.Run();
  EXPECT_EQ(a.Summary().dump(), b.Summary().dump());
  EXPECT_EQ(a.Svg(), b.Svg());
}

GapResult FollowGap(double leader_kmh) {
  auto j = ScenarioJson(420);
  auto leader = TrainJson(2, 3800, 0);
  leader["speed_cap_kmh"] = leader_kmh;
  j["trains"].push_back(leader);
  j["trains"].push_back(TrainJson(3, 3650, 0));
  j["gap"] = {{"leader", 2}, {"follower", 3}, {"from_s", 240}, {"to_s", 420}};
  Simulation sim = Make(j);
  RunWithoutViolations(sim);
  const auto g = sim.Gap();
  EXPECT_TRUE(g.has_value());
  return g.value_or(GapResult{});
}

// @verifies REQ-MB-006
// @verifies REQ-MB-018
TEST(SimRun, FollowerAtFullPowerSettlesBehindASlowLeader) {
  const GapResult g = FollowGap(20.0);
  EXPECT_NEAR(g.follower_speed_kmh, 20.0, 1.0);
  EXPECT_NEAR(g.leader_speed_kmh, 20.0, 0.5);
  EXPECT_GT(g.min_m, 20.0);  // never closer than the preceding-train margin
  EXPECT_LT(g.max_m - g.min_m, 30.0) << "gap did not settle: " << g.min_m << " .. " << g.max_m;
  EXPECT_LT(g.std_m, 10.0);
  // the patterns' distance at 20 km/h: the service offset, the run-up, the envelopes of both
  // trains, the preceding-train margin and the report's age (spec/design/sim.md §6)
  EXPECT_GT(g.mean_m, 80.0);
  EXPECT_LT(g.mean_m, 250.0);
}

// @verifies REQ-MB-006
TEST(SimRun, SettledGapGrowsWithSpeed) {
  const GapResult g20 = FollowGap(20.0);
  const GapResult g40 = FollowGap(40.0);
  EXPECT_NEAR(g40.follower_speed_kmh, 40.0, 2.0);
  EXPECT_GT(g40.mean_m, g20.mean_m + 10.0);
}

// @verifies REQ-MB-004
// @verifies REQ-MB-009
TEST(SimRun, InjectedRadioLossStopsTheTrainWithoutViolations) {
  auto j = ScenarioJson(260);
  auto t2 = TrainJson(2, 1000, 0);
  t2["speed_cap_kmh"] = 60;
  j["trains"].push_back(t2);
  j["trains"].push_back(TrainJson(3, 400, 0));
  j["faults"] = {{{"type", "radio_loss"}, {"train", 2}, {"from_s", 100}, {"to_s", 160}}};
  Simulation sim = Make(j);
  const TrainView mid = StandingAt(sim, 150'000, 2);
  EXPECT_FALSE(mid.authority_usable);
  EXPECT_TRUE(mid.abnormal);
  EXPECT_GE(mid.emergency_brakes, 1U);
  const auto f = RunWithoutViolations(sim)["faults"][0];
  ASSERT_FALSE(f["standstill_after_s"].is_null());
  ASSERT_FALSE(f["abnormal_after_s"].is_null());
  // authority validity 3 s + braking from 60 km/h at 1.2 m/s^2 (14 s)
  EXPECT_LT(f["standstill_after_s"].get<double>(), 20.0);
  EXPECT_LE(f["abnormal_after_s"].get<double>(), 4.0);
  ASSERT_FALSE(f["moving_again_after_end_s"].is_null());
  EXPECT_LT(f["moving_again_after_end_s"].get<double>(), 10.0);
  EXPECT_GT(sim.Train(2)->front_m, mid.front_m + 500.0);
}

// @verifies REQ-MB-004
TEST(SimRun, TrackingLossMarksTheTrainAbnormalAndHoldsTheFollower) {
  auto j = ScenarioJson(240);
  j["trains"].push_back(TrainJson(2, 1000, 0));
  j["trains"].push_back(TrainJson(3, 600, 0));
  j["faults"] = {{{"type", "tracking_loss"}, {"train", 2}, {"from_s", 90}, {"to_s", 150}}};
  Simulation sim = Make(j);
  const TrainView leader = StandingAt(sim, 149'000, 2);
  const auto follower = sim.Train(3);
  ASSERT_TRUE(follower.has_value()) << "the follower is on the line";
  EXPECT_TRUE(leader.abnormal);
  // the follower stands at least the abnormal-train margin behind the leader's rear
  EXPECT_GT(leader.rear_m - follower->front_m, 50.0);
  const auto f = RunWithoutViolations(sim)["faults"][0];
  ASSERT_FALSE(f["abnormal_after_s"].is_null());
  EXPECT_LE(f["abnormal_after_s"].get<double>(), 4.5);
  EXPECT_FALSE(f["tracked_again_after_end_s"].is_null());
  EXPECT_FALSE(sim.Train(2)->abnormal);
}

// @verifies REQ-MB-014
TEST(SimRun, PossessionBecomesActiveAndNoTrainEntersIt) {
  auto j = ScenarioJson(300);
  j["trains"].push_back(TrainJson(2, 5500, 0));
  j["faults"] = {{{"type", "possession"}, {"begin_m", 7000}, {"end_m", 7400}, {"from_s", 10}, {"to_s", 150}}};
  Simulation sim = Make(j);
  EXPECT_LE(StandingAt(sim, 140'000, 2).front_m, 7000.0 - 50.0);  // before possession start minus margin
  const auto s = RunWithoutViolations(sim);
  EXPECT_FALSE(s["faults"][0]["active_after_s"].is_null());
  EXPECT_GT(s["checks"]["REQ-MB-014"]["checks"].get<int>(), 0);
  EXPECT_GT(sim.Train(2)->front_m, 7400.0);  // continues after the cancellation
}

// @verifies REQ-MB-011
// @verifies REQ-MB-013
TEST(SimRun, SidingRouteRequestHoldsTrainsBeforeTheRouteEntrance) {
  auto j = ScenarioJson(300);
  j["trains"].push_back(TrainJson(2, 3800, 0));
  // requested before the first cycle: no authority over the main route yet, so the
  // automatic main route is released and the siding route set at once
  j["faults"] = {{{"type", "siding_request"}, {"from_s", 0}, {"to_s", 150}},
                 // requested while the train holds authority over the points: approach
                 // locking keeps the main route until the train has passed
                 {{"type", "siding_request"}, {"from_s", 152}, {"to_s", 280}}};
  Simulation sim = Make(j);
  EXPECT_LE(StandingAt(sim, 140'000, 2).front_m, 4950.0 - 30.0);  // route entrance minus the route margin
  const auto s = RunWithoutViolations(sim);
  EXPECT_FALSE(s["faults"][0]["set_after_s"].is_null());
  EXPECT_FALSE(s["faults"][0]["freed_after_end_s"].is_null());
  ASSERT_FALSE(s["faults"][1]["set_after_s"].is_null());
  EXPECT_GT(s["faults"][1]["set_after_s"].get<double>(), 10.0);  // only once the train had passed
  EXPECT_GT(s["checks"]["REQ-MB-011"]["checks"].get<int>(), 0);
  EXPECT_GT(sim.Train(2)->front_m, 5100.0);
}

// Negative test of the invariant checks: a train whose brakes are weaker than the braking data
// its on-board unit supervises with (service and emergency deceleration below the patterns')
// cannot stop where the patterns say: it overruns its stop limit at the end of the line, and the
// check must say so; the summary names the mismatch.
TEST(SimRun, InvariantChecksFireOnATrainWithBrakesWeakerThanItsData) {
  auto j = ScenarioJson(300);
  j["channel"] = {{"loss_probability", 0.0}, {"max_delay_ms", 100}};
  auto t = TrainJson(2, 5200, 0);
  t["service_decel_mps2"] = 0.3;
  t["emergency_decel_mps2"] = 0.4;
  j["trains"].push_back(t);
  Simulation sim = Make(j);
  sim.Run();
  const auto s = sim.Summary();
  EXPECT_EQ(s["result"], "FAIL");
  EXPECT_GE(s["checks"]["ASM-013"]["violations"].get<int>(), 1);
  EXPECT_EQ(s["checks"]["REQ-MB-008"]["violations"], 0);
  EXPECT_EQ(s["train_data_findings"].size(), 2U);
  ASSERT_FALSE(sim.Violations().empty());
}

// The same train with the brakes its data describe runs the same line without a violation.
// @verifies REQ-BR-001
// @verifies REQ-BR-004
TEST(SimRun, TheSameTrainWithItsRealBrakesStopsInTime) {
  auto j = ScenarioJson(300);
  j["channel"] = {{"loss_probability", 0.0}, {"max_delay_ms", 100}};
  j["trains"].push_back(TrainJson(2, 5200, 0));
  Simulation sim = Make(j);
  const auto s = RunWithoutViolations(sim);
  EXPECT_TRUE(s["train_data_findings"].empty());
  EXPECT_GT(sim.Train(2)->front_m, 9800.0);  // ran to the end of the line
}

// The train type the on-board unit carries: named by train_type, else found by length; a
// name the train data lack, a length that is not the named type's, or two types of one length
// without a name are input errors naming the entry.
TEST(SimRun, TheTrainTypeIsNamedOrFoundByLength) {
  nlohmann::json j = ScenarioJson(10);
  j["trains"].push_back(TrainJson(2, 1000, 0));
  EXPECT_NO_THROW((void)Make(j));
  j["trains"][0]["train_type"] = "test100";
  EXPECT_NO_THROW((void)Make(j));
  j["trains"][0]["train_type"] = "nonesuch";
  testing::ExpectInputError([&] { (void)Make(j); }, "unit.json", {"unit.json: trains[0].train_type: no train type nonesuch"});
  j["trains"][0]["train_type"] = "test100";
  j["trains"][0]["length_m"] = 90;
  testing::ExpectInputError([&] { (void)Make(j); }, "unit.json",
                            {"unit.json: trains[0].length_m: 90.00 m is not the length of train type test100"});
  j["trains"][0].erase("train_type");
  j["trains"][0]["length_m"] = 100;
  TrainType twin = TestType();
  twin.name = "twin100";
  testing::ExpectInputError(
      [&] { (void)Simulation(ParseScenario(j.dump(), "unit.json"), TestLine(), {TestType(), twin}); }, "unit.json",
      {"unit.json: trains[0]: train types test100 and twin100 both have length 100.00 m: name one with train_type"});
}

TEST(SimRun, TrainsStopAtStationsAndLeaveAtTheTerminus) {
  auto j = ScenarioJson(600);
  auto t2 = TrainJson(2, 1000, 0);
  t2["stops"] = {{{"station", "A"}, {"dwell_s", 20}}, {{"station", "B"}, {"dwell_s", 10}}};
  t2["repeat"] = {{"count", 2}, {"interval_s", 60}};
  j["trains"].push_back(t2);
  Simulation sim = Make(j);
  const auto s = RunWithoutViolations(sim);
  for (const auto& t : sim.Trains()) {
    EXPECT_EQ(t.stops_made, 2U) << "train " << t.id;
    EXPECT_EQ(t.phase, "exited") << "train " << t.id;
  }
  EXPECT_EQ(s["progress"]["trains_left_line"], 2);
}

TEST(SimRun, WritesAnEventLogAndADiagram) {
  auto j = ScenarioJson(60);
  j["trains"].push_back(TrainJson(2, 1000, 0));
  j["faults"] = {{{"type", "radio_loss"}, {"train", 2}, {"from_s", 20}, {"to_s", 30}}};
  Simulation sim = Make(j);
  std::ostringstream log;
  std::vector<std::string> progress;
  RunOptions ro;
  ro.log = &log;
  ro.progress = [&](const std::string& p) { progress.push_back(p); };
  sim.Run(ro);
  const auto doc = nlohmann::json::parse(log.str());
  EXPECT_EQ(doc["schema"], "railproof/sim-log/1");
  ASSERT_TRUE(doc["events"].is_array());
  std::set<std::string> kinds;
  for (const auto& e : doc["events"]) {
    kinds.insert(e["ev"].get<std::string>());
    EXPECT_TRUE(e.contains("t_ms"));
  }
  for (const char* k : {"enter", "cycle", "fault_begin", "fault_end", "emergency_brake", "tracking_abnormal", "limit"}) {
    EXPECT_TRUE(kinds.count(k)) << k;
  }
  EXPECT_EQ(doc["summary"]["result"], "PASS");
  EXPECT_EQ(progress.size(), 10U);
  const std::string svg = sim.Svg();
  EXPECT_NE(svg.find("train 2 front"), std::string::npos);
  EXPECT_NE(svg.find("radio loss T2"), std::string::npos);
  EXPECT_NE(svg.find("distance along the running line [km]"), std::string::npos);
}

}  // namespace
}  // namespace railproof::sim
