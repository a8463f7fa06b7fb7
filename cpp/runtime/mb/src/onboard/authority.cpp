// On-board stop-limit reception, set-back supervision and speed-restriction store
// (spec/design/mb.md §4). AuthorityReceiver::Receive mirrors receive() of
// models/mb.pml: the same checks in the same order.
//
// Seeded faults (negative tests): FAULT_MB_ACCEPT_NOT_NEWER, FAULT_MB_VALIDITY_FROM_RECEPTION,
// active only in the test-only schemata variant (spec/design/seeded-faults.md).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/mb/onboard/authority.hpp"

#include "railproof/generated/mb_params.hpp"

namespace railproof::mb::onboard {

// ---- AuthorityReceiver (REQ-MB-009) ---------------------------------------------------------

// @implements REQ-MB-009
AuthorityConfig DefaultAuthorityConfig() noexcept {
  namespace p = params::mb;
  static_assert(p::authority_validity_ms > 0 && p::authority_max_age_ms > 0, "times must be positive");
  return AuthorityConfig{p::authority_validity_ms, p::authority_max_age_ms};
}

AuthorityReceiver::AuthorityReceiver(const AuthorityConfig& config) noexcept
    : config_(config),
      valid_(config.validity_ms > 0 && config.max_age_ms > 0),
      has_(false),
      limit_mm_(0),
      issue_ms_(0),
      validity_origin_ms_(0) {}

// Design §4, in this order: maximum age, newer-only while usable, accept.
// @implements REQ-MB-009
Verdict AuthorityReceiver::Receive(std::int64_t limit_mm, std::int64_t issue_time_ms, std::int64_t now_ms) noexcept {
  if (!valid_) {
    return Verdict::kTooOld;
  }
  if (issue_time_ms > now_ms) {
    return Verdict::kFutureIssue;
  }
  const std::int64_t age = now_ms - issue_time_ms;
  if (age > config_.max_age_ms) {
    return Verdict::kTooOld;
  }
  if (!RAILPROOF_FAULT(FAULT_MB_ACCEPT_NOT_NEWER) && Usable(now_ms) && issue_time_ms <= issue_ms_) {
    return Verdict::kNotNewer;
  }
  has_ = true;
  limit_mm_ = limit_mm;
  issue_ms_ = issue_time_ms;
  validity_origin_ms_ = RAILPROOF_FAULT(FAULT_MB_VALIDITY_FROM_RECEPTION) ? now_ms : issue_time_ms;
  return Verdict::kAccept;
}

std::optional<std::int64_t> AuthorityReceiver::Limit() const noexcept {
  if (!has_) {
    return std::nullopt;
  }
  return limit_mm_;
}

std::optional<std::int64_t> AuthorityReceiver::IssueTime() const noexcept {
  if (!has_) {
    return std::nullopt;
  }
  return issue_ms_;
}

// The authority is usable while now - issue <= validity (design §4).
// @implements REQ-MB-009
bool AuthorityReceiver::Usable(std::int64_t now_ms) const noexcept {
  return valid_ && has_ && now_ms >= validity_origin_ms_ && now_ms - validity_origin_ms_ <= config_.validity_ms;
}

// ---- SetBackSupervisor (REQ-MB-005) -----------------------------------------------------------

// @implements REQ-MB-005
SetBackConfigError SetBackSupervisor::Init(std::span<const Section> setback_sections, std::int64_t setback_max_mm,
                                           std::int64_t initial_front_mm) noexcept {
  count_ = 0;
  if (setback_sections.size() > kSetBackSectionsMax) {
    return SetBackConfigError::kTooManySections;
  }
  for (std::size_t i = 0; i < setback_sections.size(); ++i) {
    const Section& s = setback_sections[i];
    if (s.begin_mm >= s.end_mm || (i > 0 && s.begin_mm < setback_sections[i - 1].end_mm)) {
      return SetBackConfigError::kSectionInvalid;
    }
  }
  if (setback_max_mm < 0) {
    return SetBackConfigError::kSetBackMaxInvalid;
  }
  for (std::size_t i = 0; i < setback_sections.size(); ++i) {
    sections_[i] = setback_sections[i];
  }
  count_ = setback_sections.size();
  max_mm_ = setback_max_mm;
  front_mm_ = initial_front_mm;
  furthest_mm_ = initial_front_mm;
  return SetBackConfigError::kNone;
}

// The set-back section holding the front (b < front <= e), or null.
const Section* SetBackSupervisor::SectionHolding(std::int64_t front_mm) const noexcept {
  for (std::size_t i = 0; i < count_; ++i) {  // bounded by kSetBackSectionsMax
    if (sections_[i].begin_mm < front_mm && front_mm <= sections_[i].end_mm) {
      return &sections_[i];
    }
  }
  return nullptr;
}

// Backward movement only inside one set-back section (from the new front up to the furthest
// front reached) and at most setback_max_mm behind the furthest front reached.
// @implements REQ-MB-005
SetBackVerdict SetBackSupervisor::Update(std::int64_t front_mm) noexcept {
  if (front_mm < front_mm_) {
    const Section* s = SectionHolding(front_mm);
    if (s == nullptr || furthest_mm_ > s->end_mm) {
      return SetBackVerdict::kOutsideSection;
    }
    if (furthest_mm_ - front_mm > max_mm_) {
      return SetBackVerdict::kTooFar;
    }
  }
  front_mm_ = front_mm;
  if (front_mm > furthest_mm_) {
    furthest_mm_ = front_mm;
  }
  return SetBackVerdict::kOk;
}

// @implements REQ-MB-005
std::int64_t SetBackSupervisor::SetBackLimit() const noexcept {
  const Section* s = SectionHolding(front_mm_);
  if (s == nullptr || furthest_mm_ > s->end_mm) {
    return front_mm_;
  }
  std::int64_t limit = furthest_mm_ - max_mm_;
  if (limit <= s->begin_mm) {
    limit = s->begin_mm + 1;  // the front must stay inside: b < front
  }
  return limit < front_mm_ ? limit : front_mm_;
}

// ---- SpeedRestrictionStore (REQ-MB-015) -------------------------------------------------------

namespace {

bool RestrictionLess(const SpeedRestriction& a, const SpeedRestriction& b) noexcept {
  return a.begin_mm < b.begin_mm || (a.begin_mm == b.begin_mm && a.id < b.id);
}

// The train body [front - length, front) overlaps [begin, end): from the front entering
// until the rear has left (D5 §5.1.5).
bool UnderTrain(const SpeedRestriction& r, std::int64_t front_mm, std::int64_t length_mm) noexcept {
  return core::Overlaps(front_mm - length_mm, front_mm, r.begin_mm, r.end_mm);
}

}  // namespace

// Insertion sort (bounded by kStoredRestrictionsMax, no allocation).
void SpeedRestrictionStore::Sort() noexcept {
  for (std::size_t i = 1; i < count_; ++i) {
    const SpeedRestriction x = held_[i];
    std::size_t j = i;
    while (j > 0 && RestrictionLess(x, held_[j - 1])) {
      held_[j] = held_[j - 1];
      --j;
    }
    held_[j] = x;
  }
}

// @implements REQ-MB-015
StoreStatus SpeedRestrictionStore::Update(std::span<const SpeedRestriction> received, std::int64_t front_mm,
                                          std::int64_t length_mm) noexcept {
  std::array<SpeedRestriction, kStoredRestrictionsMax> next{};
  std::size_t n = 0;
  bool truncated = false;
  // First the old ones the train is inside and that are no longer sent (kept: safe side).
  for (std::size_t i = 0; i < count_; ++i) {
    bool resent = false;
    for (const SpeedRestriction& r : received) {
      resent = resent || r.id == held_[i].id;
    }
    if (!resent && UnderTrain(held_[i], front_mm, length_mm)) {
      next[n] = held_[i];  // n <= i < kStoredRestrictionsMax
      ++n;
    }
  }
  // Then the received ones, skipping those the rear has already left.
  for (const SpeedRestriction& r : received) {
    if (front_mm - length_mm >= r.end_mm || r.begin_mm >= r.end_mm) {
      continue;
    }
    if (n >= kStoredRestrictionsMax) {
      truncated = true;
      continue;
    }
    next[n] = r;
    ++n;
  }
  held_ = next;
  count_ = n;
  Sort();
  return truncated ? StoreStatus::kTruncated : StoreStatus::kOk;
}

// @implements REQ-MB-015
void SpeedRestrictionStore::Advance(std::int64_t front_mm, std::int64_t length_mm) noexcept {
  std::size_t n = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    if (front_mm - length_mm < held_[i].end_mm) {  // the rear has not yet left it
      held_[n] = held_[i];
      ++n;
    }
  }
  count_ = n;
}

// @implements REQ-MB-015
std::optional<std::int64_t> SpeedRestrictionStore::ApplicableSpeed(std::int64_t front_mm,
                                                                   std::int64_t length_mm) const noexcept {
  std::optional<std::int64_t> lowest;
  for (std::size_t i = 0; i < count_; ++i) {
    if (UnderTrain(held_[i], front_mm, length_mm) && (!lowest.has_value() || held_[i].speed_mm_s < *lowest)) {
      lowest = held_[i].speed_mm_s;
    }
  }
  return lowest;
}

}  // namespace railproof::mb::onboard
