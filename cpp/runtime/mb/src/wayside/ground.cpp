// Ground moving-block unit (spec/design/mb.md §2, §3). Mirror of ground_cycle()
// of models/mb.pml: Cycle = steps 1..5 of design §3 in that order.
//
// Complexity of one Cycle: O((trains + unequipped) log(trains) + blocks + routes^2 +
// trains * (log(sections) + secured_handovers_ahead + restrictions)), the last two bounded
// by their capacities (routes^2 <= 256^2 with the default capacity): the
// "trains ahead" obstructions use suffix minima over the trains sorted by front (tracked and
// abnormal separately), in_use uses prefix maxima over ranges sorted by begin / end, the
// occupancy a difference array over the blocks. Sorting is heap sort (std::make_heap +
// std::sort_heap: iterative, in place, no allocation), on total orders (ties by slot), so
// the result does not depend on the sort's stability.
//
// The ground cycle's sections live in files of their own, by section of the design note:
//   ground.cpp               creation and validation, lookups, the cycle, outputs
//   ground_tracking.cpp      tracking (§3.1)
//   ground_interlocking.cpp  in_use, interlocking, possessions, handover, boundary,
//                            restrictions, unequipped occupancy (§3.2, §3.3)
//   ground_stop_limits.cpp   stop limits (§3.4) and occupancy (§3.5)
// Seeded faults (RAILPROOF_FAULT(FAULT_MB_*), spec/design/seeded-faults.md) are active only in
// the test-only schemata variant.
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/wayside/ground.hpp"

#include <algorithm>
#include <limits>

#include "ground_internal.hpp"

#include "railproof/generated/mb_params.hpp"

namespace railproof::mb::wayside {

using namespace ground_detail;  // NOLINT(google-build-using-namespace)

// ---- defaults from spec/parameters/mb.yaml --------------------------------------

// @implements REQ-MB-021
Capacity DefaultCapacity() noexcept {
  namespace p = params::mb;
  static_assert(p::max_trains > 0 && p::max_blocks > 0, "capacities must be positive");
  static_assert(p::ground_cycle_ms > 0 && p::authority_validity_ms > 0, "times must be positive");
  return Capacity{
      static_cast<std::size_t>(p::max_trains),
      static_cast<std::size_t>(p::max_blocks),
      256,   // routes
      256,   // points
      1024,  // sections per list
      256,   // handovers
      64,    // possessions
      64,    // restrictions
      64,    // unequipped sections
      static_cast<std::size_t>(p::authority_validity_ms / p::ground_cycle_ms + 2),
  };
}

// @implements REQ-MB-006
// @implements REQ-MB-019
LineConfig DefaultLineParameters() noexcept {
  namespace p = params::mb;
  LineConfig c{};
  c.length_mm = 0;
  c.margins = Margins{p::margin_preceding_train_mm, p::margin_fixed_block_mm, p::margin_route_end_mm,
                      p::margin_handover_mm,        p::margin_system_boundary_mm, p::margin_possession_mm,
                      p::margin_abnormal_train_mm,  p::margin_end_of_track_mm};
  c.policy = MarginPolicy::kReportedCorrection;
  c.d2 = D2Params{p::d2_rate_ppm, p::d2_tau_ms, p::d2_resolution_mm};
  c.tracking_timeout_ms = p::tracking_timeout_ms;
  c.authority_validity_ms = p::authority_validity_ms;
  c.ground_cycle_ms = p::ground_cycle_ms;
  c.setback_max_mm = p::setback_max_mm;
  return c;
}

// ---- creation and validation (REQ-MB-020, REQ-MB-021) -------------------------------------

Ground::~Ground() = default;

// @implements REQ-MB-020
// @implements REQ-MB-021
Ground::CreateResult Ground::Create(const LineConfig& line, const Capacity& capacity, std::int64_t start_ms) noexcept {
  if (start_ms < 0) {
    return CreateResult{ConfigError::kTimeInvalid, 3, nullptr};
  }
  std::unique_ptr<Ground> g(new (std::nothrow) Ground());
  if (!g) {
    return CreateResult{ConfigError::kOutOfMemory, 0, nullptr};  // GCOVR_EXCL_LINE defensive
  }
  std::size_t entry = 0;
  const ConfigError error = g->Init(line, capacity, entry);
  if (error != ConfigError::kNone) {
    return CreateResult{error, entry, nullptr};
  }
  g->clock_ms_ = start_ms;
  return CreateResult{ConfigError::kNone, 0, std::move(g)};
}

// Line data rules in the order of ConfigError; then one allocation of every container.
// @implements REQ-MB-020
// @implements REQ-MB-021
ConfigError Ground::Init(const LineConfig& line, const Capacity& cap, std::size_t& entry) noexcept {
  entry = 0;
  const std::int64_t len = line.length_mm;
  if (len <= 0 || len > kMaxLineMm) {
    return ConfigError::kLineLengthInvalid;
  }
  const auto blocks = line.blocks_mm;
  if (blocks.size() < 2) {
    return ConfigError::kTooFewBlocks;
  }
  if (blocks.size() - 1 > cap.blocks) {
    return ConfigError::kTooManyBlocks;
  }
  if (blocks[0] != 0) {
    return ConfigError::kBlocksNotFromZero;
  }
  for (std::size_t i = 1; i < blocks.size(); ++i) {
    if (blocks[i] <= blocks[i - 1]) {
      entry = i;
      return ConfigError::kBlocksNotIncreasing;
    }
  }
  if (blocks.back() != len) {
    entry = blocks.size() - 1;
    return ConfigError::kBlocksNotToLineEnd;
  }
  const std::span<const Section> lists[3] = {line.fixed_blocks, line.setback_sections, line.no_stop_sections};
  const ConfigError list_errors[3] = {ConfigError::kFixedBlockInvalid, ConfigError::kSetBackSectionInvalid,
                                      ConfigError::kNoStopSectionInvalid};
  for (std::size_t k = 0; k < 3; ++k) {
    if (lists[k].size() > cap.sections) {
      entry = k;
      return ConfigError::kTooManySections;
    }
  }
  for (std::size_t k = 0; k < 3; ++k) {
    if (!ValidSectionList(lists[k], len, entry)) {
      return list_errors[k];
    }
  }
  // points
  if (line.points.size() > cap.points) {
    return ConfigError::kTooManyPoints;
  }
  if (!UniqueIds(line.points, entry)) {
    return ConfigError::kPointsIdDuplicate;
  }
  for (std::size_t i = 0; i < line.points.size(); ++i) {
    const Section& s = line.points[i].section;
    entry = i;
    if (s.begin_mm < 0 || s.end_mm > len || s.begin_mm >= s.end_mm) {
      return ConfigError::kPointsSectionInvalid;
    }
    if (!std::binary_search(blocks.begin(), blocks.end(), s.begin_mm) ||
        !std::binary_search(blocks.begin(), blocks.end(), s.end_mm)) {
      return ConfigError::kPointsNotOnBlockBoundaries;
    }
  }
  entry = 0;
  // routes
  if (line.routes.size() > cap.routes) {
    return ConfigError::kTooManyRoutes;
  }
  if (!UniqueIds(line.routes, entry)) {
    return ConfigError::kRouteIdDuplicate;
  }
  for (std::size_t i = 0; i < line.routes.size(); ++i) {
    const RouteConfig& r = line.routes[i];
    entry = i;
    if (r.entry_mm < 0 || r.exit_mm > len || r.entry_mm >= r.exit_mm) {
      return ConfigError::kRouteInvalid;
    }
    if (r.points_index >= line.points.size()) {
      return ConfigError::kRouteUnknownPoints;
    }
  }
  entry = 0;
  // handovers
  if (line.handovers.size() > cap.handovers) {
    return ConfigError::kTooManyHandovers;
  }
  if (!UniqueIds(line.handovers, entry)) {
    return ConfigError::kHandoverIdDuplicate;
  }
  for (std::size_t i = 0; i < line.handovers.size(); ++i) {
    const std::int64_t pos = line.handovers[i].position_mm;
    if (pos <= 0 || pos > len || (i > 0 && pos <= line.handovers[i - 1].position_mm)) {
      entry = i;
      return ConfigError::kHandoverInvalid;
    }
  }
  if (line.system_boundary_mm.has_value() && (*line.system_boundary_mm <= 0 || *line.system_boundary_mm > len)) {
    return ConfigError::kSystemBoundaryInvalid;
  }
  const std::int64_t margins[8] = {line.margins.preceding_train_mm, line.margins.fixed_block_mm,
                                   line.margins.route_end_mm,       line.margins.handover_mm,
                                   line.margins.system_boundary_mm, line.margins.possession_mm,
                                   line.margins.abnormal_train_mm,  line.margins.end_of_track_mm};
  for (std::size_t i = 0; i < 8; ++i) {
    if (margins[i] < 0 || margins[i] > kMaxLineMm) {
      entry = i;
      return ConfigError::kMarginInvalid;
    }
  }
  if (line.policy != MarginPolicy::kReportedCorrection && line.policy != MarginPolicy::kD2Buffers) {
    return ConfigError::kPolicyInvalid;
  }
  if (line.d2.rate_ppm < 0 || line.d2.rate_ppm > kPpm) {
    return ConfigError::kD2ParamsInvalid;
  }
  if (line.d2.tau_ms < 0 || line.d2.tau_ms > kMaxTimeMs) {
    entry = 1;
    return ConfigError::kD2ParamsInvalid;
  }
  if (line.d2.resolution_mm < 0 || line.d2.resolution_mm > kMaxLineMm) {
    entry = 2;
    return ConfigError::kD2ParamsInvalid;
  }
  const std::int64_t times[3] = {line.tracking_timeout_ms, line.authority_validity_ms, line.ground_cycle_ms};
  for (std::size_t i = 0; i < 3; ++i) {
    if (times[i] <= 0 || times[i] > kMaxTimeMs) {
      entry = i;
      return ConfigError::kTimeInvalid;
    }
  }
  if (line.setback_max_mm < 0 || line.setback_max_mm > kMaxLineMm) {
    return ConfigError::kSetBackMaxInvalid;
  }
  const std::size_t needed[4] = {cap.trains, cap.possessions, cap.restrictions, cap.unequipped};
  for (std::size_t i = 0; i < 4; ++i) {
    if (needed[i] == 0 || needed[i] >= kNoSlot) {
      entry = i;
      return ConfigError::kCapacityInvalid;
    }
  }
  const auto min_history = static_cast<std::size_t>(line.authority_validity_ms / line.ground_cycle_ms + 2);
  if (cap.history_per_train < min_history || cap.history_per_train >= kNoSlot) {
    return ConfigError::kHistoryTooSmall;
  }

  // ---- copy the configuration, allocate the state and the per-cycle scratch ----
  length_mm_ = len;
  has_boundary_ = line.system_boundary_mm.has_value();
  boundary_mm_ = has_boundary_ ? *line.system_boundary_mm : 0;
  margins_ = line.margins;
  policy_ = line.policy;
  d2_ = line.d2;
  timeout_ms_ = line.tracking_timeout_ms;
  validity_ms_ = line.authority_validity_ms;
  setback_max_mm_ = line.setback_max_mm;
  history_cap_ = cap.history_per_train;

  const std::size_t n_blocks = blocks.size() - 1;
  const std::size_t n_points = line.points.size();
  const std::size_t n_routes = line.routes.size();
  const std::size_t n_handovers = line.handovers.size();
  const std::size_t n_fixed = line.fixed_blocks.size();
  const std::size_t trains = cap.trains;

  bool ok = blocks_.AssignFrom(blocks, blocks.size()) && fixed_blocks_.AssignFrom(line.fixed_blocks, n_fixed) &&
            setback_.AssignFrom(line.setback_sections, line.setback_sections.size()) &&
            no_stop_.AssignFrom(line.no_stop_sections, line.no_stop_sections.size()) &&
            points_.AssignFrom(line.points, n_points) && handovers_.AssignFrom(line.handovers, n_handovers) &&
            routes_.Allocate(n_routes) && handover_ids_.Allocate(n_handovers) &&
            AllocateFull(points_reverse_, n_points);
  if (!ok) {
    return ConfigError::kOutOfMemory;  // GCOVR_EXCL_LINE defensive
  }
  for (const RouteConfig& r : line.routes) {
    (void)routes_.PushBack(RouteState{r, false, false});
  }
  HeapSort(routes_.Span(), [](const RouteState& a, const RouteState& b) { return a.config.id < b.config.id; });
  for (std::size_t i = 0; i < n_handovers; ++i) {
    (void)handover_ids_.PushBack(IdSlot{handovers_[i].id, static_cast<std::uint32_t>(i)});
  }
  HeapSort(handover_ids_.Span(), [](const IdSlot& a, const IdSlot& b) { return a.id < b.id; });
  for (std::size_t i = 0; i < n_points; ++i) {
    points_reverse_[i] = false;
  }

  ok = AllocateFull(trains_, trains) && free_slots_.Allocate(trains) && order_.Allocate(trains) &&
       ids_.Allocate(trains) && AllocateFull(history_, trains * history_cap_) &&
       AllocateFull(handover_secured_, trains * n_handovers) && possessions_.Allocate(cap.possessions) &&
       restrictions_.Allocate(cap.restrictions) && unequipped_.Allocate(cap.unequipped) &&
       ranges_by_begin_.Allocate(trains + cap.unequipped) && prefix_max_end_.Allocate(trains + cap.unequipped) &&
       ends_.Allocate(trains) && prefix_max_protected_.Allocate(trains) && by_front_.Allocate(trains) &&
       suffix_min_rear_tracked_.Allocate(trains + 1) && suffix_min_rear_abnormal_.Allocate(trains + 1) &&
       AllocateFull(fixed_count_, n_fixed) && AllocateFull(fixed_occupant_, n_fixed) &&
       AllocateFull(fixed_next_occupied_, n_fixed + 1) && unset_route_entries_.Allocate(n_routes) &&
       possession_begins_.Allocate(cap.possessions) && unequipped_begins_.Allocate(cap.unequipped) &&
       confirmed_sorted_.Allocate(cap.restrictions) && AllocateFull(occupancy_diff_, n_blocks + 1) &&
       AllocateFull(occupied_, n_blocks) && telegrams_.Allocate(trains);
  if (!ok) {
    return ConfigError::kOutOfMemory;  // GCOVR_EXCL_LINE defensive
  }
  for (std::size_t s = trains; s > 0; --s) {
    trains_[s - 1] = TrainState{};
    (void)free_slots_.PushBack(static_cast<std::uint32_t>(s - 1));  // slot 0 is popped first
  }
  return ConfigError::kNone;
}

// ---- lookups ------------------------------------------------------------------------------

std::optional<std::uint32_t> Ground::SlotOf(std::uint32_t train_id) const noexcept {
  const auto it = std::lower_bound(ids_.begin(), ids_.end(), train_id,
                                   [](const IdSlot& e, std::uint32_t id) { return e.id < id; });
  if (it == ids_.end() || it->id != train_id) {
    return std::nullopt;
  }
  return it->slot;
}

std::optional<std::size_t> Ground::RouteIndex(std::uint32_t route_id) const noexcept {
  const auto it = std::lower_bound(routes_.begin(), routes_.end(), route_id,
                                   [](const RouteState& r, std::uint32_t id) { return r.config.id < id; });
  if (it == routes_.end() || it->config.id != route_id) {
    return std::nullopt;
  }
  return static_cast<std::size_t>(it - routes_.begin());
}

std::optional<std::size_t> Ground::HandoverIndex(std::uint32_t handover_id) const noexcept {
  const auto it = std::lower_bound(handover_ids_.begin(), handover_ids_.end(), handover_id,
                                   [](const IdSlot& e, std::uint32_t id) { return e.id < id; });
  if (it == handover_ids_.end() || it->id != handover_id) {
    return std::nullopt;
  }
  return it->slot;
}

bool Ground::SectionOnLine(const Section& s) const noexcept {
  return s.begin_mm >= 0 && s.end_mm <= length_mm_ && s.begin_mm < s.end_mm;
}

std::optional<BlockPosition> Ground::LocateFront(std::int64_t front_mm) const noexcept {
  return core::LocateFront(blocks_.Span(), front_mm);  // the blocks end at the line's end (Init)
}

// ---- the cycle ----------------------------------------------------------------------------

// Design §3, steps 1..5 in order.
// @implements REQ-MB-004
// @implements REQ-MB-006
// @implements REQ-MB-010
// @implements REQ-MB-024
CycleStatus Ground::Cycle(std::int64_t now_ms) noexcept {
  if (now_ms < clock_ms_) {
    telegrams_.Clear();
    return CycleStatus::kClockWentBack;
  }
  clock_ms_ = now_ms;
  TrackingStep(now_ms);    // 1
  BuildInUseIndex();
  InterlockingStep();      // 2
  PossessionStep();        // 3
  BuildLimitIndex();
  StopLimitStep(now_ms);   // 4
  OccupancyStep();         // 5
  return CycleStatus::kDone;
}

// ---- outputs ------------------------------------------------------------------------------

TrainOutput Ground::TrainAt(std::size_t k) const noexcept {
  const TrainState& t = trains_[order_[k]];
  TrainOutput out{t.id, t.out_abnormal, std::nullopt, t.kind, t.provisional};
  if (t.has_limit) {
    out.limit_mm = t.limit_mm;
  }
  return out;
}

std::optional<TrainOutput> Ground::Train(std::uint32_t train_id) const noexcept {
  const auto slot = SlotOf(train_id);
  if (!slot.has_value()) {
    return std::nullopt;
  }
  const TrainState& t = trains_[*slot];
  TrainOutput out{t.id, t.out_abnormal, std::nullopt, t.kind, t.provisional};
  if (t.has_limit) {
    out.limit_mm = t.limit_mm;
  }
  return out;
}

std::optional<std::int64_t> Ground::ProtectedAuthority(std::uint32_t train_id) const noexcept {
  const auto slot = SlotOf(train_id);
  if (!slot.has_value()) {
    return std::nullopt;
  }
  return Protected(*slot);
}

std::optional<ExtendedRange> Ground::Extended(std::uint32_t train_id) const noexcept {
  const auto slot = SlotOf(train_id);
  if (!slot.has_value()) {
    return std::nullopt;
  }
  return ExtendedRange{trains_[*slot].ext_begin_mm, trains_[*slot].ext_end_mm};
}

bool Ground::RouteSet(std::uint32_t route_id) const noexcept {
  const auto r = RouteIndex(route_id);
  return r.has_value() && routes_[*r].set;
}

bool Ground::RouteRequested(std::uint32_t route_id) const noexcept {
  const auto r = RouteIndex(route_id);
  return r.has_value() && routes_[*r].requested;
}

bool Ground::PointsReverse(std::size_t points_index) const noexcept {
  return points_index < points_reverse_.Size() && points_reverse_[points_index];
}

PossessionState Ground::Possession(std::uint32_t possession_id) const noexcept {
  for (const auto& p : possessions_) {
    if (p.id == possession_id) {
      return p.active ? PossessionState::kActive : PossessionState::kRequested;
    }
  }
  return PossessionState::kNone;
}

bool Ground::RestrictionConfirmed(std::uint32_t restriction_id) const noexcept {
  for (const Restriction& r : restrictions_) {
    if (r.r.id == restriction_id) {
      return r.confirmed;
    }
  }
  return false;
}

bool Ground::HandoverSecured(std::uint32_t train_id, std::uint32_t handover_id) const noexcept {
  const auto slot = SlotOf(train_id);
  const auto h = HandoverIndex(handover_id);
  return slot.has_value() && h.has_value() &&
         handover_secured_[static_cast<std::size_t>(*slot) * handovers_.Size() + *h] != 0;
}

bool Ground::BlockOccupied(std::size_t block) const noexcept {
  return block < occupied_.Size() && occupied_[block] != 0;
}

}  // namespace railproof::mb::wayside
