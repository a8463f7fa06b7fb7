// A wayside line configuration together with the data it refers to (LineConfig holds spans):
// the unit tests, the conformance runner and the bench keep the line's vectors here and take
// the LineConfig over them from Config().
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "railproof/mb/wayside/ground.hpp"

namespace railproof::mb::wayside::test {

struct LineData {
  std::vector<std::int64_t> blocks;
  std::vector<Section> fixed;
  std::vector<Section> setback;
  std::vector<Section> no_stop;
  std::vector<PointsConfig> points;
  std::vector<RouteConfig> routes;
  std::vector<HandoverConfig> handovers;
  std::optional<std::int64_t> boundary;
  LineConfig base = DefaultLineParameters();  // every other field of the configuration

  // The configuration over this object's data (valid while it lives unchanged).
  [[nodiscard]] LineConfig Config() const {
    LineConfig c = base;
    c.blocks_mm = blocks;
    c.fixed_blocks = fixed;
    c.setback_sections = setback;
    c.no_stop_sections = no_stop;
    c.points = points;
    c.routes = routes;
    c.handovers = handovers;
    c.system_boundary_mm = boundary;
    return c;
  }
};

}  // namespace railproof::mb::wayside::test
