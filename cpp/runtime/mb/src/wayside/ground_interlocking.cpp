// Ground unit: in_use, interlocking, possessions, handover, boundary, restrictions and
// unequipped occupancy (spec/design/mb.md §3.2, §3.3; REQ-MB-011..015).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/wayside/ground.hpp"

#include <algorithm>
#include <limits>

#include "ground_internal.hpp"

namespace railproof::mb::wayside {

using namespace ground_detail;  // NOLINT(google-build-using-namespace)

// ---- in_use (design §3.2) -----------------------------------------------------------------

// Sorted views for O(log n) in_use queries during one Cycle: ranges (trains' extended ranges
// and unequipped sections) by begin with prefix maxima of their ends; trains by extended
// front end with prefix maxima of protected(t).
void Ground::BuildInUseIndex() noexcept {
  ranges_by_begin_.Clear();
  ends_.Clear();
  for (const std::uint32_t slot : order_) {
    const TrainState& t = trains_[slot];
    (void)ranges_by_begin_.PushBack(Section{t.ext_begin_mm, t.ext_end_mm});
    const auto p = Protected(slot);
    (void)ends_.PushBack(Section{t.ext_end_mm, p.has_value() ? *p : kMinusInf});
  }
  for (const Unequipped& u : unequipped_) {
    (void)ranges_by_begin_.PushBack(u.range);
  }
  const auto less = [](const Section& a, const Section& b) {
    return a.begin_mm < b.begin_mm || (a.begin_mm == b.begin_mm && a.end_mm < b.end_mm);
  };
  HeapSort(ranges_by_begin_.Span(), less);
  HeapSort(ends_.Span(), less);
  prefix_max_end_.Clear();
  std::int64_t m = kMinusInf;
  for (const Section& s : ranges_by_begin_) {
    m = std::max(m, s.end_mm);
    (void)prefix_max_end_.PushBack(m);
  }
  prefix_max_protected_.Clear();
  m = kMinusInf;
  for (const Section& s : ends_) {  // begin_mm = extended front end, end_mm = protected
    m = std::max(m, s.end_mm);
    (void)prefix_max_protected_.PushBack(m);
  }
}

// in_use(section, m): some train's extended range (or an unequipped section) overlaps the
// section, or a train's extended front end is <= section.begin and its protected authority
// is > section.begin - m (design §3.2). Uses the index of the current Cycle.
// @implements REQ-MB-011
// @implements REQ-MB-013
// @implements REQ-MB-014
bool Ground::InUse(const Section& s, std::int64_t margin_mm) const noexcept {
  // ranges with begin < s.end: a prefix of ranges_by_begin_
  const auto n_before = static_cast<std::size_t>(
      std::lower_bound(ranges_by_begin_.begin(), ranges_by_begin_.end(), s.end_mm,
                       [](const Section& r, std::int64_t x) { return r.begin_mm < x; }) -
      ranges_by_begin_.begin());
  if (n_before > 0 && prefix_max_end_[n_before - 1] > s.begin_mm) {
    return true;
  }
  if (RAILPROOF_FAULT(FAULT_MB_LOCK_IGNORES_AUTHORITY)) {
    return false;
  }
  // trains with extended front end <= s.begin: a prefix of ends_
  const auto n_behind = static_cast<std::size_t>(
      std::upper_bound(ends_.begin(), ends_.end(), s.begin_mm,
                       [](std::int64_t x, const Section& r) { return x < r.begin_mm; }) -
      ends_.begin());
  return n_behind > 0 && prefix_max_protected_[n_behind - 1] > s.begin_mm - margin_mm;
}

// The same predicate evaluated directly on the current state (for commands between cycles).
// @implements REQ-MB-013
bool Ground::InUseDirect(const Section& s, std::int64_t margin_mm) const noexcept {
  for (const Unequipped& u : unequipped_) {
    if (Overlaps(u.range.begin_mm, u.range.end_mm, s.begin_mm, s.end_mm)) {
      return true;
    }
  }
  for (const std::uint32_t slot : order_) {
    const TrainState& t = trains_[slot];
    if (Overlaps(t.ext_begin_mm, t.ext_end_mm, s.begin_mm, s.end_mm)) {
      return true;
    }
    if (!RAILPROOF_FAULT(FAULT_MB_LOCK_IGNORES_AUTHORITY) && t.ext_end_mm <= s.begin_mm) {
      const auto p = Protected(slot);
      if (p.has_value() && *p > s.begin_mm - margin_mm) {
        return true;
      }
    }
  }
  return false;
}

// ---- interlocking (design §3.2, REQ-MB-011..013) -----------------------------------------

// Two different routes over the same points conflict.
// @implements REQ-MB-012
bool Ground::Conflicts(std::size_t a, std::size_t b) const noexcept {
  return a != b && routes_[a].config.points_index == routes_[b].config.points_index;
}

// @implements REQ-MB-012
bool Ground::ConflictingSet(std::size_t r) const noexcept {
  for (std::size_t a = 0; a < routes_.Size(); ++a) {
    if (routes_[a].set && Conflicts(r, a)) {
      return true;
    }
  }
  return false;
}

// @implements REQ-MB-012
bool Ground::ConflictingRequested(std::size_t r) const noexcept {
  for (std::size_t a = 0; a < routes_.Size(); ++a) {
    if (routes_[a].requested && Conflicts(r, a)) {
      return true;
    }
  }
  return false;
}

// Move the points if needed and set the route (callers checked the preconditions).
// @implements REQ-MB-011
void Ground::SetRoute(std::size_t r) noexcept {
  points_reverse_[routes_[r].config.points_index] = routes_[r].config.reverse;
  routes_[r].set = true;
}

// Design §3.2, steps 2.1-2.3, routes in ascending id.
// @implements REQ-MB-011
// @implements REQ-MB-012
// @implements REQ-MB-013
void Ground::InterlockingStep() noexcept {
  const std::int64_t m = margins_.route_end_mm;
  const std::size_t n = routes_.Size();
  // 2.1 release set automatic routes conflicting with a pending request, if not in use
  for (std::size_t r = 0; r < n; ++r) {
    if (!routes_[r].requested) {
      continue;
    }
    for (std::size_t a = 0; a < n; ++a) {
      RouteState& ra = routes_[a];
      if (ra.set && ra.config.automatic && Conflicts(r, a) &&
          !InUse(Section{ra.config.entry_mm, ra.config.exit_mm}, m)) {
        ra.set = false;
      }
    }
  }
  // 2.2 pending requests
  for (std::size_t r = 0; r < n; ++r) {
    if (!routes_[r].requested) {
      continue;
    }
    const Section& points = points_[routes_[r].config.points_index].section;
    if (!ConflictingSet(r) && !InUse(points, m)) {
      SetRoute(r);
      routes_[r].requested = false;
    }
  }
  // 2.3 automatic routes
  for (std::size_t a = 0; a < n; ++a) {
    if (!routes_[a].config.automatic || routes_[a].set) {
      continue;
    }
    const Section& points = points_[routes_[a].config.points_index].section;
    if (!ConflictingSet(a) && !ConflictingRequested(a) && !InUse(points, m)) {
      SetRoute(a);
    }
  }
}

// @implements REQ-MB-013
CommandStatus Ground::RequestRoute(std::uint32_t route_id) noexcept {
  const auto r = RouteIndex(route_id);
  if (!r.has_value()) {
    return CommandStatus::kUnknownRoute;
  }
  routes_[*r].requested = true;
  return CommandStatus::kAccepted;
}

// Approach locking (REQ-MB-013): a set route is released only when nothing is in use.
// @implements REQ-MB-013
CommandStatus Ground::FreeRoute(std::uint32_t route_id) noexcept {
  const auto r = RouteIndex(route_id);
  if (!r.has_value()) {
    return CommandStatus::kUnknownRoute;
  }
  RouteState& route = routes_[*r];
  route.requested = false;
  if (route.set) {
    if (InUseDirect(Section{route.config.entry_mm, route.config.exit_mm}, margins_.route_end_mm)) {
      return CommandStatus::kRefusedInUse;
    }
    route.set = false;
  }
  return CommandStatus::kAccepted;
}

// ---- possessions (REQ-MB-014) -------------------------------------------------------------

// @implements REQ-MB-014
CommandResult Ground::RequestPossession(Section range) noexcept {
  return AddWithNextId(possessions_, next_possession_id_, SectionOnLine(range),
                       [&](std::uint32_t id) { return PossessionEntry{id, range, false}; });
}

// @implements REQ-MB-014
CommandStatus Ground::CancelPossession(std::uint32_t possession_id) noexcept {
  return EraseById(possessions_, possession_id, [](const PossessionEntry& p) { return p.id; });
}

// Design §3.3: a requested possession becomes active iff it is not in use.
// @implements REQ-MB-014
void Ground::PossessionStep() noexcept {
  for (PossessionEntry& p : possessions_) {
    if (p.active) {
      continue;
    }
    if (RAILPROOF_FAULT(FAULT_MB_POSSESSION_NO_CONFIRM) || !InUse(p.range, margins_.possession_mm)) {
      p.active = true;
    }
  }
}

// ---- handover, boundary, restrictions, unequipped occupancy -------------------------------

// @implements REQ-MB-017
CommandStatus Ground::SecureHandover(std::uint32_t train_id, std::uint32_t handover_id) noexcept {
  const auto slot = SlotOf(train_id);
  if (!slot.has_value()) {
    return CommandStatus::kUnknownTrain;
  }
  const auto h = HandoverIndex(handover_id);
  if (!h.has_value()) {
    return CommandStatus::kUnknownHandover;
  }
  handover_secured_[static_cast<std::size_t>(*slot) * handovers_.Size() + *h] = 1;
  return CommandStatus::kAccepted;
}

// @implements REQ-MB-023
CommandStatus Ground::AcceptAtBoundary(bool accepted) noexcept {
  if (!has_boundary_) {
    return CommandStatus::kNoSystemBoundary;
  }
  boundary_accepted_ = accepted;
  return CommandStatus::kAccepted;
}

// @implements REQ-MB-015
CommandResult Ground::RequestSpeedRestriction(Section range, std::int64_t speed_mm_s) noexcept {
  return AddWithNextId(restrictions_, next_restriction_id_,
                       SectionOnLine(range) && speed_mm_s > 0 && speed_mm_s <= kMaxSpeedMmS, [&](std::uint32_t id) {
                         return Restriction{SpeedRestriction{id, range.begin_mm, range.end_mm, speed_mm_s}, false};
                       });
}

// @implements REQ-MB-015
CommandStatus Ground::ConfirmSpeedRestriction(std::uint32_t restriction_id) noexcept {
  for (Restriction& r : restrictions_) {
    if (r.r.id == restriction_id) {
      if (r.confirmed) {
        return CommandStatus::kNotConfirmable;
      }
      r.confirmed = true;
      return CommandStatus::kAccepted;
    }
  }
  return CommandStatus::kUnknownId;
}

// @implements REQ-MB-015
CommandStatus Ground::CancelSpeedRestriction(std::uint32_t restriction_id) noexcept {
  return EraseById(restrictions_, restriction_id, [](const Restriction& r) { return r.r.id; });
}

// @implements REQ-MB-016
CommandResult Ground::ReportUnequippedOccupancy(Section range) noexcept {
  return AddWithNextId(unequipped_, next_unequipped_id_, SectionOnLine(range),
                       [&](std::uint32_t id) { return Unequipped{id, range}; });
}

// @implements REQ-MB-016
CommandStatus Ground::ClearUnequippedOccupancy(std::uint32_t occupancy_id) noexcept {
  return EraseById(unequipped_, occupancy_id, [](const Unequipped& u) { return u.id; });
}

}  // namespace railproof::mb::wayside
