// libFuzzer target: the line loader (offline::ParseLine, cpp/offline/common/src/line.cpp) on
// any bytes, structure-aware (json_fuzz.hpp). Seeds: the committed corpus and the generated
// lines (build/gen/lines). Oracle: every rejection is the project's input error in the one
// form "<file>: <entry>: <reason>", no crash and no undefined behaviour (ASan+UBSan), and an
// accepted line keeps the rules the simulation, the ground and the studies rely on (REQ-MB-020,
// REQ-LC-016): lengths within the line coordinate range, block boundaries from 0 to the length,
// gradients, speed limits and radio cells covering the line, every section and position on
// it, level crossings inside it with a warning time in [min, max].
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "json_fuzz.hpp"
#include "railproof/core/units.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/offline/line.hpp"

namespace {

namespace off = railproof::offline;
using railproof::fuzz::Require;

const std::string kFile = "line.json";

bool OnLine(const off::Section& s, std::int64_t length) { return 0 <= s.begin_mm && s.begin_mm < s.end_mm && s.end_mm <= length; }

template <typename T, typename SectionOf>
void RequireCover(const std::vector<T>& items, std::int64_t length, SectionOf section, const char* what) {
  std::int64_t at = 0;
  for (const T& i : items) {
    Require(section(i).begin_mm == at && section(i).end_mm > at, what);
    at = section(i).end_mm;
  }
  Require(at == length, what);
}

void CheckAccepted(const off::Line& line) {
  Require(!line.running_lines.empty(), "a running line");
  for (const off::RunningLine& rl : line.running_lines) {
    const std::int64_t l = rl.length_mm;
    Require(l > 0 && l <= railproof::core::kMaxPositionMm, "length within (0, kMaxPositionMm]");
    Require(rl.blocks_mm.size() >= 2 && rl.blocks_mm.front() == 0 && rl.blocks_mm.back() == l &&
                std::adjacent_find(rl.blocks_mm.begin(), rl.blocks_mm.end(), std::greater_equal<>()) == rl.blocks_mm.end(),
            "block boundaries strictly increasing from 0 to the length");
    RequireCover(rl.gradients, l, [](const off::Gradient& g) { return g.section; }, "gradients cover the line");
    RequireCover(rl.speed_limits, l, [](const off::SpeedLimit& s) { return s.section; }, "speed limits cover the line");
    RequireCover(rl.radio_cells, l, [](const off::RadioCell& c) { return c.section; }, "radio cells cover the line");
    for (const auto& s : rl.speed_limits) {
      Require(s.kmh > 0 && s.kmh <= 400, "speed limit within 1..400 km/h");
    }
    for (const auto& c : rl.curves) {
      Require(OnLine(c.section, l) && c.radius_m > 0, "curve on the line with a positive radius");
    }
    for (const auto& p : rl.points) {
      Require(OnLine(p.section, l), "points on the line");
    }
    for (const auto& r : rl.routes) {
      Require(OnLine(r.section, l) && r.id > 0 && rl.FindPoints(r.points) != nullptr, "route on the line with its points");
    }
    for (const auto& s : rl.no_stop_sections) {
      Require(OnLine(s, l), "no-stop section on the line");
    }
    for (std::size_t i = 0; i < rl.balises.size(); ++i) {
      Require(rl.balises[i].position_mm >= 0 && rl.balises[i].position_mm <= l &&
                  (i == 0 || rl.balises[i - 1].position_mm <= rl.balises[i].position_mm),
              "balises sorted, on the line");
    }
    for (const auto& s : rl.stations) {
      Require(OnLine(s.platform, l) && s.stop_mm > s.platform.begin_mm && s.stop_mm <= s.platform.end_mm,
              "station platform on the line, stop on the platform");
    }
    for (std::size_t i = 0; i < rl.level_crossings.size(); ++i) {
      const off::LevelCrossing& c = rl.level_crossings[i];
      Require(c.NearMm() > 0 && c.FarMm() < l && (i == 0 || rl.level_crossings[i - 1].FarMm() <= c.NearMm()),
              "level crossings inside the line, not overlapping");
      Require(c.warning_time_ms >= railproof::params::lc::min_warning_time_ms &&
                  c.warning_time_ms <= railproof::params::lc::max_warning_ms,
              "design warning time within [min_warning_time_ms, max_warning_ms]");
    }
    Require(!rl.system_boundary_mm || (*rl.system_boundary_mm > 0 && *rl.system_boundary_mm <= l),
            "system boundary on the line");
    // what the simulation asks of the line, at and beyond both ends
    for (const std::int64_t at : {std::int64_t{-1}, std::int64_t{0}, l / 2, l, l + 1}) {
      (void)rl.GradientAt(at);
      (void)rl.SpeedLimitAt(at);
    }
  }
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

// @verifies REQ-MB-020
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { CheckAccepted(off::ParseLine(text, kFile)); });
}
