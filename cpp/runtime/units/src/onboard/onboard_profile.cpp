// The merged permitted-speed profile (onboard_profile.hpp). It connects REQ-MB-015 (the held
// temporary restrictions) with REQ-BR-004 (restrictions as ceilings in the patterns) and
// REQ-LC-001 (the earliest arrival over the permitted speeds); each is implemented by its
// module.
#include "railproof/units/onboard_profile.hpp"

#include <algorithm>
#include <limits>

#include "railproof/core/seeded_fault.hpp"

namespace railproof::units {

MergeResult MergeRestrictions(std::span<const core::RestrictionSegment> line,
                              std::span<const messages::SpeedRestriction> held,
                              std::span<core::RestrictionSegment> out, std::span<std::int64_t> scratch) noexcept {
  const std::size_t need = MergeCapacity(line.size(), held.size());
  if (out.size() < need || scratch.size() < need) {
    return {};
  }
  // A restriction lost here would let the patterns run through it at line speed.
  const std::size_t first_held = RAILPROOF_FAULT(FAULT_UNIT_RESTRICTION_DROPPED) && !held.empty() ? 1 : 0;
  std::size_t points = 0;
  for (const core::RestrictionSegment& s : line) {
    scratch[points++] = s.begin_mm;
    scratch[points++] = s.end_mm;
  }
  for (std::size_t h = first_held; h < held.size(); ++h) {
    scratch[points++] = held[h].begin_mm;
    scratch[points++] = held[h].end_mm;
  }
  const auto cuts = scratch.first(points);
  std::sort(cuts.begin(), cuts.end());
  const auto distinct = static_cast<std::size_t>(std::unique(cuts.begin(), cuts.end()) - cuts.begin());
  std::size_t count = 0;
  std::size_t l = 0;  // the first line limit not yet left behind
  for (std::size_t i = 0; i + 1 < distinct; ++i) {
    const std::int64_t a = cuts[i];
    const std::int64_t b = cuts[i + 1];
    std::int64_t limit = std::numeric_limits<std::int64_t>::max();
    while (l < line.size() && line[l].end_mm <= a) {
      ++l;
    }
    if (l < line.size() && line[l].begin_mm <= a) {
      limit = line[l].limit_mm_s;
    }
    // [a, b) lies between two cuts: a restriction covers all of it or none of it
    for (std::size_t h = first_held; h < held.size(); ++h) {
      if (held[h].begin_mm <= a && b <= held[h].end_mm) {
        limit = std::min(limit, held[h].speed_mm_s);
      }
    }
    if (limit != std::numeric_limits<std::int64_t>::max()) {
      out[count++] = core::RestrictionSegment{a, b, limit};
    }
  }
  return {true, count};
}

}  // namespace railproof::units
