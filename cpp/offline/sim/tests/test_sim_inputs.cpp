// Unit tests of the simulation's inputs: line JSON loader (REQ-MB-020), ground line
// building, scenario files (the payload coding is the runtime codec's, cpp/runtime/messages/tests).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "railproof/sim/ground_line.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/sim/scenario.hpp"
#include "railproof/testing/input_error.hpp"
#include "sim_test_data.hpp"

namespace railproof::sim {
namespace {

nlohmann::json TestLineJson() {
  std::ifstream in(DataDir() / "sim_test_line.json");
  return nlohmann::json::parse(in);
}

// Expects ParseLine of the mutated test line to fail with a message containing every
// fragment (file name and entry path first).
void ExpectLineError(const std::function<void(nlohmann::json&)>& mutate, const std::vector<std::string>& fragments) {
  nlohmann::json j = TestLineJson();
  mutate(j);
  testing::ExpectInputError([&] { (void)ParseLine(j.dump(), "bad_line.json"); }, "bad_line.json", fragments);
}

nlohmann::json& Up(nlohmann::json& j) { return j["running_lines"][0]; }

// @verifies REQ-MB-020
TEST(SimLineLoader, LoadsTheTestLine) {
  const Line line = LoadLine(DataDir() / "sim_test_line.json");
  EXPECT_EQ(line.name, "sim_test_line");
  ASSERT_EQ(line.running_lines.size(), 2U);
  const RunningLine& up = line.Running("up");
  EXPECT_EQ(up.length_mm, 10'000'000);
  EXPECT_EQ(up.blocks_mm.size(), 201U);
  EXPECT_EQ(up.GradientAt(3'500'000), -100);
  EXPECT_EQ(up.SpeedLimitAt(7'200'000), 60);
  EXPECT_EQ(up.SpeedLimitAt(10'000'000), 100);
  ASSERT_NE(up.FindStation("B"), nullptr);
  EXPECT_EQ(up.FindStation("B")->stop_mm, 8'990'000);
  EXPECT_EQ(up.FindStation("Z"), nullptr);
  EXPECT_FALSE(up.system_boundary_mm.has_value());
  EXPECT_EQ(up.handovers.at(0).position_mm, 6'000'000);
  EXPECT_EQ(LinePath("/x/lines", "d1_test_line"), std::filesystem::path("/x/lines/d1_test_line.json"));
}

// @verifies REQ-MB-020
TEST(SimLineLoader, RejectsUnreadableAndMalformedFiles) {
  const auto missing = DataDir() / "no_such_line.json";
  testing::ExpectInputError([&] { (void)LoadLine(missing); }, missing.string(), {"cannot read"});
  testing::ExpectInputError([] { (void)ParseLine("{\"schema\": ", "trunc.json"); }, "trunc.json", {"invalid JSON"});
  ExpectLineError([](auto& j) { j["schema"] = "railproof/line-json/0"; }, {"schema", "unsupported schema"});
}

// @verifies REQ-MB-020
TEST(SimLineLoader, RejectsMissingKeysAndWrongTypes) {
  ExpectLineError([](auto& j) { j.erase("running_lines"); }, {"missing key 'running_lines'"});
  ExpectLineError([](auto& j) { Up(j).erase("blocks_mm"); }, {"running_lines[0] (up)", "missing key 'blocks_mm'"});
  ExpectLineError([](auto& j) { Up(j)["length_mm"] = "10 km"; }, {"running_lines[0] (up).length_mm", "expected an integer, got string"});
  ExpectLineError([](auto& j) { Up(j)["blocks_mm"][3] = 150000.5; }, {"running_lines[0] (up).blocks_mm[3]", "expected an integer"});
  ExpectLineError([](auto& j) { Up(j)["stations"][0]["fixed_block"] = 1; },
                  {"running_lines[0] (up).stations[0] (A).fixed_block", "expected true or false"});
  ExpectLineError([](auto& j) { Up(j)["balises"] = nlohmann::json::object(); }, {"balises", "expected an array"});
  ExpectLineError([](auto& j) { j["running_lines"] = nlohmann::json::array(); }, {"running_lines", "no running line"});
  ExpectLineError([](auto& j) { j["running_lines"][1]["id"] = "up"; }, {"running_lines[1].id", "duplicate identifier 'up'"});
}

// @verifies REQ-MB-020
TEST(SimLineLoader, RejectsBadGeometry) {
  ExpectLineError([](auto& j) { std::swap(Up(j)["blocks_mm"][3], Up(j)["blocks_mm"][4]); },
                  {"running_lines[0] (up).blocks_mm[4]", "not greater than the previous one"});
  ExpectLineError([](auto& j) { Up(j)["blocks_mm"][0] = 10; }, {"blocks_mm[0]", "first block boundary must be 0"});
  ExpectLineError([](auto& j) { Up(j)["blocks_mm"].erase(Up(j)["blocks_mm"].size() - 1); },
                  {"blocks_mm[199]", "must equal length_mm"});
  ExpectLineError([](auto& j) { Up(j)["gradients"][1]["begin_mm"] = 3'100'000; },
                  {"running_lines[0] (up).gradients[1]", "begins at 3100000 mm, expected 3000000"});
  ExpectLineError([](auto& j) { Up(j)["speed_limits"].erase(2); }, {"speed_limits[1]", "must cover the whole line"});
  ExpectLineError([](auto& j) { Up(j)["radio_cells"] = nlohmann::json::array(); }, {"radio_cells", "must cover the line"});
  ExpectLineError([](auto& j) { Up(j)["balises"][2]["position_mm"] = 10'000'001; },
                  {"balises[2] (B3).position_mm", "lies off the line"});
  ExpectLineError([](auto& j) { Up(j)["stations"][0]["stop_mm"] = 2'100'000; }, {"stations[0] (A).stop_mm", "outside the platform"});
  ExpectLineError([](auto& j) { Up(j)["points"][0]["end_mm"] = 5'100'000; }, {"points[0] (P1)", "not exactly one virtual block"});
  ExpectLineError([](auto& j) { Up(j)["routes"][1]["points"] = "P9"; }, {"routes[1] (route 2).points", "unknown points 'P9'"});
  ExpectLineError([](auto& j) { Up(j)["routes"][1]["id"] = 1; }, {"routes[1].id", "duplicate route id 1"});
  ExpectLineError([](auto& j) { Up(j)["handovers"][0]["position_mm"] = 5'000'000; },
                  {"handovers[0] (H1).position_mm", "not at a boundary between two radio cells"});
  ExpectLineError([](auto& j) { Up(j)["gradients"][0]["end_mm"] = 0; Up(j)["gradients"][0]["begin_mm"] = 0; },
                  {"gradients[0]", "empty or reversed section"});
  ExpectLineError([](auto& j) { Up(j)["curves"][0]["radius_m"] = 0; }, {"curves[0].radius_m", "radius must be positive"});
  ExpectLineError([](auto& j) { Up(j)["system_boundary_mm"] = 0; }, {"system_boundary_mm", "lies off the line"});
}

// Values beyond the range the simulation computes with, and a key twice: the whole message.
// @verifies REQ-MB-020
TEST(SimLineLoader, RejectsOutOfRangeValuesAndDuplicateKeys) {
  ExpectLineError([](auto& j) { Up(j)["length_mm"] = 20'000'000'000; },
                  {"bad_line.json: running_lines[0] (up).length_mm: value 20000000000 mm is outside [1, 10000000000]"});
  const std::string text = TestLineJson().dump();
  const std::string twice = "{\"name\": \"x\", " + text.substr(1);  // "name" now stands twice
  testing::ExpectInputError([&] { (void)ParseLine(twice, "bad_line.json"); }, "bad_line.json",
                            {"bad_line.json: (top level): duplicate key 'name'"});
}

// @verifies REQ-MB-020
TEST(SimLineLoader, RejectsAnUnknownRunningLine) {
  const Line line = LoadLine(DataDir() / "sim_test_line.json");
  testing::ExpectInputError([&] { (void)line.Running("sideways"); }, line.file,
                            {"unknown running line 'sideways' (the line has: up, down)"});
}

// @verifies REQ-MB-020
TEST(SimGroundLine, BuildsTheGroundConfigurationAndCreatesTheGround) {
  const Line line = LoadLine(DataDir() / "sim_test_line.json");
  const RunningLine& up = line.Running("up");
  const GroundLine gl = BuildGroundLine(line, up, mb::wayside::MarginPolicy::kReportedCorrection, 500);
  EXPECT_EQ(gl.config.length_mm, up.length_mm);
  EXPECT_EQ(gl.config.blocks_mm.size(), up.blocks_mm.size());
  EXPECT_EQ(gl.fixed_blocks.size(), 2U);
  EXPECT_EQ(gl.setback_sections.size(), 1U);
  ASSERT_EQ(gl.routes.size(), 2U);
  EXPECT_EQ(gl.routes[1].points_index, 0U);
  EXPECT_TRUE(gl.routes[1].reverse);
  EXPECT_EQ(gl.handovers.at(0).position_mm, 6'000'000);
  auto ground = CreateGround(line, up, gl, 3);
  ASSERT_NE(ground, nullptr);
  EXPECT_EQ(ground->BlockCount(), 200U);
}

// A wayside unit of a split line holds its part in its own chainage; an item across an end
// of the part, or an end off the virtual blocks, names the split.
TEST(SimGroundLine, TheAreaOfAWaysideUnitIsItsPartOfTheLineShifted) {
  const Line line = LoadLine(DataDir() / "sim_test_line.json");
  const RunningLine& up = line.Running("up");
  const RunningLine a = AreaOfRunningLine(up, 4'000'000, 7'000'000, 6'500'000, "s.json: wayside_splits[0]");
  EXPECT_EQ(a.length_mm, 3'000'000);
  ASSERT_EQ(a.blocks_mm.size(), 61U);
  EXPECT_EQ(a.blocks_mm.front(), 0);
  EXPECT_EQ(a.blocks_mm.back(), 3'000'000);
  ASSERT_EQ(a.points.size(), 1U);
  EXPECT_EQ(a.points[0].section.begin_mm, 1'000'000);
  EXPECT_EQ(a.routes.size(), 2U);
  ASSERT_EQ(a.handovers.size(), 1U);
  EXPECT_EQ(a.handovers[0].position_mm, 2'000'000);
  EXPECT_TRUE(a.stations.empty());
  EXPECT_EQ(a.system_boundary_mm, std::optional<std::int64_t>(2'500'000));
  const GroundLine gl = BuildGroundLine(line, a, mb::wayside::MarginPolicy::kReportedCorrection, 500);
  EXPECT_NE(CreateGround(line, a, gl, 3), nullptr);
  testing::ExpectInputError([&] { (void)AreaOfRunningLine(up, 1'900'000, 4'000'000, 3'000'000, "s.json: wayside_splits[0]"); },
                            "s.json", {"wayside_splits[0]", "the platform of station A", "crosses an end"});
  testing::ExpectInputError([&] { (void)AreaOfRunningLine(up, 1'925'000, 4'000'000, 3'000'000, "s.json: wayside_splits[0]"); },
                            "s.json", {"wayside_splits[0]", "virtual-block boundaries"});
}

// @verifies REQ-MB-020
TEST(SimGroundLine, ALineTheGroundRefusesNamesTheEntry) {
  nlohmann::json j = TestLineJson();
  // two fixed-block platforms that overlap: valid JSON shapes, refused by the ground
  Up(j)["stations"][1]["platform_begin_mm"] = 1'900'000;
  Up(j)["stations"][1]["platform_end_mm"] = 2'100'000;
  Up(j)["stations"][1]["stop_mm"] = 2'050'000;
  const Line line = ParseLine(j.dump(), "overlap.json");
  const RunningLine& up = line.Running("up");
  const GroundLine gl = BuildGroundLine(line, up, mb::wayside::MarginPolicy::kReportedCorrection, 500);
  testing::ExpectInputError([&] { (void)CreateGround(line, up, gl, 2); }, "overlap.json",
                            {"running line 'up': the ground refuses the line: FixedBlockInvalid", "fixed-block platforms[1]"});
}

// ---- scenario files --------------------------------------------------------------------

nlohmann::json MinimalScenario() {
  return nlohmann::json::parse(R"({
    "schema": "railproof/scenario/1", "name": "t", "line": "sim_test_line", "running_line": "up",
    "duration_s": 60, "step_ms": 100, "seed": 1,
    "channel": {"loss_probability": 0.0, "max_delay_ms": 0},
    "trains": [{"id": 2, "length_m": 100, "max_speed_kmh": 100, "accel_mps2": 0.8,
                "service_decel_mps2": 0.8, "emergency_decel_mps2": 1.2,
                "initial_front_m": 500, "depart_s": 0}]})");
}

void ExpectScenarioError(const std::function<void(nlohmann::json&)>& mutate, const std::vector<std::string>& fragments,
                         bool against_line = false) {
  nlohmann::json j = MinimalScenario();
  mutate(j);
  testing::ExpectInputError(
      [&] {
        const Scenario sc = ParseScenario(j.dump(), "bad_scenario.json");
        if (against_line) {
          const Line line = LoadLine(DataDir() / "sim_test_line.json");
          CheckScenarioAgainstLine(sc, SelectRunningLine(sc, line));
        }
      },
      "bad_scenario.json", fragments);
}

TEST(SimScenarioFile, ParsesAndFillsDefaultsFromTheParameters) {
  nlohmann::json j = MinimalScenario();
  j["duration_s"] = 600;  // the copies depart before the end
  j["trains"][0]["repeat"] = {{"count", 3}, {"interval_s", 120}};
  j["trains"][0]["stops"] = {{{"station", "A"}, {"dwell_s", 30}}};
  j["faults"] = {{{"type", "radio_loss"}, {"train", 3}, {"from_s", 10}, {"to_s", 20}},
                 {{"type", "possession"}, {"begin_m", 7000}, {"end_m", 7400}, {"from_s", 5}, {"to_s", 50}}};
  const Scenario sc = ParseScenario(j.dump(), "s.json");
  EXPECT_EQ(sc.ground_cycle_ms, 500);
  EXPECT_EQ(sc.report_period_ms, 1000);
  ASSERT_EQ(sc.trains.size(), 3U);
  EXPECT_EQ(sc.trains[2].id, 4);
  EXPECT_EQ(sc.trains[2].enter_ms, 240'000);
  EXPECT_EQ(sc.trains[2].depart_ms, 240'000);
  EXPECT_EQ(sc.trains[1].stops.at(0).dwell_ms, 30'000);
  EXPECT_DOUBLE_EQ(sc.trains[0].performance.max_speed_mps, 100.0 / 3.6);
  ASSERT_EQ(sc.faults.size(), 2U);
  EXPECT_EQ(sc.faults[1].begin_mm, 7'000'000);
  EXPECT_EQ(sc.faults[0].type, FaultType::kRadioLoss);
}

TEST(SimScenarioFile, BadScenarioFilesGiveOneLineErrorsNamingTheEntry) {
  // unknown keys are the schema's (railproof_testgen validate); the reader guards the values
  ExpectScenarioError([](auto& j) { j["trains"][0]["length_m"] = 1e300; }, {"trains[0].length_m", "value 1e+300 is outside (0, 2000]"});
  ExpectScenarioError([](auto& j) { j.erase("seed"); }, {"missing key 'seed'"});
  ExpectScenarioError([](auto& j) { j["channel"]["loss_probability"] = 1.5; }, {"channel.loss_probability", "probability"});
  ExpectScenarioError([](auto& j) { j["channel"]["max_delay_ms"] = -1; }, {"channel.max_delay_ms"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["length_m"] = "long"; }, {"trains[0].length_m", "expected a number"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["id"] = 1; }, {"trains[0].id", "ground id"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["emergency_decel_mps2"] = 0.5; }, {"trains[0].emergency_decel_mps2"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["depart_s"] = 5; j["trains"][0]["enter_s"] = 10; },
                      {"trains[0].depart_s", "before the train enters"});
  ExpectScenarioError([](auto& j) { j["trains"].push_back(j["trains"][0]); }, {"trains[1].id", "duplicate train id 2"});
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "meteor"}, {"from_s", 1}, {"to_s", 2}}}; },
                      {"faults[0].type", "unknown fault type 'meteor'"});
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "radio_loss"}, {"train", 9}, {"from_s", 1}, {"to_s", 2}}}; },
                      {"faults[0].train", "unknown train 9"});
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "radio_loss"}, {"train", 2}, {"from_s", 5}, {"to_s", 2}}}; },
                      {"faults[0].to_s", "window end not after its start"});
  ExpectScenarioError([](auto& j) { j["step_ms"] = 300; }, {"ground_cycle_ms 500 is not a multiple of step_ms 300"});
  ExpectScenarioError([](auto& j) { j["schema"] = "x"; }, {"schema", "unsupported schema"});
  ExpectScenarioError([](auto& j) { j["gap"] = {{"leader", 2}, {"follower", 2}, {"from_s", 1}, {"to_s", 2}}; },
                      {"gap.follower", "follower equals leader"});
  ExpectScenarioError([](auto& j) { j["line"] = "../etc/x"; }, {"line", "plain line name"});
  ExpectScenarioError([](auto& j) { j["wayside_splits"] = {{{"at_m", 4000}, {"overlap_m", 500}}, {{"at_m", 4800}, {"overlap_m", 500}}}; },
                      {"wayside_splits[1].at_m", "after the previous split's overlap ends"});
  ExpectScenarioError([](auto& j) { j["wayside_splits"] = {{{"at_m", 4000}, {"overlap_m", 0}}}; },
                      {"wayside_splits[0].overlap_m"});
  // against the line
  ExpectScenarioError([](auto& j) { j["trains"][0]["stops"] = {{{"station", "Q"}, {"dwell_s", 1}}}; },
                      {"trains[0].stops[0].station", "unknown station 'Q'", "(has: A, B)"}, true);
  ExpectScenarioError([](auto& j) { j["trains"][0]["initial_front_m"] = 50; }, {"trains[0].initial_front_m", "lies off"}, true);
  ExpectScenarioError([](auto& j) { j["running_line"] = "left"; }, {"running_line: unknown running line 'left' on line 'sim_test_line' (has: up, down)"}, true);
  ExpectScenarioError([](auto& j) { j["line"] = "other_line"; }, {"line: the scenario names line 'other_line'"}, true);
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "siding_request"}, {"route", 7}, {"from_s", 1}, {"to_s", 2}}}; },
                      {"faults[0]", "unknown route 7"}, true);
  // low-adhesion sections: sorted and disjoint, a condition that reduces the adhesion, known
  // trains, on the line
  const auto sections = [](auto& j, const nlohmann::json& s) { j["low_adhesion"] = {{"sections", s}}; };
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 400}}}); },
                      {"low_adhesion.sections[0].end_m", "section end not after its begin"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 900}}, {{"begin_m", 800}, {"end_m", 1000}}}); },
                      {"low_adhesion.sections[1].begin_m", "before the end of the previous one (900 m)"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 900}, {"rail", "icy"}}}); },
                      {"low_adhesion.sections[0].rail", "unknown rail condition 'icy'"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 900}, {"factor", 0}}}); },
                      {"low_adhesion.sections[0].factor", "outside (0, 1]"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 900}, {"rail", "dry"}}}); },
                      {"low_adhesion.sections[0]", "does not reduce the adhesion"});
  ExpectScenarioError([&](auto& j) { sections(j, nlohmann::json::array()); }, {"low_adhesion.sections", "no low-adhesion section"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 500}, {"end_m", 900}}}); j["low_adhesion"]["trains"] = {9}; },
                      {"low_adhesion.trains[0]", "unknown train 9"});
  ExpectScenarioError([&](auto& j) { sections(j, {{{"begin_m", 9500}, {"end_m", 10500}}}); },
                      {"low_adhesion.sections[0]", "low-adhesion section [9500000, 10500000) mm lies off running line 'up'"}, true);
}

// Huge but finite values: refused before a conversion to mm or ms, and before they can turn
// the motion into NaN or put a train or a fault after the end
// of the run, where it would silently never act while the run reports PASS.
TEST(SimScenarioFile, HugeValuesAndTimesAfterTheEndAreRefused) {
  ExpectScenarioError([](auto& j) { j["trains"][0]["initial_front_m"] = 1e300; },
                      {"bad_scenario.json: trains[0].initial_front_m: value 1e+300 m is outside [0, 1e+07]"});
  ExpectScenarioError([](auto& j) { j["handover_secure_ahead_m"] = 1e300; },
                      {"bad_scenario.json: handover_secure_ahead_m: value 1e+300 m is outside [0, 1e+07]"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["resistance"] = {{"a0", 1.5}, {"a1", 0.02}, {"a2", 1e300}}; },
                      {"bad_scenario.json: trains[0].resistance.a2: value 1e+300 N/kN per (km/h)^2 is outside [0, 1]"});
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "possession"}, {"begin_m", 100}, {"end_m", 1e300}, {"from_s", 1}, {"to_s", 2}}}; },
                      {"bad_scenario.json: faults[0].end_m: value 1e+300 m is outside [0, 1e+07]"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["depart_s"] = 1e300; },
                      {"bad_scenario.json: trains[0].depart_s: value 1e+300 s is outside [0, 604800]"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["depart_s"] = 60; },
                      {"bad_scenario.json: trains[0].depart_s: the train departs at 60 s, at or after the end of the "
                       "scenario (duration_s 60)"});
  ExpectScenarioError([](auto& j) { j["trains"][0]["repeat"] = {{"count", 3}, {"interval_s", 35}}; },
                      {"bad_scenario.json: trains[0].repeat.interval_s: copy 2 departs at 70 s, at or after the end of "
                       "the scenario (duration_s 60)"});
  ExpectScenarioError([](auto& j) { j["faults"] = {{{"type", "radio_loss"}, {"train", 2}, {"from_s", 61}, {"to_s", 70}}}; },
                      {"bad_scenario.json: faults[0].from_s: the fault begins at 61 s, at or after the end of the "
                       "scenario (duration_s 60)"});
  ExpectScenarioError([](auto& j) { j["duration_s"] = 1e-6; },
                      {"bad_scenario.json: duration_s: the scenario is shorter than one step (step_ms 100)"});
  testing::ExpectInputError([] { (void)ParseScenario(R"({"schema": "railproof/scenario/1", "trains": [{"id": 2, "id": 3}]})", "s.json"); },
                            "s.json", {"s.json: trains[0]: duplicate key 'id'"});
}

TEST(SimScenarioFile, EveryProvidedScenarioParses) {
  const auto dir = std::filesystem::path(RAILPROOF_TEST_SOURCE_DIR) / "spec" / "scenarios";
  std::size_t n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") {
      continue;
    }
    ++n;
    EXPECT_NO_THROW({
      const Scenario sc = LoadScenario(entry.path());
      EXPECT_EQ(sc.name, entry.path().stem().string()) << "file name and scenario name differ";
    }) << entry.path();
  }
  EXPECT_GE(n, 7U);
}

}  // namespace
}  // namespace railproof::sim
