// Messages of every type at the bounds of their ranges (codec.hpp), shared by the codec's unit
// tests and the generator of its fuzz corpus (not a test file itself).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "railproof/core/units.hpp"
#include "railproof/messages/codec.hpp"

namespace railproof::messages::test {

struct Sample {
  std::string name;
  Message message;
};

inline constexpr std::uint32_t kIdMax = std::numeric_limits<std::uint32_t>::max();
inline constexpr std::int64_t kTimeMin = std::numeric_limits<std::int64_t>::min();
inline constexpr std::int64_t kTimeMax = std::numeric_limits<std::int64_t>::max();
inline constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
inline constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();

inline PositionReport PositionMin() {
  return PositionReport{0, 0, 0, 1, 0, -core::kMaxPositionMm, 0, Direction::kNominal};
}

inline PositionReport PositionMax() {
  return PositionReport{kIdMax,
                        kIdMax,
                        core::kMaxPositionMm,
                        core::kMaxTrainLengthMm,
                        core::kMaxPositionErrorMm,
                        core::kMaxPositionMm,
                        core::kMaxMeasuredSpeedMmS,
                        Direction::kReverse};
}

inline StopLimitTelegram StopLimitMin() {
  StopLimitTelegram t{};
  t.limit_mm = -core::kMaxPositionMm;
  t.issue_time_ms = kTimeMin;
  return t;
}

// kWireRestrictionsMax restrictions at the bounds of their fields, in ascending (begin, id)
// order (two with the same begin), `truncated` set.
inline StopLimitTelegram StopLimitMax() {
  StopLimitTelegram t{};
  t.train_id = kIdMax;
  t.limit_mm = core::kMaxPositionMm;
  t.kind = Obstruction::kEndOfTrack;
  t.issue_time_ms = kTimeMax;
  t.restriction_count = 6;
  t.restrictions_truncated = true;
  t.restrictions[0] = SpeedRestriction{kIdMax, kI32Min, kI32Min + 1, 1};
  t.restrictions[1] = SpeedRestriction{0, -1, 0, core::kMaxLimitMmS};
  t.restrictions[2] = SpeedRestriction{5, 0, 1, 8'333};
  t.restrictions[3] = SpeedRestriction{6, 0, kI32Max, 16'666};
  t.restrictions[4] = SpeedRestriction{1, 2'000'000, 2'500'000, 22'222};
  t.restrictions[5] = SpeedRestriction{2, kI32Max - 1, kI32Max, 27'777};
  return t;
}

inline CrossingReport ReportMin() {
  CrossingReport r{};
  r.warning_start_ms = kTimeMin;
  r.issued_ms = kTimeMin + 1;
  return r;
}

inline CrossingReport ReportMax() {
  CrossingReport r{.crossing_id = kIdMax,
                   .status = CrossingStatus::kFailed,
                   .warning_start_ms = kTimeMax - 1,
                   .issued_ms = kTimeMax,
                   .clock_fault = true,
                   .requesters = {},
                   .requester_count = kMaxReportRequesters};
  for (std::size_t i = 0; i < kMaxReportRequesters; ++i) {
    r.requesters[i] = i == 0 ? kIdMax : static_cast<std::uint32_t>(1'000 + 7 * i);
  }
  return r;
}

inline CentrePositionReport CentreMin() {
  return CentrePositionReport{0, kTimeMin, -core::kMaxPositionMm + 1, -core::kMaxPositionMm, 0};
}

inline CentrePositionReport CentreMax() {
  return CentrePositionReport{kIdMax, kTimeMax, core::kMaxPositionMm, core::kMaxPositionMm - 1,
                              core::kMaxMeasuredSpeedMmS};
}

// Every type once at its lower and once at its upper bounds (the types without fields once);
// fields of one width differ where the bounds allow, so that a layout with two of them
// exchanged does not pass for the documented one.
inline std::vector<Sample> BoundarySamples() {
  return {
      {"position_report_min", PositionMin()},
      {"position_report_max", PositionMax()},
      {"no_position", NoPosition{}},
      {"stop_limit_min", StopLimitMin()},
      {"stop_limit_max", StopLimitMax()},
      {"keep_alive", KeepAlive{}},
      {"crossing_request_min", CrossingRequest{0, 0}},
      {"crossing_request_max", CrossingRequest{kIdMax, kIdMax - 1}},
      {"crossing_withdrawal", CrossingWithdrawal{CrossingRequest{kIdMax, 0}}},
      {"crossing_report_min", ReportMin()},
      {"crossing_report_max", ReportMax()},
      {"withdrawal_ack", WithdrawalAck{0, kIdMax}},
      {"centre_position_report_min", CentreMin()},
      {"centre_position_report_max", CentreMax()},
  };
}

}  // namespace railproof::messages::test
