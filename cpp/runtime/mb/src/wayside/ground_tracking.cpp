// Ground unit: tracking (spec/design/mb.md §3.1; REQ-MB-001..005, REQ-MB-016, REQ-MB-019).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/wayside/ground.hpp"

#include <algorithm>
#include <limits>

#include "ground_internal.hpp"

namespace railproof::mb::wayside {

using namespace ground_detail;  // NOLINT(google-build-using-namespace)

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
// ends, or the D2 safety buffers l_f = e + ceil(v tau) + l_c, l_r = e + l_c with
// e = max(ceil(r|x - x_m|), reported correction) (rounded up: conservative).
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
    // D2's rate r(x - x_m) bounds a plain tachogenerator odometry; the train's own bound (its
    // reported correction: compensation and margins included) may be larger, and then governs.
    const std::int64_t odometry = std::max(CeilDiv(d2_.rate_ppm * run, kPpm), correction_mm);
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

}  // namespace railproof::mb::wayside
