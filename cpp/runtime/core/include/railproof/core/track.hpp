// Track geometry shared by the train-side and ground-side modules: half-open sections of
// the running line, gradient and speed-restriction segments (spec/design/mb.md §2,
// spec/design/br.md §2). Positions are chainage in mm (int64) on one running line,
// increasing in the running direction; a section is [begin_mm, end_mm).
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>

namespace railproof::core {

// Half-open section [begin_mm, end_mm) of the running line.
struct Section {
  std::int64_t begin_mm;
  std::int64_t end_mm;
};

// True iff the half-open ranges [a_begin, a_end) and [b_begin, b_end) overlap.
constexpr bool Overlaps(std::int64_t a_begin, std::int64_t a_end, std::int64_t b_begin,
                        std::int64_t b_end) noexcept {
  return a_begin < b_end && b_begin < a_end;
}

// Gradient [begin, end) of the running line; positions not covered by a segment are level
// (0). permille_x10 > 0 rises in the running direction.
struct GradientSegment {
  std::int64_t begin_mm = 0;
  std::int64_t end_mm = 0;
  std::int64_t permille_x10 = 0;
};

// Speed restriction [begin, end) (static line limit or temporary restriction).
struct RestrictionSegment {
  std::int64_t begin_mm = 0;
  std::int64_t end_mm = 0;
  std::int64_t limit_mm_s = 0;
};

// Estimated front x_m with its front error e_f and rear error e_r (odometry length
// correction + permanent re-adhesion margin), measured speed v_m: what the odometry gives
// the braking supervision every cycle (spec/design/br.md §2, spec/design/ra.md §7).
struct PositionEstimate {
  std::int64_t front_mm = 0;
  std::int64_t front_error_mm = 0;
  std::int64_t rear_error_mm = 0;
  std::int64_t speed_mm_s = 0;
  bool standstill = false;  // measured speed zero for the standstill time
};

// A front as the position report carries it: the virtual block holding its foremost
// millimetre (front - 1; block 0 for front 0) and the front's offset from that block's start.
struct BlockPosition {
  std::uint32_t block;
  std::int64_t offset_mm;
};

// The block position of `front_mm` on the virtual-block boundaries `blocks_mm` ([0] = 0,
// strictly increasing, back() = the line's end); none for a front off the line.
[[nodiscard]] inline std::optional<BlockPosition> LocateFront(std::span<const std::int64_t> blocks_mm,
                                                              std::int64_t front_mm) noexcept {
  if (blocks_mm.empty() || front_mm < 0 || front_mm > blocks_mm.back()) {
    return std::nullopt;
  }
  if (front_mm == 0) {
    return BlockPosition{0, 0};
  }
  const auto it = std::upper_bound(blocks_mm.begin(), blocks_mm.end(), front_mm - 1);
  const auto block = static_cast<std::size_t>(it - blocks_mm.begin()) - 1;
  return BlockPosition{static_cast<std::uint32_t>(block), front_mm - blocks_mm[block]};
}

}  // namespace railproof::core
