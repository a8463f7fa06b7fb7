// The line data of one running line as the ground (mb::wayside::Ground) takes it: builds a
// mb::wayside::LineConfig (margins, times and D2 parameters from the generated parameters)
// from a loaded RunningLine and creates the Ground. A line the ground refuses gives an
// InputError naming the file and the entry (REQ-MB-020).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "railproof/offline/line.hpp"
#include "railproof/mb/wayside/ground.hpp"

namespace railproof::sim {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// Owns the arrays the LineConfig spans point into (keep it alive while `config` is used).
struct GroundLine {
  std::vector<std::int64_t> blocks_mm;
  std::vector<core::Section> fixed_blocks;      // platforms of fixed-block stations
  std::vector<core::Section> setback_sections;  // platforms of set-back stations
  std::vector<core::Section> no_stop_sections;
  std::vector<mb::wayside::PointsConfig> points;       // id = index + 1 (line ids are strings)
  std::vector<mb::wayside::RouteConfig> routes;
  std::vector<mb::wayside::HandoverConfig> handovers;  // id = index + 1
  mb::wayside::LineConfig config{};
};

// `line` is the file the running line came from (for messages), `index` its position in
// running_lines.
// @implements REQ-MB-020
GroundLine BuildGroundLine(const Line& line, const RunningLine& running, mb::wayside::MarginPolicy policy,
                           std::int64_t ground_cycle_ms);

// The part [begin_mm, end_mm] of a running line that one wayside unit holds, in its own
// chainage (0 at begin_mm): the virtual blocks, the platforms, no-stop sections, points, routes
// and radio handovers inside it, and `boundary_mm` (line chainage) as its system boundary.
// Begin and end must be block boundaries, and no item may cross them: InputError
// "<scenario>: <where>: <reason>" naming the item.
RunningLine AreaOfRunningLine(const RunningLine& running, std::int64_t begin_mm, std::int64_t end_mm,
                              std::optional<std::int64_t> boundary_mm, const std::string& where);

// Capacity for `trains` trains on this line (the defaults, sized down to the line).
mb::wayside::Capacity GroundCapacity(const GroundLine& gl, std::size_t trains);

// Ground::Create, InputError "<file>: running_lines (<id>): the ground refuses the line: <error>
// (<list>[<entry>])" on a configuration error.
// @implements REQ-MB-020
std::unique_ptr<mb::wayside::Ground> CreateGround(const Line& line, const RunningLine& running, const GroundLine& gl,
                                              std::size_t trains, std::int64_t start_ms = 0);

}  // namespace railproof::sim
