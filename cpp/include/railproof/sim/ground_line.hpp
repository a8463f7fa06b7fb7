// The line data of one running line as the ground (wayside::Ground) takes it: builds a
// wayside::LineConfig (margins, times and D2 parameters from the generated parameters)
// from a loaded RunningLine and creates the Ground. A line the ground refuses gives an
// InputError naming the file and the entry (REQ-MB-020).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "railproof/sim/line.hpp"
#include "railproof/wayside/ground.hpp"

namespace railproof::sim {

// Owns the arrays the LineConfig spans point into (keep it alive while `config` is used).
struct GroundLine {
  std::vector<std::int64_t> blocks_mm;
  std::vector<wayside::Section> fixed_blocks;      // platforms of fixed-block stations
  std::vector<wayside::Section> setback_sections;  // platforms of set-back stations
  std::vector<wayside::Section> no_stop_sections;
  std::vector<wayside::PointsConfig> points;       // id = index + 1 (line ids are strings)
  std::vector<wayside::RouteConfig> routes;
  std::vector<wayside::HandoverConfig> handovers;  // id = index + 1
  wayside::LineConfig config{};
};

// `line` is the file the running line came from (for messages), `index` its position in
// running_lines.
// @implements REQ-MB-020
GroundLine BuildGroundLine(const Line& line, const RunningLine& running, wayside::MarginPolicy policy,
                           std::int64_t ground_cycle_ms);

// Capacity for `trains` trains on this line (the defaults, sized down to the line).
wayside::Capacity GroundCapacity(const GroundLine& gl, std::size_t trains);

// Ground::Create, InputError "<file>: running_lines (<id>): the ground refuses the line: <error>
// (<list>[<entry>])" on a configuration error.
// @implements REQ-MB-020
std::unique_ptr<wayside::Ground> CreateGround(const Line& line, const RunningLine& running, const GroundLine& gl,
                                              std::size_t trains, std::int64_t start_ms = 0);

}  // namespace railproof::sim
