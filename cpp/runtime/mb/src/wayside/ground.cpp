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
// Seeded faults (negative tests): each FAULT_MB_* macro below, when defined, injects exactly
// one fault; unit tests (cpp/tests/unit/wayside) and the conformance vectors must detect it.
// They are never defined in the railproof_wayside library.
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/wayside/ground.hpp"

#include <algorithm>
#include <limits>

#include "railproof/generated/mb_params.hpp"

namespace railproof::mb::wayside {
namespace {

constexpr std::uint32_t kNoSlot = std::numeric_limits<std::uint32_t>::max();
constexpr std::int64_t kPlusInf = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMinusInf = std::numeric_limits<std::int64_t>::min();
constexpr std::int64_t kPpm = 1'000'000;
constexpr std::int64_t kMsPerS = 1'000;

// ceil(a / b) for a >= 0, b > 0.
constexpr std::int64_t CeilDiv(std::int64_t a, std::int64_t b) noexcept { return (a + b - 1) / b; }

// In-place, non-recursive, allocation-free sort (heap sort).
template <typename T, typename Less>
void HeapSort(std::span<T> v, Less less) noexcept {
  std::make_heap(v.begin(), v.end(), less);
  std::sort_heap(v.begin(), v.end(), less);
}

bool ValidSectionList(std::span<const Section> list, std::int64_t length_mm, std::size_t& entry) noexcept {
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Section& s = list[i];
    const bool bad = s.begin_mm < 0 || s.end_mm > length_mm || s.begin_mm >= s.end_mm ||
                     (i > 0 && s.begin_mm < list[i - 1].end_mm);
    if (bad) {
      entry = i;
      return false;
    }
  }
  return true;
}

template <typename T>
bool CopyInto(FixedVector<T>& dst, std::span<const T> src, std::size_t capacity) noexcept {
  if (!dst.Allocate(capacity)) {
    return false;  // GCOVR_EXCL_LINE defensive: out of memory
  }
  for (const T& x : src) {
    if (!dst.PushBack(x)) {
      return false;  // GCOVR_EXCL_LINE unreachable: capacity >= src.size() checked
    }
  }
  return true;
}

template <typename T>
bool AllocateFull(FixedVector<T>& v, std::size_t n) noexcept {
  return v.Allocate(n) && v.Resize(n);
}

}  // namespace

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
  for (std::size_t i = 0; i < line.points.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (line.points[j].id == line.points[i].id) {
        entry = i;
        return ConfigError::kPointsIdDuplicate;
      }
    }
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
  for (std::size_t i = 0; i < line.routes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (line.routes[j].id == line.routes[i].id) {
        entry = i;
        return ConfigError::kRouteIdDuplicate;
      }
    }
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
  for (std::size_t i = 0; i < line.handovers.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (line.handovers[j].id == line.handovers[i].id) {
        entry = i;
        return ConfigError::kHandoverIdDuplicate;
      }
    }
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

  bool ok = CopyInto(blocks_, blocks, blocks.size()) && CopyInto(fixed_blocks_, line.fixed_blocks, n_fixed) &&
            CopyInto(setback_, line.setback_sections, line.setback_sections.size()) &&
            CopyInto(no_stop_, line.no_stop_sections, line.no_stop_sections.size()) &&
            CopyInto(points_, line.points, n_points) && CopyInto(handovers_, line.handovers, n_handovers) &&
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
  if (front_mm < 0 || front_mm > length_mm_) {
    return std::nullopt;
  }
  if (front_mm == 0) {
    return BlockPosition{0, 0};
  }
  // the block holding the foremost millimetre front_mm - 1
  const auto it = std::upper_bound(blocks_.begin(), blocks_.end(), front_mm - 1);
  const auto block = static_cast<std::size_t>(it - blocks_.begin()) - 1;
  return BlockPosition{static_cast<std::uint32_t>(block), front_mm - blocks_[block]};
}

// ---- tracking (REQ-MB-001..005, REQ-MB-016, REQ-MB-019) -------------------------------------

// Extended occupied range (design §3.6): [front - length - corr_r, front + corr_f); for an
// abnormal train the front end is max(frozen, front + corr_f).
// @implements REQ-MB-003
// @implements REQ-MB-004
void Ground::UpdateExtended(TrainState& t) noexcept {
  t.ext_begin_mm = t.front_mm - t.length_mm - t.corr_rear_mm;
  t.ext_end_mm = t.front_mm + t.corr_front_mm;
  if (t.abnormal && t.has_frozen && t.frozen_mm > t.ext_end_mm) {
    t.ext_end_mm = t.frozen_mm;
  }
}

// Length corrections by the margin policy (design §3.6): the reported correction at both
// ends, or the D2 safety buffers l_f = ceil(r|x - x_m|) + ceil(v tau) + l_c,
// l_r = ceil(r|x - x_m|) + l_c (rounded up: conservative).
// @implements REQ-MB-002
// @implements REQ-MB-003
// @implements REQ-MB-019
// @implements REQ-BR-016
void Ground::SetPosition(TrainState& t, std::int64_t front_mm, std::int64_t correction_mm,
                         std::int64_t last_balise_mm, std::int64_t speed_mm_s) noexcept {
  t.front_mm = front_mm;
  if (front_mm > t.furthest_front_mm) {
    t.furthest_front_mm = front_mm;
  }
  if (policy_ == MarginPolicy::kD2Buffers) {
    const std::int64_t run = front_mm >= last_balise_mm ? front_mm - last_balise_mm : last_balise_mm - front_mm;
    const std::int64_t odometry = CeilDiv(d2_.rate_ppm * run, kPpm);
    const std::int64_t delay = CeilDiv(speed_mm_s * d2_.tau_ms, kMsPerS);
    t.corr_front_mm = odometry + delay + d2_.resolution_mm;
    t.corr_rear_mm = odometry + d2_.resolution_mm;
  } else {
    t.corr_front_mm = correction_mm;
    t.corr_rear_mm = correction_mm;
  }
  UpdateExtended(t);
}

// @implements REQ-MB-016
RegisterStatus Ground::RegisterTrain(const TrainRegistration& reg) noexcept {
  if (SlotOf(reg.id).has_value()) {
    return RegisterStatus::kDuplicateId;
  }
  if (free_slots_.Empty()) {
    return RegisterStatus::kCapacityExceeded;
  }
  if (reg.length_mm <= 0 || reg.length_mm > length_mm_) {
    return RegisterStatus::kLengthInvalid;
  }
  if (reg.front_mm < 0 || reg.front_mm > length_mm_) {
    return RegisterStatus::kFrontOffLine;
  }
  if (reg.correction_mm < 0 || reg.correction_mm > length_mm_) {
    return RegisterStatus::kCorrectionInvalid;
  }
  if (reg.initial != InitialPosition::kStabledProvisional && reg.initial != InitialPosition::kEntryBalise) {
    return RegisterStatus::kInitialInvalid;
  }
  // The registration's uncertainty extends both ends; under D2 plus l_c (speed 0).
  const std::int64_t extra = policy_ == MarginPolicy::kD2Buffers ? d2_.resolution_mm : 0;
  const Section range{reg.front_mm - reg.length_mm - reg.correction_mm - extra, reg.front_mm + reg.correction_mm + extra};
  for (const Unequipped& u : unequipped_) {
    if (Overlaps(u.range.begin_mm, u.range.end_mm, range.begin_mm, range.end_mm)) {
      return RegisterStatus::kPositionOccupied;
    }
  }
  for (const std::uint32_t other : order_) {
    if (Overlaps(trains_[other].ext_begin_mm, trains_[other].ext_end_mm, range.begin_mm, range.end_mm)) {
      return RegisterStatus::kPositionOccupied;
    }
  }
  const std::uint32_t slot = free_slots_[free_slots_.Size() - 1];
  (void)free_slots_.Resize(free_slots_.Size() - 1);
  TrainState& t = trains_[slot];
  t = TrainState{};
  t.id = reg.id;
  t.used = true;
  t.length_mm = reg.length_mm;
  t.front_mm = reg.front_mm;
  t.furthest_front_mm = reg.front_mm;
  t.last_report_ms = clock_ms_;
  t.provisional = reg.initial == InitialPosition::kStabledProvisional;
  t.kind = Obstruction::kNone;
  t.corr_front_mm = reg.correction_mm + extra;
  t.corr_rear_mm = reg.correction_mm + extra;
  UpdateExtended(t);
  const std::size_t n_handovers = handovers_.Size();
  for (std::size_t h = 0; h < n_handovers; ++h) {
    handover_secured_[slot * n_handovers + h] = 0;
  }
  // ids_ stays sorted: shift the larger ids up by one (bounded by the capacity)
  const auto pos = static_cast<std::size_t>(
      std::lower_bound(ids_.begin(), ids_.end(), reg.id, [](const IdSlot& e, std::uint32_t id) { return e.id < id; }) -
      ids_.begin());
  (void)ids_.Resize(ids_.Size() + 1);
  for (std::size_t k = ids_.Size() - 1; k > pos; --k) {
    ids_[k] = ids_[k - 1];
  }
  ids_[pos] = IdSlot{reg.id, slot};
  (void)order_.PushBack(slot);
  return RegisterStatus::kRegistered;
}

CommandStatus Ground::RemoveTrain(std::uint32_t train_id) noexcept {
  const auto slot = SlotOf(train_id);
  if (!slot.has_value()) {
    return CommandStatus::kUnknownTrain;
  }
  for (std::size_t k = 0; k < ids_.Size(); ++k) {
    if (ids_[k].id == train_id) {
      ids_.EraseAt(k);
      break;
    }
  }
  for (std::size_t k = 0; k < order_.Size(); ++k) {
    if (order_[k] == *slot) {
      order_.EraseAt(k);
      break;
    }
  }
  trains_[*slot] = TrainState{};
  (void)free_slots_.PushBack(*slot);
  return CommandStatus::kAccepted;
}

// Backward movement (REQ-MB-005): the front positions from the new front up to the furthest
// front reached must lie inside one set-back section (front inside [b, e): b < front <= e).
// @implements REQ-MB-005
bool Ground::SetBackAllowed(std::int64_t new_front, std::int64_t furthest) const noexcept {
  // the last section with begin < new_front
  const auto it = std::lower_bound(setback_.begin(), setback_.end(), new_front,
                                   [](const Section& s, std::int64_t x) { return s.begin_mm < x; });
  if (it == setback_.begin()) {
    return false;
  }
  const Section& s = *(it - 1);
  return s.begin_mm < new_front && furthest <= s.end_mm;
}

// Report validation in the order of ReportStatus, then the new position (design §3: stamped
// with the time of the last cycle).
// @implements REQ-MB-001
// @implements REQ-MB-002
// @implements REQ-MB-004
// @implements REQ-MB-005
// @implements REQ-MB-016
ReportStatus Ground::OnReport(const PositionReport& r) noexcept {
  const auto slot = SlotOf(r.train_id);
  if (!slot.has_value()) {
    return ReportStatus::kUnknownTrain;
  }
  TrainState& t = trains_[*slot];
  const std::size_t n_blocks = blocks_.Size() - 1;
  if (r.front_block >= n_blocks) {
    return ReportStatus::kBlockOutOfRange;
  }
  const std::int64_t block_begin = blocks_[r.front_block];
  const std::int64_t block_len = blocks_[r.front_block + 1] - block_begin;
  if (r.offset_mm < 0 || r.offset_mm > block_len) {
    return ReportStatus::kOffsetOutOfBlock;
  }
  if (r.length_mm != t.length_mm) {
    return ReportStatus::kLengthMismatch;
  }
  if (r.correction_mm < 0 || r.correction_mm > length_mm_) {
    return ReportStatus::kCorrectionOutOfRange;
  }
  if (r.last_balise_mm < 0 || r.last_balise_mm > length_mm_) {
    return ReportStatus::kBaliseOffLine;
  }
  if (r.speed_mm_s < 0 || r.speed_mm_s > kMaxSpeedMmS) {
    return ReportStatus::kSpeedOutOfRange;
  }
  if (r.direction != Direction::kNominal) {
    return ReportStatus::kWrongDirection;
  }
  const std::int64_t front = block_begin + r.offset_mm;
  if (front < t.front_mm) {
    if (!SetBackAllowed(front, t.furthest_front_mm)) {
      return ReportStatus::kBackwardMovement;
    }
    if (t.furthest_front_mm - front > setback_max_mm_) {
      return ReportStatus::kSetBackTooFar;
    }
  }
  t.last_report_ms = clock_ms_;
  t.provisional = false;
  t.abnormal = false;  // a valid report restores tracking
  t.has_frozen = false;
  t.frozen_mm = 0;
  SetPosition(t, front, r.correction_mm, r.last_balise_mm, r.speed_mm_s);
  return ReportStatus::kAccepted;
}

// Issued-limit history (design §3.1, §3.6): a ring per train, oldest first.
// @implements REQ-MB-009
void Ground::PruneHistory(std::uint32_t slot, std::int64_t now_ms) noexcept {
  TrainState& t = trains_[slot];
  HistoryEntry* ring = &history_[static_cast<std::size_t>(slot) * history_cap_];
  while (t.hist_count > 0 && now_ms - ring[t.hist_head].issue_ms > validity_ms_) {
    t.hist_head = static_cast<std::uint32_t>((t.hist_head + 1U) % history_cap_);
    --t.hist_count;
  }
}

// Appends (limit, now). With the capacity of Init (validity / cycle + 2) and a regular cycle
// the ring never overflows; should it (irregular calls), the two oldest entries are merged
// into (max limit, newer time), which can only enlarge protected(t) (safe side).
// @implements REQ-MB-009
void Ground::AppendHistory(std::uint32_t slot, std::int64_t limit_mm, std::int64_t now_ms) noexcept {
  TrainState& t = trains_[slot];
  HistoryEntry* ring = &history_[static_cast<std::size_t>(slot) * history_cap_];
  if (t.hist_count >= history_cap_) {
    const std::uint32_t second = static_cast<std::uint32_t>((t.hist_head + 1U) % history_cap_);
    ring[second].limit_mm = std::max(ring[second].limit_mm, ring[t.hist_head].limit_mm);
    t.hist_head = second;
    --t.hist_count;
  }
  ring[(t.hist_head + t.hist_count) % history_cap_] = HistoryEntry{limit_mm, now_ms};
  ++t.hist_count;
}

// protected(t) (design §3.6).
// @implements REQ-MB-009
// @implements REQ-MB-013
std::optional<std::int64_t> Ground::Protected(std::uint32_t slot) const noexcept {
  const TrainState& t = trains_[slot];
  const HistoryEntry* ring = &history_[static_cast<std::size_t>(slot) * history_cap_];
  bool has = false;
  std::int64_t best = 0;
  for (std::uint32_t k = 0; k < t.hist_count; ++k) {
    const std::int64_t l = ring[(t.hist_head + k) % history_cap_].limit_mm;
    if (!has || l > best) {
      best = l;
      has = true;
    }
  }
  if (t.abnormal && t.has_frozen && (!has || t.frozen_mm > best)) {
    best = t.frozen_mm;
    has = true;
  }
  if (!has) {
    return std::nullopt;
  }
  return best;
}

// Design §3.1: per train in registration order, drop expired history entries, then the
// tracking timeout (strict: exactly tracking_timeout_ms after the last report the train is
// still tracked).
// @implements REQ-MB-004
// @implements REQ-MB-009
void Ground::TrackingStep(std::int64_t now_ms) noexcept {
  for (const std::uint32_t slot : order_) {
    PruneHistory(slot, now_ms);
    TrainState& t = trains_[slot];
    const bool timed_out = RAILPROOF_FAULT(FAULT_MB_TIMEOUT_INCLUSIVE) ? now_ms - t.last_report_ms >= timeout_ms_
                                                                       : now_ms - t.last_report_ms > timeout_ms_;
    if (!t.abnormal && timed_out) {
      const auto p = Protected(slot);
      t.abnormal = true;
      t.has_frozen = p.has_value();
      t.frozen_mm = p.has_value() ? *p : 0;
      UpdateExtended(t);
    }
  }
}

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
  if (!SectionOnLine(range)) {
    return CommandResult{CommandStatus::kInvalidRange, 0};
  }
  if (possessions_.Full()) {
    return CommandResult{CommandStatus::kCapacityExceeded, 0};
  }
  const std::uint32_t id = next_possession_id_++;
  (void)possessions_.PushBack(PossessionEntry{id, range, false});
  return CommandResult{CommandStatus::kAccepted, id};
}

// @implements REQ-MB-014
CommandStatus Ground::CancelPossession(std::uint32_t possession_id) noexcept {
  for (std::size_t i = 0; i < possessions_.Size(); ++i) {
    if (possessions_[i].id == possession_id) {
      possessions_.EraseAt(i);
      return CommandStatus::kAccepted;
    }
  }
  return CommandStatus::kUnknownId;
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
  if (!SectionOnLine(range) || speed_mm_s <= 0 || speed_mm_s > kMaxSpeedMmS) {
    return CommandResult{CommandStatus::kInvalidRange, 0};
  }
  if (restrictions_.Full()) {
    return CommandResult{CommandStatus::kCapacityExceeded, 0};
  }
  const std::uint32_t id = next_restriction_id_++;
  (void)restrictions_.PushBack(Restriction{SpeedRestriction{id, range.begin_mm, range.end_mm, speed_mm_s}, false});
  return CommandResult{CommandStatus::kAccepted, id};
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
  for (std::size_t i = 0; i < restrictions_.Size(); ++i) {
    if (restrictions_[i].r.id == restriction_id) {
      restrictions_.EraseAt(i);
      return CommandStatus::kAccepted;
    }
  }
  return CommandStatus::kUnknownId;
}

// @implements REQ-MB-016
CommandResult Ground::ReportUnequippedOccupancy(Section range) noexcept {
  if (!SectionOnLine(range)) {
    return CommandResult{CommandStatus::kInvalidRange, 0};
  }
  if (unequipped_.Full()) {
    return CommandResult{CommandStatus::kCapacityExceeded, 0};
  }
  const std::uint32_t id = next_unequipped_id_++;
  (void)unequipped_.PushBack(Unequipped{id, range});
  return CommandResult{CommandStatus::kAccepted, id};
}

// @implements REQ-MB-016
CommandStatus Ground::ClearUnequippedOccupancy(std::uint32_t occupancy_id) noexcept {
  for (std::size_t i = 0; i < unequipped_.Size(); ++i) {
    if (unequipped_[i].id == occupancy_id) {
      unequipped_.EraseAt(i);
      return CommandStatus::kAccepted;
    }
  }
  return CommandStatus::kUnknownId;
}

// ---- stop limits (design §3.4) ------------------------------------------------------------

// Sorted views for the stop-limit step: trains by front with suffix minima of the extended
// rear (tracked and abnormal separately), fixed-block occupants, and the ascending positions
// of unset automatic route entries, possession starts and unequipped sections.
void Ground::BuildLimitIndex() noexcept {
  by_front_.Clear();
  for (const std::uint32_t slot : order_) {
    (void)by_front_.PushBack(Keyed{trains_[slot].front_mm, slot});
  }
  HeapSort(by_front_.Span(),
           [](const Keyed& a, const Keyed& b) { return a.key < b.key || (a.key == b.key && a.slot < b.slot); });
  const std::size_t n = by_front_.Size();
  (void)suffix_min_rear_tracked_.Resize(n + 1);
  (void)suffix_min_rear_abnormal_.Resize(n + 1);
  suffix_min_rear_tracked_[n] = kPlusInf;
  suffix_min_rear_abnormal_[n] = kPlusInf;
  for (std::size_t i = n; i > 0; --i) {
    const TrainState& t = trains_[by_front_[i - 1].slot];
    const std::int64_t rear = t.ext_begin_mm;
    suffix_min_rear_tracked_[i - 1] = suffix_min_rear_tracked_[i];
    suffix_min_rear_abnormal_[i - 1] = suffix_min_rear_abnormal_[i];
    std::int64_t& target = t.abnormal ? suffix_min_rear_abnormal_[i - 1] : suffix_min_rear_tracked_[i - 1];
    target = std::min(target, rear);
  }

  // fixed blocks: occupant count and one occupant (kNoSlot for an unequipped section)
  const std::size_t nf = fixed_blocks_.Size();
  for (std::size_t f = 0; f < nf; ++f) {
    fixed_count_[f] = 0;
    fixed_occupant_[f] = kNoSlot;
  }
  const auto mark = [this, nf](std::int64_t begin, std::int64_t end, std::uint32_t occupant) {
    // first fixed block with end > begin (ends ascend: the list is sorted, non-overlapping)
    auto f = static_cast<std::size_t>(
        std::lower_bound(fixed_blocks_.begin(), fixed_blocks_.end(), begin,
                         [](const Section& s, std::int64_t x) { return s.end_mm <= x; }) -
        fixed_blocks_.begin());
    for (; f < nf && fixed_blocks_[f].begin_mm < end; ++f) {
      if (fixed_count_[f] == 0) {
        fixed_occupant_[f] = occupant;
      }
      ++fixed_count_[f];
    }
  };
  for (const std::uint32_t slot : order_) {
    mark(trains_[slot].ext_begin_mm, trains_[slot].ext_end_mm, slot);
  }
  for (const Unequipped& u : unequipped_) {
    mark(u.range.begin_mm, u.range.end_mm, kNoSlot);
  }
  fixed_next_occupied_[nf] = static_cast<std::uint32_t>(nf);
  for (std::size_t f = nf; f > 0; --f) {
    fixed_next_occupied_[f - 1] =
        fixed_count_[f - 1] > 0 ? static_cast<std::uint32_t>(f - 1) : fixed_next_occupied_[f];
  }

  const auto ascending = [](std::int64_t a, std::int64_t b) { return a < b; };
  unset_route_entries_.Clear();
  for (const RouteState& r : routes_) {
    if (r.config.automatic && !r.set) {
      (void)unset_route_entries_.PushBack(r.config.entry_mm);
    }
  }
  HeapSort(unset_route_entries_.Span(), ascending);
  possession_begins_.Clear();
  for (const PossessionEntry& p : possessions_) {
    (void)possession_begins_.PushBack(p.range.begin_mm);  // requested or active
  }
  HeapSort(possession_begins_.Span(), ascending);
  unequipped_begins_.Clear();
  for (const Unequipped& u : unequipped_) {
    (void)unequipped_begins_.PushBack(u.range.begin_mm);
  }
  HeapSort(unequipped_begins_.Span(), ascending);
  confirmed_sorted_.Clear();
  for (const Restriction& r : restrictions_) {
    if (r.confirmed) {
      (void)confirmed_sorted_.PushBack(r);
    }
  }
  HeapSort(confirmed_sorted_.Span(), [](const Restriction& a, const Restriction& b) {
    return a.r.begin_mm < b.r.begin_mm || (a.r.begin_mm == b.r.begin_mm && a.r.id < b.r.id);
  });
}

// @implements REQ-MB-006
std::int64_t Ground::MarginOf(Obstruction kind) const noexcept {
  switch (kind) {
    case Obstruction::kPrecedingTrain: return margins_.preceding_train_mm;
    case Obstruction::kFixedBlock: return margins_.fixed_block_mm;
    case Obstruction::kRouteEnd: return margins_.route_end_mm;
    case Obstruction::kHandover: return margins_.handover_mm;
    case Obstruction::kSystemBoundary: return margins_.system_boundary_mm;
    case Obstruction::kPossession: return margins_.possession_mm;
    case Obstruction::kAbnormalTrain: return margins_.abnormal_train_mm;
    case Obstruction::kEndOfTrack: return margins_.end_of_track_mm;
    case Obstruction::kNone: return 0;  // GCOVR_EXCL_LINE defensive: never selected
  }
  return 0;  // GCOVR_EXCL_LINE defensive
}

// REQ-MB-022: a limit inside a no-stop section [b, e) (b <= limit < e) is pulled back to
// b minus the margin of the selected kind; repeated while it falls into another one (each
// step moves it before a section's begin: at most one step per section).
// @implements REQ-MB-022
std::int64_t Ground::NoStopAdjusted(std::int64_t best, Obstruction kind) const noexcept {
  const std::int64_t margin = MarginOf(kind);
  for (std::size_t step = 0; step <= no_stop_.Size(); ++step) {
    const auto it = std::upper_bound(no_stop_.begin(), no_stop_.end(), best,
                                     [](std::int64_t x, const Section& s) { return x < s.begin_mm; });
    if (it == no_stop_.begin()) {
      break;
    }
    const Section& s = *(it - 1);  // the last section with begin <= best
    if (best >= s.end_mm) {
      break;
    }
    best = s.begin_mm - margin;
  }
  return best;
}

// Confirmed restrictions the train has not yet left (end > extended rear), nearest first.
// @implements REQ-MB-015
// @implements REQ-MB-024
void Ground::FillRestrictions(StopLimitTelegram& telegram, const TrainState& t) const noexcept {
  telegram.restriction_count = 0;
  telegram.restrictions_truncated = false;
  for (const Restriction& r : confirmed_sorted_) {
    if (r.r.end_mm <= t.ext_begin_mm) {
      continue;
    }
    if (telegram.restriction_count >= kTelegramRestrictionsMax) {
      telegram.restrictions_truncated = true;
      break;
    }
    telegram.restrictions[telegram.restriction_count] = r.r;
    ++telegram.restriction_count;
  }
}

// Design §3.4: for every tracked train, best starts at END_OF_TRACK and is replaced only by
// a strictly smaller candidate, in the order 1..8 (the order decides the kind on ties);
// then the no-stop rule; the limit is recorded in the history and sent. Abnormal trains
// show their frozen bound and get no telegram.
// @implements REQ-MB-004
// @implements REQ-MB-006
// @implements REQ-MB-007
// @implements REQ-BR-015
// @implements REQ-MB-008
// @implements REQ-MB-014
// @implements REQ-MB-016
// @implements REQ-MB-017
// @implements REQ-MB-018
// @implements REQ-MB-022
// @implements REQ-MB-023
// @implements REQ-MB-024
void Ground::StopLimitStep(std::int64_t now_ms) noexcept {
  telegrams_.Clear();
  const std::size_t nf = fixed_blocks_.Size();
  const std::size_t nh = handovers_.Size();
  for (const std::uint32_t slot : order_) {
    TrainState& t = trains_[slot];
    t.out_abnormal = t.abnormal;
    if (t.abnormal) {
      t.has_limit = t.has_frozen;
      t.limit_mm = t.frozen_mm;
      t.kind = Obstruction::kNone;
      continue;
    }
    const std::int64_t front = t.front_mm;
    std::int64_t best = length_mm_ - margins_.end_of_track_mm;
    Obstruction kind = Obstruction::kEndOfTrack;
    const auto consider = [&best, &kind](std::int64_t candidate, Obstruction k) {
      if (candidate < best) {
        best = candidate;
        kind = k;
      }
    };
    // 1, 2: trains with front_u > front_t (the suffix after the last front <= front_t)
    const auto ahead = static_cast<std::size_t>(
        std::upper_bound(by_front_.begin(), by_front_.end(), front,
                         [](std::int64_t x, const Keyed& k) { return x < k.key; }) -
        by_front_.begin());
    if (suffix_min_rear_tracked_[ahead] != kPlusInf) {
      const std::int64_t margin = RAILPROOF_FAULT(FAULT_MB_NO_TRAIN_MARGIN) ? 0 : margins_.preceding_train_mm;
      consider(suffix_min_rear_tracked_[ahead] - margin, Obstruction::kPrecedingTrain);
    }
    if (!RAILPROOF_FAULT(FAULT_MB_ABNORMAL_RELEASED) && suffix_min_rear_abnormal_[ahead] != kPlusInf) {
      consider(suffix_min_rear_abnormal_[ahead] - margins_.abnormal_train_mm, Obstruction::kAbnormalTrain);
    }
    // 3: the first fixed block with begin >= front occupied by another train
    auto f = static_cast<std::size_t>(
        std::lower_bound(fixed_blocks_.begin(), fixed_blocks_.end(), front,
                         [](const Section& s, std::int64_t x) { return s.begin_mm < x; }) -
        fixed_blocks_.begin());
    f = fixed_next_occupied_[f];
    while (f < nf) {  // each iteration advances f: at most nf iterations
      if (fixed_count_[f] >= 2 || fixed_occupant_[f] != slot) {
        consider(fixed_blocks_[f].begin_mm - margins_.fixed_block_mm, Obstruction::kFixedBlock);
        break;
      }
      f = fixed_next_occupied_[f + 1];
    }
    // 4: automatic routes not set, entry >= front
    const auto* route = std::lower_bound(unset_route_entries_.begin(), unset_route_entries_.end(), front);
    if (route != unset_route_entries_.end()) {
      consider(*route - margins_.route_end_mm, Obstruction::kRouteEnd);
    }
    // 5: the first handover point >= front not secured for t
    auto h = static_cast<std::size_t>(
        std::lower_bound(handovers_.begin(), handovers_.end(), front,
                         [](const HandoverConfig& c, std::int64_t x) { return c.position_mm < x; }) -
        handovers_.begin());
    for (; h < nh; ++h) {
      if (handover_secured_[static_cast<std::size_t>(slot) * nh + h] == 0) {
        consider(handovers_[h].position_mm - margins_.handover_mm, Obstruction::kHandover);
        break;
      }
    }
    // 6: system boundary
    if (has_boundary_ && !boundary_accepted_ && front <= boundary_mm_) {
      consider(boundary_mm_ - margins_.system_boundary_mm, Obstruction::kSystemBoundary);
    }
    // 7: possessions (requested or active)
    const auto* poss = std::lower_bound(possession_begins_.begin(), possession_begins_.end(), front);
    if (poss != possession_begins_.end()) {
      consider(*poss - margins_.possession_mm, Obstruction::kPossession);
    }
    // 8: unequipped occupancy ahead (C++ only)
    const auto* uneq = std::lower_bound(unequipped_begins_.begin(), unequipped_begins_.end(), front);
    if (uneq != unequipped_begins_.end()) {
      consider(*uneq - margins_.abnormal_train_mm, Obstruction::kAbnormalTrain);
    }
    best = NoStopAdjusted(best, kind);

    t.has_limit = true;
    t.limit_mm = best;
    t.kind = kind;
    AppendHistory(slot, best, now_ms);
    StopLimitTelegram telegram{};
    telegram.train_id = t.id;
    telegram.limit_mm = best;
    telegram.kind = kind;
    telegram.issue_time_ms = now_ms;
    FillRestrictions(telegram, t);
    (void)telegrams_.PushBack(telegram);
  }
}

// ---- occupancy (design §3.5, REQ-MB-010) --------------------------------------------------

// A block is occupied iff some train's extended range (or an unequipped section) overlaps
// it: a difference array over the blocks, O(ranges log blocks + blocks).
// @implements REQ-MB-010
void Ground::OccupancyStep() noexcept {
  const std::size_t nb = blocks_.Size() - 1;
  for (std::size_t b = 0; b <= nb; ++b) {
    occupancy_diff_[b] = 0;
  }
  const auto add = [this](std::int64_t begin, std::int64_t end) {
    begin = std::max<std::int64_t>(begin, 0);
    end = std::min(end, length_mm_);
    if (begin >= end) {
      return;
    }
    const auto first = static_cast<std::size_t>(std::upper_bound(blocks_.begin(), blocks_.end(), begin) -
                                                 blocks_.begin()) - 1;
    const auto last = static_cast<std::size_t>(std::upper_bound(blocks_.begin(), blocks_.end(), end - 1) -
                                                blocks_.begin()) - 1;
    ++occupancy_diff_[first];
    --occupancy_diff_[last + 1];
  };
  for (const std::uint32_t slot : order_) {
    const TrainState& t = trains_[slot];
    if (RAILPROOF_FAULT(FAULT_MB_OCCUPANCY_NO_CORRECTION)) {
      add(t.front_mm - t.length_mm, t.front_mm);
    } else {
      add(t.ext_begin_mm, t.ext_end_mm);
    }
  }
  for (const Unequipped& u : unequipped_) {
    add(u.range.begin_mm, u.range.end_mm);
  }
  std::int32_t running = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    running += occupancy_diff_[b];
    occupied_[b] = running > 0 ? 1 : 0;
  }
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
