// On-board speed supervision decision (spec/design/br.md §4; model: decide() of
// models/br.pml). One Step per supervision cycle turns the supervised speed and the
// pattern speeds of this cycle (computed by br::PatternCalculator) into the brake
// command: none, mild brakes 4N/5N/6N, service brake 7N or the latched emergency brake,
// and the driver's "pattern approaching" indication.
//
// Runtime module: no heap, no exceptions, no recursion, deterministic. Units: mm/s.
#pragma once

#include "railproof/core/enum_names.hpp"

#include <cstdint>

namespace railproof::br {

// @implements REQ-BR-001 REQ-BR-002 REQ-BR-003
enum class BrakeLevel : std::uint8_t { kNone, k4N, k5N, k6N, k7N, kEmergency };

constexpr const char* ToString(BrakeLevel l) noexcept {
  return core::EnumName(l, std::array<const char*, 6>{"NONE", "4N", "5N", "6N", "7N", "EB"});
}

// The service brake a level commands in sevenths of the full service brake (D5 §5.5: the
// notches 4N..7N): 4..7; 0 for none and for the emergency brake, which is no service notch.
constexpr int ServiceNotchSevenths(BrakeLevel l) noexcept {
  switch (l) {
    case BrakeLevel::k4N: return 4;
    case BrakeLevel::k5N: return 5;
    case BrakeLevel::k6N: return 6;
    case BrakeLevel::k7N: return 7;
    case BrakeLevel::kNone:
    case BrakeLevel::kEmergency: return 0;
  }
  return 0;
}

// A pattern speed of kNoPermittedSpeed means that not even standing is permitted at that
// point (the run-up from rest already reaches the target, or the input was invalid): every
// supervised speed, 0 included, exceeds it, so a standing train is held by the brake and a
// creeping train whose measured speed reads 0 is braked (design note §3).
inline constexpr std::int64_t kNoPermittedSpeed = -1;

// The supervised speed and the pattern speeds of one cycle (design note §3), mm/s:
//   v_s        measured speed plus the speed-measurement allowance
//   v_e        emergency pattern at the supervised front
//   v_7n       service pattern at the supervised front
//   v_6n..v_4n service pattern lead_6n/5n/4n_ms ahead (at the current speed)
//   v_release  service pattern release_lead_ms ahead
struct PatternSpeeds {
  std::int64_t v_s = 0;
  std::int64_t v_e = 0;
  std::int64_t v_7n = 0;
  std::int64_t v_6n = 0;
  std::int64_t v_5n = 0;
  std::int64_t v_4n = 0;
  std::int64_t v_release = 0;
};

struct DriverInputs {
  bool standstill = false;        // measured speed zero for the standstill time
  bool handle_emergency = false;  // brake handle in the emergency position
  bool reset = false;             // reset switch operated this cycle
};

struct Decision {
  BrakeLevel level = BrakeLevel::kNone;
  bool pattern_approaching = false;
  bool emergency_latched = false;
};

// @implements REQ-BR-001 REQ-BR-002 REQ-BR-003 REQ-BR-006
class Supervisor {
 public:
  // One supervision cycle (design note §4, steps 1-6).
  Decision Step(const PatternSpeeds& p, const DriverInputs& in) noexcept;

  [[nodiscard]] bool emergency_latched() const noexcept { return latched_; }
  [[nodiscard]] BrakeLevel service_level() const noexcept { return service_; }

 private:
  bool latched_ = false;
  BrakeLevel service_ = BrakeLevel::kNone;  // level commanded in the previous cycle
};

}  // namespace railproof::br
