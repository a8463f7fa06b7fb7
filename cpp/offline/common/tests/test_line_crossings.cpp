// Level-crossing data of the line JSON (REQ-LC-016): the provided D4 line loads with the
// crossing fields, and the loader rejects a crossing outside the line (including its road
// width), a width or warning time that is not positive, a warning time below
// min_warning_time_ms and overlapping crossings, naming the file, the crossing and the reason.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/generated/lc_params.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/testing/gen_data.hpp"
#include "railproof/testing/input_error.hpp"

namespace railproof::offline {
namespace {

std::filesystem::path GenLinesDir() { return testing::GenDir() / "lines"; }

nlohmann::json D4Json() {
  std::ifstream in(GenLinesDir() / "d4_local_line.json");
  return nlohmann::json::parse(in);
}

// The first crossing of the up running line of the D4 line (LC01, centre 1500 m, 6 m wide).
nlohmann::json& FirstCrossing(nlohmann::json& j) { return j["running_lines"][0]["level_crossings"][0]; }

// Inserts a copy of the first crossing as crossing `index` of the up running line, named `id`,
// centred at `position_mm` and, if given, `width_mm` wide.
void InsertCrossing(nlohmann::json& j, std::size_t index, const std::string& id, std::int64_t position_mm,
                    std::optional<std::int64_t> width_mm = std::nullopt) {
  auto& lcs = j["running_lines"][0]["level_crossings"];
  nlohmann::json c = lcs[0];
  c["id"] = id;
  c["position_mm"] = position_mm;
  if (width_mm) {
    c["width_mm"] = *width_mm;
  }
  lcs.insert(lcs.begin() + static_cast<std::ptrdiff_t>(index), c);
}

void ExpectCrossingError(const std::function<void(nlohmann::json&)>& mutate, const std::vector<std::string>& fragments) {
  nlohmann::json j = D4Json();
  mutate(j);
  testing::ExpectInputError([&] { (void)ParseLine(j.dump(), "bad_line.json"); }, "bad_line.json", fragments);
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, ProvidedLineCarriesWidthAndWarningTime) {
  const Line line = LoadLine(GenLinesDir() / "d4_local_line.json");
  const RunningLine& up = line.Running("up");
  const RunningLine& down = line.Running("down");
  ASSERT_EQ(up.level_crossings.size(), 12U);
  ASSERT_EQ(down.level_crossings.size(), 12U);
  const LevelCrossing& lc01 = up.level_crossings.front();
  EXPECT_EQ(lc01.id, "LC01");
  EXPECT_EQ(lc01.position_mm, 1'500'000);
  EXPECT_EQ(lc01.width_mm, 6'000);
  EXPECT_EQ(lc01.warning_time_ms, 30'000);
  EXPECT_EQ(lc01.NearMm(), 1'497'000);
  EXPECT_EQ(lc01.FarMm(), 1'503'000);
  // the down line meets LC01 last, mirrored: 30500 - 1500 m
  EXPECT_EQ(down.level_crossings.back().id, "LC01");
  EXPECT_EQ(down.level_crossings.back().position_mm, 29'000'000);
  for (const auto& lc : up.level_crossings) {
    EXPECT_GE(lc.warning_time_ms, params::lc::min_warning_time_ms) << lc.id;
  }
}

TEST(SimLineCrossings, OddWidthIsRoundedOutwards) {
  LevelCrossing lc{"X", 1'000'000, 7'001, 30'000};
  EXPECT_EQ(lc.NearMm(), 996'499);
  EXPECT_EQ(lc.FarMm(), 1'003'501);
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsACrossingWhoseWidthLeavesTheLine) {
  // centre 2 m from the line start: the 6 m road begins before it
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j)["position_mm"] = 2'000; },
                      {"level_crossings[0] (LC01)", "level crossing LC01 [-1000, 5000) mm", "lies off the line (0, 30500000)"});
  // centre inside, far edge at the line end
  ExpectCrossingError(
      [](nlohmann::json& j) {
        auto& lcs = j["running_lines"][0]["level_crossings"];
        lcs = nlohmann::json::array({lcs[0]});
        lcs[0]["position_mm"] = 30'497'000;
      },
      {"level crossing LC01 [30494000, 30500000) mm", "lies off the line"});
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsAWidthThatIsNotPositive) {
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j)["width_mm"] = 0; },
                      {"(LC01).width_mm", "level crossing LC01: road width 0 mm is not positive"});
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j)["width_mm"] = -6'000; },
                      {"road width -6000 mm is not positive"});
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsAWarningTimeThatIsNotPositive) {
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j)["warning_time_ms"] = 0; },
                      {"(LC01).warning_time_ms", "level crossing LC01: design warning time 0 ms is not positive"});
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsAWarningTimeBelowTheMinimum) {
  const std::int64_t below = params::lc::min_warning_time_ms - 1;
  ExpectCrossingError([below](nlohmann::json& j) { FirstCrossing(j)["warning_time_ms"] = below; },
                      {"(LC01).warning_time_ms", "design warning time " + std::to_string(below) +
                                                     " ms is below min_warning_time_ms " +
                                                     std::to_string(params::lc::min_warning_time_ms)});
  // at the minimum: accepted
  nlohmann::json j = D4Json();
  FirstCrossing(j)["warning_time_ms"] = params::lc::min_warning_time_ms;
  EXPECT_NO_THROW((void)ParseLine(j.dump(), "ok.json"));
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsAWarningTimeAboveTheMaximum) {
  const std::int64_t above = params::lc::max_warning_ms + 1;
  ExpectCrossingError([above](nlohmann::json& j) { FirstCrossing(j)["warning_time_ms"] = above; },
                      {"(LC01).warning_time_ms", "level crossing LC01: design warning time " + std::to_string(above) +
                                                     " ms is above max_warning_ms " +
                                                     std::to_string(params::lc::max_warning_ms) + " ms"});
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsOverlappingCrossings) {
  // [1502000, 1508000) overlaps [1497000, 1503000)
  ExpectCrossingError([](nlohmann::json& j) { InsertCrossing(j, 1, "LC01b", 1'505'000); },
                      {"(LC01b)", "level crossing LC01b [1502000, 1508000) mm overlaps LC01 [1497000, 1503000) mm"});
  // crossings out of order
  ExpectCrossingError(
      [](nlohmann::json& j) {
        FirstCrossing(j)["width_mm"] = 40'000;        // [1480000, 1520000)
        InsertCrossing(j, 1, "B", 1'530'000, 2'000);  // [1529000, 1531000): clear of LC01
        InsertCrossing(j, 2, "C", 1'510'000, 2'000);  // out of order: listed after B
      },
      {"(C)", "must be sorted"});
  // a narrow crossing inside a wide one
  ExpectCrossingError(
      [](nlohmann::json& j) {
        FirstCrossing(j)["width_mm"] = 40'000;  // [1480000, 1520000)
        InsertCrossing(j, 1, "C", 1'515'000, 2'000);
      },
      {"level crossing C [1514000, 1516000) mm overlaps LC01 [1480000, 1520000) mm"});
}

// @verifies REQ-LC-016
TEST(SimLineCrossings, RejectsMissingAndUnknownFields) {
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j).erase("width_mm"); }, {"(LC01)", "width_mm"});
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j).erase("warning_time_ms"); }, {"(LC01)", "warning_time_ms"});
  ExpectCrossingError([](nlohmann::json& j) { FirstCrossing(j)["warning_s"] = 30; }, {"(LC01)", "warning_s"});
}

}  // namespace
}  // namespace railproof::offline
