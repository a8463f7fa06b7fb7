// The stop-limit telegram the ground sends to every tracked train (moving block, ground ->
// train): obstruction kinds, speed restrictions and the telegram itself
// (spec/design/mb.md §2, §3.4, REQ-MB-024). Ground side (mb::wayside::Ground) and train side
// (mb::onboard::AuthorityReceiver) meet here and nowhere else.
//
// Units: positions are chainage in mm (int64) on one running line, increasing in the
// running direction; times in ms (int64); speeds in mm/s. Sections are half-open
// [begin_mm, end_mm).
#pragma once

#include "railproof/core/enum_names.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace railproof::messages {

// The eight obstruction kinds of D5 §5.1.4, numbered as in the design note (and the model).
// @implements REQ-MB-006
enum class Obstruction : std::uint8_t {
  kNone = 0,            // no limit (abnormal train, or nothing issued)
  kPrecedingTrain = 1,  // extended rear of a tracked train ahead
  kFixedBlock = 2,      // start of an occupied fixed-block section (platform, home block)
  kRouteEnd = 3,        // entrance of an automatic route that is not set
  kHandover = 4,        // radio handover point not secured for the train
  kSystemBoundary = 5,  // system boundary not accepted by the neighbour
  kPossession = 6,      // start of a requested or active possession
  kAbnormalTrain = 7,   // last known rear of a train with abnormal tracking (and unequipped occupancy)
  kEndOfTrack = 8,      // end of the line
};

constexpr const char* ToString(Obstruction kind) noexcept {
  return core::EnumName(kind, std::array<const char*, 9>{"NONE", "PRECEDING_TRAIN", "FIXED_BLOCK", "ROUTE_END", "HANDOVER", "SYSTEM_BOUNDARY", "POSSESSION", "ABNORMAL_TRAIN", "END_OF_TRACK"});
}

// A temporary speed restriction (REQ-MB-015): kilometre range [begin_mm, end_mm) and the
// permitted speed. `id` is assigned by the ground when the restriction is requested.
struct SpeedRestriction {
  std::uint32_t id;
  std::int64_t begin_mm;
  std::int64_t end_mm;
  std::int64_t speed_mm_s;
};

// Most restrictions carried by one stop-limit telegram. The ground sends the confirmed
// restrictions the train has not yet left (end_mm > extended rear), nearest first
// (ascending begin_mm, then id); `restrictions_truncated` is set if more existed.
inline constexpr std::size_t kTelegramRestrictionsMax = 8;

// The stop-limit telegram the ground sends to every tracked train every cycle (REQ-MB-024).
// @implements REQ-MB-024
struct StopLimitTelegram {
  std::uint32_t train_id;
  std::int64_t limit_mm;       // the front must satisfy front <= limit_mm
  Obstruction kind;            // kind of the obstruction that gave the limit
  std::int64_t issue_time_ms;  // the ground cycle time `now` at which it was issued
  std::uint32_t restriction_count;  // entries used in `restrictions`
  bool restrictions_truncated;      // more confirmed restrictions applied than fit
  std::array<SpeedRestriction, kTelegramRestrictionsMax> restrictions;
};

}  // namespace railproof::messages
