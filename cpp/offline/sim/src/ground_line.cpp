#include "railproof/sim/ground_line.hpp"

#include <algorithm>
#include <string>

namespace railproof::sim {

namespace {

// Which list of the running line an error entry of Ground::Create refers to.
std::string EntryName(mb::wayside::ConfigError e, std::size_t entry) {
  using mb::wayside::ConfigError;
  const std::string i = "[" + std::to_string(entry) + "]";
  switch (e) {
    case ConfigError::kTooFewBlocks:
    case ConfigError::kTooManyBlocks:
    case ConfigError::kBlocksNotFromZero:
    case ConfigError::kBlocksNotIncreasing:
    case ConfigError::kBlocksNotToLineEnd: return "blocks_mm" + i;
    case ConfigError::kFixedBlockInvalid: return "fixed-block platforms" + i;
    case ConfigError::kSetBackSectionInvalid: return "set-back platforms" + i;
    case ConfigError::kNoStopSectionInvalid: return "no_stop_sections" + i;
    case ConfigError::kTooManyPoints:
    case ConfigError::kPointsIdDuplicate:
    case ConfigError::kPointsSectionInvalid:
    case ConfigError::kPointsNotOnBlockBoundaries: return "points" + i;
    case ConfigError::kTooManyRoutes:
    case ConfigError::kRouteIdDuplicate:
    case ConfigError::kRouteInvalid:
    case ConfigError::kRouteUnknownPoints: return "routes" + i;
    case ConfigError::kTooManyHandovers:
    case ConfigError::kHandoverIdDuplicate:
    case ConfigError::kHandoverInvalid: return "handovers" + i;
    case ConfigError::kSystemBoundaryInvalid: return "system_boundary_mm";
    case ConfigError::kMarginInvalid: return "margins" + i;
    case ConfigError::kD2ParamsInvalid: return "d2 parameters" + i;
    case ConfigError::kTimeInvalid: return "times" + i;
    default: return "entry " + std::to_string(entry);
  }
}

}  // namespace

GroundLine BuildGroundLine(const Line& line, const RunningLine& rl, mb::wayside::MarginPolicy policy,
                           std::int64_t ground_cycle_ms) {
  (void)line;
  GroundLine gl;
  gl.blocks_mm = rl.blocks_mm;
  for (const auto& s : rl.stations) {
    if (s.fixed_block) {
      gl.fixed_blocks.push_back({s.platform.begin_mm, s.platform.end_mm});
    }
    if (s.setback) {
      gl.setback_sections.push_back({s.platform.begin_mm, s.platform.end_mm});
    }
  }
  const auto by_begin = [](const core::Section& a, const core::Section& b) { return a.begin_mm < b.begin_mm; };
  std::stable_sort(gl.fixed_blocks.begin(), gl.fixed_blocks.end(), by_begin);
  std::stable_sort(gl.setback_sections.begin(), gl.setback_sections.end(), by_begin);
  for (const auto& s : rl.no_stop_sections) {
    gl.no_stop_sections.push_back({s.begin_mm, s.end_mm});
  }
  for (std::size_t i = 0; i < rl.points.size(); ++i) {
    gl.points.push_back({static_cast<std::uint32_t>(i + 1), {rl.points[i].section.begin_mm, rl.points[i].section.end_mm}});
  }
  for (const auto& r : rl.routes) {
    std::uint32_t index = 0;
    for (std::size_t i = 0; i < rl.points.size(); ++i) {
      if (rl.points[i].id == r.points) {
        index = static_cast<std::uint32_t>(i);
      }
    }
    gl.routes.push_back({static_cast<std::uint32_t>(r.id), r.section.begin_mm, r.section.end_mm, index, r.reverse,
                         r.automatic});
  }
  for (std::size_t i = 0; i < rl.handovers.size(); ++i) {
    gl.handovers.push_back({static_cast<std::uint32_t>(i + 1), rl.handovers[i].position_mm});
  }
  std::stable_sort(gl.handovers.begin(), gl.handovers.end(),
                   [](const auto& a, const auto& b) { return a.position_mm < b.position_mm; });

  mb::wayside::LineConfig c = mb::wayside::DefaultLineParameters();
  c.length_mm = rl.length_mm;
  c.blocks_mm = gl.blocks_mm;
  c.fixed_blocks = gl.fixed_blocks;
  c.setback_sections = gl.setback_sections;
  c.no_stop_sections = gl.no_stop_sections;
  c.points = gl.points;
  c.routes = gl.routes;
  c.handovers = gl.handovers;
  c.system_boundary_mm = rl.system_boundary_mm;
  c.policy = policy;
  c.ground_cycle_ms = ground_cycle_ms;
  gl.config = c;
  return gl;
}

RunningLine AreaOfRunningLine(const RunningLine& rl, std::int64_t begin_mm, std::int64_t end_mm,
                              std::optional<std::int64_t> boundary_mm, const std::string& where) {
  const auto fail = [&](const std::string& reason) { throw InputError(where + ": " + reason); };
  const auto on_block = [&](std::int64_t x) { return std::binary_search(rl.blocks_mm.begin(), rl.blocks_mm.end(), x); };
  if (!on_block(begin_mm) || !on_block(end_mm)) {
    fail("the unit's line [" + std::to_string(begin_mm) + ", " + std::to_string(end_mm) +
         "] mm must begin and end at virtual-block boundaries of running line '" + rl.id + "'");
  }
  // an item inside the part, shifted; none outside it; an item across an end refused
  const auto part = [&](const Section& s, const std::string& item) -> std::optional<Section> {
    if (s.end_mm <= begin_mm || s.begin_mm >= end_mm) {
      return std::nullopt;
    }
    if (s.begin_mm < begin_mm || s.end_mm > end_mm) {
      fail(item + " [" + std::to_string(s.begin_mm) + ", " + std::to_string(s.end_mm) + "] mm crosses an end of the unit's line [" +
           std::to_string(begin_mm) + ", " + std::to_string(end_mm) + "] mm");
    }
    return Section{s.begin_mm - begin_mm, s.end_mm - begin_mm};
  };
  RunningLine a;
  a.id = rl.id;
  a.length_mm = end_mm - begin_mm;
  for (const std::int64_t b : rl.blocks_mm) {
    if (b >= begin_mm && b <= end_mm) {
      a.blocks_mm.push_back(b - begin_mm);
    }
  }
  for (const Station& s : rl.stations) {
    if (const auto p = part(s.platform, "the platform of station " + s.name)) {
      Station c = s;
      c.platform = *p;
      c.stop_mm -= begin_mm;
      a.stations.push_back(c);
    }
  }
  for (const Section& s : rl.no_stop_sections) {
    if (const auto p = part(s, "a no-stop section")) {
      a.no_stop_sections.push_back(*p);
    }
  }
  for (const Points& pt : rl.points) {
    if (const auto p = part(pt.section, "points " + pt.id)) {
      a.points.push_back(Points{pt.id, *p});
    }
  }
  for (const Route& r : rl.routes) {
    if (const auto p = part(r.section, "route " + std::to_string(r.id))) {
      Route c = r;
      c.section = *p;
      a.routes.push_back(c);
    }
  }
  for (const Handover& h : rl.handovers) {
    if (h.position_mm > begin_mm && h.position_mm < end_mm) {
      a.handovers.push_back(Handover{h.id, h.position_mm - begin_mm});
    }
  }
  if (boundary_mm) {
    a.system_boundary_mm = *boundary_mm - begin_mm;
  }
  return a;
}

mb::wayside::Capacity GroundCapacity(const GroundLine& gl, std::size_t trains) {
  mb::wayside::Capacity cap = mb::wayside::DefaultCapacity();
  cap.trains = std::max<std::size_t>(1, trains);
  cap.blocks = std::max<std::size_t>(1, gl.blocks_mm.size() - 1);
  cap.routes = gl.routes.size();
  cap.points = gl.points.size();
  cap.sections = std::max({gl.fixed_blocks.size(), gl.setback_sections.size(), gl.no_stop_sections.size()});
  cap.handovers = gl.handovers.size();
  cap.possessions = std::max<std::size_t>(cap.possessions, 4);
  cap.restrictions = std::max<std::size_t>(cap.restrictions, 4);
  cap.unequipped = std::max<std::size_t>(cap.unequipped, 1);
  const auto validity = gl.config.authority_validity_ms;
  const auto cycle = gl.config.ground_cycle_ms;
  cap.history_per_train = std::max<std::size_t>(cap.history_per_train,
                                                static_cast<std::size_t>(validity / std::max<std::int64_t>(1, cycle)) + 2);
  return cap;
}

std::unique_ptr<mb::wayside::Ground> CreateGround(const Line& line, const RunningLine& rl, const GroundLine& gl,
                                              std::size_t trains, std::int64_t start_ms) {
  auto created = mb::wayside::Ground::Create(gl.config, GroundCapacity(gl, trains), start_ms);
  if (created.error != mb::wayside::ConfigError::kNone) {
    throw InputError(line.file + ": running line '" + rl.id + "': the ground refuses the line: " +
                     mb::wayside::ToString(created.error) + " (" + EntryName(created.error, created.entry) + ")");
  }
  return std::move(created.ground);
}

}  // namespace railproof::sim
