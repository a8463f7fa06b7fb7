// Level-crossing radio messages between the train, the crossing controllers and the
// centre (spec/design/lc.md §3-§5). Train side (lc::onboard::CrossingProtection) and ground
// side (lc::wayside::CrossingController, lc::wayside::CentreScheduler) meet here.
#pragma once

#include "railproof/core/enum_names.hpp"

#include <array>
#include <cstddef>
#include <cstdint>

namespace railproof::messages {

// Status a crossing controller reports every cycle (lc::wayside::CrossingController):
//   kOpen     controller kOpen or kOpening (barriers up or rising): not closed
//   kWarning  controller kWarning or kClosing (lights on, barriers not yet detected down)
//   kClosed   controller kClosed (barriers detected down), with the warning start
//   kFailed   controller kFailed (never closed)
// @implements REQ-LC-003 REQ-LC-006
enum class CrossingStatus : std::uint8_t { kOpen, kWarning, kClosed, kFailed };

constexpr const char* ToString(CrossingStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 4>{"OPEN", "WARNING", "CLOSED", "FAILED"});
}

// Crossing report (the controller's cycle output, broadcast to trains and the centre).
// issued_ms is the controller's cycle time of the report; the on-board unit measures the age
// of a confirmation from it (design §3 "received at rx": a delayed message is as old as its
// issue, so the age from the issue time is the safe reading; with no delay both agree).
// warning_start_ms (ws) is meaningful in kWarning and kClosed (and kFailed: the start of the
// warning in force); clock_fault reports REQ-LC-013. requesters lists the trains among the
// controller's requesters (design §3 item 3: a CLOSED report clears only a train it lists; a
// crossing closed for another train is no confirmation for this one, whose own requests may
// have been lost: the warning ends when that other train withdraws).
// @implements REQ-LC-003 REQ-LC-006 REQ-LC-013
inline constexpr std::size_t kMaxReportRequesters = 16;
struct CrossingReport {
  std::uint32_t crossing_id = 0;
  CrossingStatus status = CrossingStatus::kOpen;
  std::int64_t warning_start_ms = 0;
  std::int64_t issued_ms = 0;
  bool clock_fault = false;
  std::array<std::uint32_t, kMaxReportRequesters> requesters{};
  std::size_t requester_count = 0;

  // True if train_id is among the first requester_count entries (a count above the capacity
  // is read as the capacity).
  [[nodiscard]] constexpr bool Lists(std::uint32_t train_id) const noexcept {
    const std::size_t n = requester_count < kMaxReportRequesters ? requester_count : kMaxReportRequesters;
    for (std::size_t i = 0; i < n; ++i) {
      if (requesters[i] == train_id) {
        return true;
      }
    }
    return false;
  }
};

// A request or a withdrawal of the warning of one crossing by one train (design §3:
// "Requests and withdrawals name the train and the crossing").
// @implements REQ-LC-002 REQ-LC-004
struct CrossingRequest {
  std::uint32_t train_id = 0;
  std::uint32_t crossing_id = 0;
};

// The controller's acknowledgement of a withdrawal (sent for every withdrawal received, also
// repeated ones).
// @implements REQ-LC-004 REQ-LC-007
struct WithdrawalAck {
  std::uint32_t crossing_id = 0;
  std::uint32_t train_id = 0;
};

}  // namespace railproof::messages
