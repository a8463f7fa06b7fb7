// The benchmark line of the moving-block ground and of the wayside unit around it
// (bench_ground.cpp, cpp/runtime/units/bench): a 500 km line of 10,000 virtual blocks of 50 m
// with a station (fixed block) every 5 km, a junction (points, two routes) every 10 km, a
// radio handover point every 2 km, a few no-stop sections and a system boundary 1 km before
// the end. Benchmark code (allocates).
#pragma once

#include <cstdint>

#include "railproof/mb/wayside/ground.hpp"
#include "../tests/line_data.hpp"

namespace railproof::mb::wayside::bench {

using core::Section;

inline constexpr std::int64_t kBlocks = 10'000;
inline constexpr std::int64_t kBlockMm = 50'000;
inline constexpr std::int64_t kLineMm = kBlocks * kBlockMm;  // 500 km

struct BenchLine : test::LineData {
  BenchLine() {
    base.length_mm = kLineMm;
    boundary = kLineMm - 1'000'000;
    for (std::int64_t b = 0; b <= kBlocks; ++b) {
      blocks.push_back(b * kBlockMm);
    }
    for (std::int64_t km = 5; km < 500; km += 5) {  // a station every 5 km
      fixed.push_back(Section{km * 1'000'000, km * 1'000'000 + 200'000});
    }
    for (std::int64_t km = 7; km < 500; km += 10) {  // a junction every 10 km
      const auto p = static_cast<std::uint32_t>(points.size());
      const std::int64_t at = km * 1'000'000;
      points.push_back(PointsConfig{p, Section{at, at + kBlockMm}});
      routes.push_back(RouteConfig{2 * p + 1, at, at + 2 * kBlockMm, p, false, true});
      routes.push_back(RouteConfig{2 * p + 2, at, at + 2 * kBlockMm, p, true, false});
    }
    for (std::int64_t km = 2; km < 500; km += 2) {  // a handover every 2 km
      handovers.push_back(HandoverConfig{static_cast<std::uint32_t>(km), km * 1'000'000 + 1'000});
    }
    for (std::int64_t km = 3; km < 500; km += 25) {  // a few no-stop sections
      no_stop.push_back(Section{km * 1'000'000 + 500'000, km * 1'000'000 + 600'000});
    }
  }
};

}  // namespace railproof::mb::wayside::bench
