// Speed supervision decision (spec/design/br.md §4). Seeded faults RAILPROOF_FAULT(FAULT_BR_*)
// are active only in the test-only schemata variant (spec/design/seeded-faults.md).
#include "railproof/core/seeded_fault.hpp"
#include "railproof/br/supervisor.hpp"

namespace railproof::br {

namespace {

// Step 1: a latched emergency brake is released only at standstill with the handle in
// the emergency position and the reset switch operated (REQ-BR-006).
// @implements REQ-BR-006
bool EmergencyReleaseAllowed(const DriverInputs& in) noexcept {
  if (RAILPROOF_FAULT(FAULT_BR_RESET_IGNORES_HANDLE)) {
    return in.standstill && in.reset;
  }
  if (RAILPROOF_FAULT(FAULT_BR_RELEASE_WHILE_MOVING)) {
    return in.handle_emergency && in.reset;
  }
  return in.standstill && in.handle_emergency && in.reset;
}

// Steps 3-5: the service level from the service pattern and its leads (REQ-BR-002/003).
// @implements REQ-BR-002 REQ-BR-003
BrakeLevel ServiceLevel(const PatternSpeeds& p, BrakeLevel previous) noexcept {
  if (p.v_s > p.v_7n) {
    return BrakeLevel::k7N;
  }
  if (p.v_s > p.v_6n) {
    return BrakeLevel::k6N;
  }
  if (p.v_s > p.v_5n) {
    return BrakeLevel::k5N;
  }
  if (p.v_s > p.v_4n) {
    return BrakeLevel::k4N;
  }
  // An applied service brake is released only release_lead_ms before the pattern.
  if (!RAILPROOF_FAULT(FAULT_BR_NO_RELEASE_LEAD) && previous != BrakeLevel::kNone && p.v_s > p.v_release) {
    return BrakeLevel::k4N;
  }
  return BrakeLevel::kNone;
}

}  // namespace

// @implements REQ-BR-001 REQ-BR-002 REQ-BR-003 REQ-BR-006 REQ-BR-014
Decision Supervisor::Step(const PatternSpeeds& p, const DriverInputs& in) noexcept {
  Decision d;
  if (latched_) {
    if (!EmergencyReleaseAllowed(in)) {
      d.level = BrakeLevel::kEmergency;
      d.emergency_latched = true;
      d.pattern_approaching = true;
      service_ = BrakeLevel::kNone;
      return d;
    }
    latched_ = false;
  }
  // Step 2: emergency pattern exceeded (REQ-BR-001).
  const bool overspeed = RAILPROOF_FAULT(FAULT_BR_EMERGENCY_LATE) ? p.v_s > p.v_e + 1 : p.v_s > p.v_e;
  if (overspeed) {
    latched_ = !RAILPROOF_FAULT(FAULT_BR_EMERGENCY_NOT_LATCHED);
    d.level = BrakeLevel::kEmergency;
    d.emergency_latched = latched_;
    d.pattern_approaching = true;
    service_ = BrakeLevel::kNone;
    return d;
  }
  d.level = ServiceLevel(p, service_);
  service_ = d.level;
  // Step 6: the driver sees "pattern approaching" at the release lead and while braking.
  d.pattern_approaching = p.v_s > p.v_release || d.level != BrakeLevel::kNone;
  return d;
}

}  // namespace railproof::br
