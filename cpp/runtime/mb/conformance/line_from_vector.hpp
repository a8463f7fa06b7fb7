// The line of an mb vector file's header as a ground configuration (spec/design/mb.md §2
// mapping), shared by the mb conformance runner and the wayside unit's replay of the same
// vectors: virtual blocks, the platform as fixed block and set-back section, the points with
// the automatic main route and the siding route, the handover point, the system boundary,
// margins and times. The header's parameters and its time scale are the inputs.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

#include "../tests/line_data.hpp"
#include "railproof/mb/wayside/ground.hpp"

namespace railproof::mb::conformance {

// The route and handover ids the vectors' commands refer to.
inline constexpr std::uint32_t kMainRouteId = 1;
inline constexpr std::uint32_t kSidingRouteId = 2;
inline constexpr std::uint32_t kHandoverId = 1;

// A [begin, end] pair of the header as a section.
inline wayside::Section SectionOf(const nlohmann::json& a) {
  return wayside::Section{a.at(0).get<std::int64_t>(), a.at(1).get<std::int64_t>()};
}

// The model's line: `p` is the header's "parameters", `tick_ms` its time_ms_per_tick (the
// ground cycle).
inline void BuildLine(const nlohmann::json& p, std::int64_t tick_ms, wayside::test::LineData& d) {
  d.blocks = p.at("blocks_mm").get<std::vector<std::int64_t>>();
  d.fixed = {SectionOf(p.at("platform_mm"))};
  d.setback = d.fixed;  // the platform is the set-back section
  d.points = {wayside::PointsConfig{1, SectionOf(p.at("points_mm"))}};
  const wayside::Section main = SectionOf(p.at("route_main_mm"));
  const wayside::Section pts = SectionOf(p.at("points_mm"));
  d.routes = {wayside::RouteConfig{kMainRouteId, main.begin_mm, main.end_mm, 0, false, true},
              wayside::RouteConfig{kSidingRouteId, pts.begin_mm, pts.end_mm, 0, true, false}};
  d.handovers = {wayside::HandoverConfig{kHandoverId, p.at("handover_mm").get<std::int64_t>()}};
  const nlohmann::json& m = p.at("margins_mm");
  d.boundary = p.at("boundary_mm").get<std::int64_t>();
  wayside::LineConfig& l = d.base;
  l.length_mm = p.at("line_mm").get<std::int64_t>();
  l.margins = wayside::Margins{m.at("train").get<std::int64_t>(),    m.at("fixed_block").get<std::int64_t>(),
                               m.at("route").get<std::int64_t>(),    m.at("handover").get<std::int64_t>(),
                               m.at("boundary").get<std::int64_t>(), m.at("possession").get<std::int64_t>(),
                               m.at("abnormal").get<std::int64_t>(), m.at("eot").get<std::int64_t>()};
  l.policy = wayside::MarginPolicy::kReportedCorrection;
  l.tracking_timeout_ms = p.at("tracking_timeout_ms").get<std::int64_t>();
  l.authority_validity_ms = p.at("validity_ms").get<std::int64_t>();
  l.ground_cycle_ms = tick_ms;
  l.setback_max_mm = l.length_mm;  // the model bounds set-back itself (one unit)
}

}  // namespace railproof::mb::conformance
