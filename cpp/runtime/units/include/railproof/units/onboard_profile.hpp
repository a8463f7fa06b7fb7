// The permitted-speed profile of the on-board unit (spec/design/br.md §2, spec/design/lc.md §2):
// the line's static speed limits and the temporary speed restrictions held on board
// (mb::onboard::SpeedRestrictionStore, REQ-MB-015) merged into the non-overlapping, sorted
// segments br::PatternCalculator::SetProfile and lc::EarliestArrivalMs take, each with the
// lowest limit that applies there (the lower limit governs).
//
// Runtime rules: no heap (the caller gives the storage), no exceptions, bounded loops.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "railproof/core/track.hpp"
#include "railproof/messages/stop_limit.hpp"

namespace railproof::units {

// Storage the merge needs for `line` limits and `held` restrictions (segments and breakpoints).
[[nodiscard]] constexpr std::size_t MergeCapacity(std::size_t line, std::size_t held) noexcept {
  return 2 * (line + held);
}

struct MergeResult {
  bool ok = false;         // false: out or scratch shorter than MergeCapacity (nothing merged)
  std::size_t count = 0;   // segments written to out
};

// Cuts the line at every begin and end of `line` (sorted, non-overlapping: a profile
// SetProfile accepted) and `held` (any order, may overlap) and writes, in ascending order, every
// piece covered by at least one of them with the lowest limit covering it. Adjacent pieces are
// not joined (an earliest-arrival time summed per piece is never later: the safe side).
// O((n + m) log(n + m) + (n + m) m).
MergeResult MergeRestrictions(std::span<const core::RestrictionSegment> line,
                              std::span<const messages::SpeedRestriction> held,
                              std::span<core::RestrictionSegment> out, std::span<std::int64_t> scratch) noexcept;

}  // namespace railproof::units
