// Position reports, train -> ground (spec/design/mb.md §3.1, spec/design/lc.md §5).
//   PositionReport        to the moving-block ground unit (mb::wayside::Ground), REQ-MB-001
//   CentrePositionReport  to the level-crossing centre (lc::wayside::CentreScheduler), REQ-LC-010
// The train side builds them, the ground side reads them; neither includes the other.
#pragma once

#include <cstdint>

namespace railproof::messages {

// Running direction of the train on the running line (orientation, not movement).
enum class Direction : std::uint8_t {
  kNominal,  // running in increasing chainage (the only direction on a running line)
  kReverse,  // rejected: kWrongDirection
};

// A position report (REQ-MB-001): the front as virtual block + offset.
// front_mm = blocks_mm[front_block] + offset_mm with 0 <= offset_mm <= block length
// (a front exactly on a boundary may be given either way; LocateFront gives the canonical
// form: the block holding the train's foremost millimetre).
// @implements REQ-MB-001
struct PositionReport {
  std::uint32_t train_id;
  std::uint32_t front_block;
  std::int64_t offset_mm;
  std::int64_t length_mm;       // must equal the registered length
  std::int64_t correction_mm;   // length correction since the last balise (REQ-MB-002), >= 0
  std::int64_t last_balise_mm;  // position of the last balise fix (x_m), on the line
  std::int64_t speed_mm_s;      // >= 0, <= kMaxSpeedMmS
  Direction direction;
};

// A position report of the train (every position_report_ms): the envelope front_max and
// rear_min, an upper bound of the speed, and the time the position was taken (the train's
// GNSS time). The start times are recomputed from time_ms, not from the reception time (the
// train may have moved since: the report time is the safe reading of design §5 step 4 "now").
struct CentrePositionReport {
  std::uint32_t train_id = 0;
  std::int64_t time_ms = 0;
  std::int64_t front_mm = 0;  // front_max
  std::int64_t rear_mm = 0;   // rear_min
  std::int64_t speed_mm_s = 0;
};

}  // namespace railproof::messages
