// Ground unit: stop limits (spec/design/mb.md §3.4) and occupancy (§3.5, REQ-MB-010).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/wayside/ground.hpp"

#include <algorithm>
#include <limits>

#include "ground_internal.hpp"

namespace railproof::mb::wayside {

using namespace ground_detail;  // NOLINT(google-build-using-namespace)

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

}  // namespace railproof::mb::wayside
