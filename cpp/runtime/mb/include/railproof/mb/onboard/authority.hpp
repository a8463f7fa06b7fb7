// On-board moving-block authority handling (spec/design/mb.md §4; model:
// receive() of models/mb.pml):
//   AuthorityReceiver     stop-limit reception: maximum age, newer-only, validity from issue
//                         (REQ-MB-009)
//   SetBackSupervisor     backward movement only inside set-back sections, bounded
//                         (REQ-MB-005)
//   SpeedRestrictionStore temporary speed restrictions received with the stop limit, applied
//                         until the train's rear has left them (REQ-MB-015)
//
// Runtime module: no heap (fixed-size members only), no exceptions, bounded loops, typed
// results, deterministic. Units: mm, ms, mm/s (int64).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/track.hpp"
#include "railproof/messages/stop_limit.hpp"

namespace railproof::mb::onboard {

using core::Overlaps;
using core::Section;
using messages::Obstruction;
using messages::SpeedRestriction;
using messages::StopLimitTelegram;

using core::Section;
using messages::SpeedRestriction;
using messages::StopLimitTelegram;

// ---- stop-limit reception (design §4, REQ-MB-009) -----------------------------------------

struct AuthorityConfig {
  std::int64_t validity_ms;  // authority usable while now - issue <= validity_ms (> 0)
  std::int64_t max_age_ms;   // telegram older than this (now - issue > max_age) is refused (> 0)
};

// Service configuration from spec/parameters/mb.yaml
// (authority_validity_ms, authority_max_age_ms).
AuthorityConfig DefaultAuthorityConfig() noexcept;

// @implements REQ-MB-009
enum class Verdict : std::uint8_t {
  kAccept,       // limit and issue time taken from the telegram
  kTooOld,       // now - issue_time > max_age_ms
  kNotNewer,     // current authority usable and issue_time <= its issue time
  kFutureIssue,  // issue_time > now (clock fault): refused, nothing changes (defensive;
                 // the model's ages are never negative)
};

constexpr const char* ToString(Verdict v) noexcept {
  return core::EnumName(v, std::array<const char*, 4>{"ACCEPT", "TOO_OLD", "NOT_NEWER", "FUTURE_ISSUE"});
}

// @implements REQ-MB-009
class AuthorityReceiver {
 public:
  // Holds no authority until the first accepted telegram. Invalid config (a value <= 0)
  // makes every Receive refuse with kTooOld and the authority never usable (safe side);
  // Valid() tells.
  explicit AuthorityReceiver(const AuthorityConfig& config) noexcept;

  // Design §4: age = now - issue_time; age > max_age -> kTooOld; else if Usable(now) and
  // issue_time <= current issue time -> kNotNewer; else kAccept (even if the limit is
  // shorter: the ground's newest decision always wins).
  Verdict Receive(std::int64_t limit_mm, std::int64_t issue_time_ms, std::int64_t now_ms) noexcept;

  // The current limit (the last accepted), empty before the first acceptance. It is only a
  // movement authority while Usable(now).
  [[nodiscard]] std::optional<std::int64_t> Limit() const noexcept;
  [[nodiscard]] std::optional<std::int64_t> IssueTime() const noexcept;
  // now - issue <= validity_ms for the current authority.
  [[nodiscard]] bool Usable(std::int64_t now_ms) const noexcept;
  // Standstill demanded: no usable authority (emergency brake demand, design §4).
  [[nodiscard]] bool StandstillDemanded(std::int64_t now_ms) const noexcept { return !Usable(now_ms); }
  [[nodiscard]] bool Valid() const noexcept { return valid_; }

 private:
  AuthorityConfig config_;
  bool valid_;
  bool has_;
  std::int64_t limit_mm_;
  std::int64_t issue_ms_;     // issue time of the current authority (newer-only rule)
  std::int64_t validity_origin_ms_;  // instant the validity is counted from (= issue_ms_)
};

// ---- set-back supervision (REQ-MB-005) ---------------------------------------------------

inline constexpr std::size_t kSetBackSectionsMax = 64;

enum class SetBackVerdict : std::uint8_t {
  kOk,                 // forward, standstill, or an allowed set-back
  kOutsideSection,     // backward movement with the front not inside one set-back section
  kTooFar,             // more than setback_max_mm behind the furthest front reached
};

constexpr const char* ToString(SetBackVerdict v) noexcept {
  return core::EnumName(v, std::array<const char*, 3>{"Ok", "OutsideSection", "TooFar"}, "Invalid");
}

enum class SetBackConfigError : std::uint8_t {
  kNone,
  kTooManySections,    // more than kSetBackSectionsMax
  kSectionInvalid,     // empty, or unsorted/overlapping the previous one
  kSetBackMaxInvalid,  // setback_max_mm < 0
};

// Backward movement is allowed only while the front stays inside one set-back section
// (front inside [b, e) means b < front <= e: the foremost millimetre is in the section)
// and at most setback_max_mm behind the furthest front reached (the reference is the
// furthest front ever reached, a monotone maximum: repeated small set-backs cannot add up).
// The same rule as the ground's report check (Ground::OnReport, kBackwardMovement /
// kSetBackTooFar). A refused movement is a supervision violation: the caller brakes.
// @implements REQ-MB-005
class SetBackSupervisor {
 public:
  SetBackSupervisor() noexcept = default;
  SetBackConfigError Init(std::span<const Section> setback_sections, std::int64_t setback_max_mm,
                          std::int64_t initial_front_mm) noexcept;
  // Checks a new front position against the last; the furthest front is updated only by
  // forward positions. A refused position does not change the state.
  SetBackVerdict Update(std::int64_t front_mm) noexcept;
  [[nodiscard]] std::int64_t FurthestFront() const noexcept { return furthest_mm_; }
  [[nodiscard]] std::int64_t Front() const noexcept { return front_mm_; }
  // Smallest front the train may set back to from here (== Front() when not allowed).
  [[nodiscard]] std::int64_t SetBackLimit() const noexcept;

 private:
  [[nodiscard]] const Section* SectionHolding(std::int64_t front_mm) const noexcept;
  std::array<Section, kSetBackSectionsMax> sections_{};
  std::size_t count_ = 0;
  std::int64_t max_mm_ = 0;
  std::int64_t front_mm_ = 0;
  std::int64_t furthest_mm_ = 0;
};

// ---- speed-restriction store (REQ-MB-015) -------------------------------------------------

inline constexpr std::size_t kStoredRestrictionsMax = 2 * messages::kTelegramRestrictionsMax;

enum class StoreStatus : std::uint8_t {
  kOk,
  kTruncated,  // more restrictions than kStoredRestrictionsMax: the last received ones
               // (the furthest: the ground sends nearest first) were dropped
};

// Holds the restrictions of the last accepted stop-limit telegram. A restriction that the
// ground stops sending while the train is inside it is kept until the rear has left it
// (safe side, REQ-MB-015). A restriction applies to the train while its body
// [front - length, front) overlaps it, i.e. from the front entering until the rear has
// left (D5 §5.1.5).
// @implements REQ-MB-015
class SpeedRestrictionStore {
 public:
  SpeedRestrictionStore() noexcept = default;
  // Replaces the set with `received` (e.g. from an accepted telegram), keeping the old ones
  // the train is still inside; then drops the ones whose end the rear has passed.
  StoreStatus Update(std::span<const SpeedRestriction> received, std::int64_t front_mm,
                     std::int64_t length_mm) noexcept;
  // Drops the restrictions the rear has left (rear = front - length >= end).
  void Advance(std::int64_t front_mm, std::int64_t length_mm) noexcept;
  // Lowest speed of the restrictions applying to the train body now; empty if none.
  [[nodiscard]] std::optional<std::int64_t> ApplicableSpeed(std::int64_t front_mm,
                                                            std::int64_t length_mm) const noexcept;
  // Every held restriction (ahead or under the train), ascending begin then id: for the
  // braking patterns.
  [[nodiscard]] std::span<const SpeedRestriction> Held() const noexcept { return {held_.data(), count_}; }

 private:
  void Sort() noexcept;
  std::array<SpeedRestriction, kStoredRestrictionsMax> held_{};
  std::size_t count_ = 0;
};

}  // namespace railproof::mb::onboard
