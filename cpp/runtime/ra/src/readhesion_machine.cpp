// Re-adhesion state machine (spec/design/ra.md §5). The numbered steps are those of
// the design note and of cycle() in models/ra.pml.
//
// Seeded faults (negative tests, active only in the test-only schemata variant,
// spec/design/seeded-faults.md; the conformance replay of the ra vectors must fail against each):
//   FAULT_RA_TIMEOUT_OFF_BY_ONE    a candidate times out only at age > t_max + 1
//   FAULT_RA_CONFIRM_TWO           re-adhesion adopted after two confirming cycles
//   FAULT_RA_SPEED_IGNORED         the speed condition of the judgement is ignored
//   FAULT_RA_EPISODE_RELAXES       the episode takes the current section's limits only
//   FAULT_RA_LAST_CANDIDATE_WINS   the highest index wins when both confirm in one cycle
//   FAULT_RA_TG_FAILURE_IGNORED    a TG failure does not stop the train
//   FAULT_RA_WARMUP_COUNTS_MOTION  the warm-up counts cycles with TG pulses (a start in motion is trusted)
//   FAULT_RA_BALISE_WITHOUT_WARMUP a balise ends a stop before the history is trusted
//   FAULT_RA_TRUST_KEPT_ON_DEVIATION a deviation run while stopped keeps the history trusted
#include "railproof/core/seeded_fault.hpp"
#include "railproof/ra/readhesion_machine.hpp"

#include <algorithm>

namespace railproof::ra {

MachineError ReadhesionMachine::Validate(const MachineConfig& cfg) noexcept {
  if (cfg.confirm_cycles < 1 || cfg.confirm_cycles > 100) return MachineError::kConfirmCyclesInvalid;
  if (cfg.start_points < 1 || cfg.start_points > kMaxStartPoints) return MachineError::kStartPointsInvalid;
  if (cfg.spacing_cycles < 1 || cfg.spacing_cycles > 10000) return MachineError::kSpacingInvalid;
  if (cfg.warmup_cycles < 1 || cfg.warmup_cycles > 10000) return MachineError::kWarmupInvalid;
  return MachineError::kNone;
}

void ReadhesionMachine::Discard() noexcept {
  for (auto& c : s_.candidates) c = Candidate{};
}

// Every stop withdraws the trust in the TG history: a timeout may leave the TG slipping, a
// sensor failure restarts the history (REQ-RA-015).
// @implements REQ-RA-007 REQ-RA-013 REQ-RA-015
void ReadhesionMachine::Stop(StopReason reason) noexcept {
  Discard();
  s_.mode = Mode::kStopped;
  s_.stop_reason = reason;
  s_.stop_demand = true;
  s_.position_valid = false;
  s_.trusted = false;
  s_.rest_cycles = 0;
}

// 2a. The warm-up at standstill (REQ-RA-015): warmup_cycles healthy cycles in a row without
// a TG pulse make the history trusted; a pulse restarts the count and makes the start-up a
// start in motion.
// @implements REQ-RA-015
void ReadhesionMachine::WarmUp(bool tg_moving) noexcept {
  if (s_.trusted) return;
  if (tg_moving && !RAILPROOF_FAULT(FAULT_RA_WARMUP_COUNTS_MOTION)) {
    s_.rest_cycles = 0;
    if (s_.stop_reason == StopReason::kStartUp) s_.stop_reason = StopReason::kStartInMotion;
  } else if (s_.rest_cycles < cfg_.warmup_cycles) {
    s_.rest_cycles += 1;
  }
  if (s_.rest_cycles >= cfg_.warmup_cycles) {
    s_.trusted = true;
    s_.rest_cycles = 0;
  }
}

// @implements REQ-RA-003 REQ-RA-006 REQ-RA-007 REQ-RA-009 REQ-RA-010 REQ-RA-012 REQ-RA-013 REQ-RA-015
MachineError ReadhesionMachine::Step(const Predicates& in) noexcept {
  if (in.section.max_compensation_cycles < 1 || in.section.margin_mm < 0) {
    return MachineError::kSectionInvalid;
  }
  const bool detecting = s_.mode == Mode::kTg && in.imu_ok && in.tg_ok && in.deviation &&
                         s_.deviation_count + 1 >= cfg_.confirm_cycles;
  if (detecting && in.start_age_cycles < 0) return MachineError::kStartAgeInvalid;

  s_.detected = false;
  s_.adopted = kNoCandidate;
  s_.balise_reset = false;

  // 1. Section limits: an episode never relaxes them (REQ-RA-009).
  if (s_.mode == Mode::kCompensating && !RAILPROOF_FAULT(FAULT_RA_EPISODE_RELAXES)) {
    s_.max_compensation_cycles = std::min(s_.max_compensation_cycles, in.section.max_compensation_cycles);
    s_.margin_mm = std::max(s_.margin_mm, in.section.margin_mm);
  } else {
    s_.max_compensation_cycles = in.section.max_compensation_cycles;
    s_.margin_mm = in.section.margin_mm;
  }

  // 2. Sensor failure: the safe reaction in the same cycle (REQ-RA-013).
  if (!in.imu_ok) {
    s_.deviation_count = 0;
    Stop(StopReason::kImuFailure);
    return MachineError::kNone;
  }
  if (!in.tg_ok && !RAILPROOF_FAULT(FAULT_RA_TG_FAILURE_IGNORED)) {
    s_.deviation_count = 0;
    Stop(StopReason::kTgFailure);
    return MachineError::kNone;
  }

  const bool was_trusted = s_.trusted;
  WarmUp(in.tg_moving);

  switch (s_.mode) {
    case Mode::kStopped: {
      // 3. Held until the history is trusted and a balise fix with healthy sensors
      // re-establishes the position; the start-up without motion needs only the warm-up.
      // While waiting with the history trusted, confirm_cycles deviations in a row withdraw
      // the trust: a TG wheel that was locked through the "standstill" and rolls again shows
      // as one (REQ-RA-015).
      s_.stop_demand = true;
      s_.position_valid = false;
      if (was_trusted) {
        s_.deviation_count = in.deviation ? static_cast<std::uint8_t>(s_.deviation_count + 1) : 0;
        if (s_.deviation_count >= cfg_.confirm_cycles && !RAILPROOF_FAULT(FAULT_RA_TRUST_KEPT_ON_DEVIATION)) {
          s_.trusted = false;
          s_.rest_cycles = 0;
          s_.deviation_count = 0;
        }
      }
      const bool ends = (s_.trusted || (RAILPROOF_FAULT(FAULT_RA_BALISE_WITHOUT_WARMUP) && in.balise)) &&
                        (in.balise || s_.stop_reason == StopReason::kStartUp);
      if (ends) {
        s_.mode = Mode::kTg;
        s_.stop_reason = StopReason::kNone;
        s_.stop_demand = false;
        s_.position_valid = true;
        s_.deviation_count = 0;
        s_.balise_reset = in.balise;
      }
      return MachineError::kNone;
    }

    case Mode::kTg: {
      // 4. Detection after confirm_cycles consecutive deviations (REQ-RA-003).
      s_.deviation_count = in.deviation ? static_cast<std::uint8_t>(s_.deviation_count + 1) : 0;
      if (in.balise) s_.balise_reset = true;  // REQ-RA-012
      if (s_.deviation_count < cfg_.confirm_cycles) return MachineError::kNone;
      s_.deviation_count = 0;
      s_.detected = true;
      s_.mode = Mode::kCompensating;
      bool any = false;
      for (int c = 0; c < cfg_.start_points; ++c) {
        Candidate& k = s_.candidates[static_cast<std::size_t>(c)];
        k.active = true;
        k.confirm = 0;
        k.age_cycles = in.start_age_cycles + c * cfg_.spacing_cycles;  // REQ-RA-010
        if (k.age_cycles > s_.max_compensation_cycles) k = Candidate{};
        any = any || k.active;
      }
      if (!any) Stop(StopReason::kMaxCompensationTime);  // 6.
      return MachineError::kNone;
    }

    case Mode::kCompensating: {
      // 5. Age, timeout and re-adhesion judgement of each candidate (REQ-RA-006/007).
      const std::int32_t limit = s_.max_compensation_cycles + (RAILPROOF_FAULT(FAULT_RA_TIMEOUT_OFF_BY_ONE) ? 1 : 0);
      const int needed = cfg_.confirm_cycles - (RAILPROOF_FAULT(FAULT_RA_CONFIRM_TWO) ? 1 : 0);
      bool any = false;
      for (std::size_t c = 0; c < s_.candidates.size(); ++c) {
        Candidate& k = s_.candidates[c];
        if (!k.active) continue;
        k.age_cycles += 1;
        if (k.age_cycles > limit) {
          k = Candidate{};
          continue;
        }
        const bool both = !in.deviation && (RAILPROOF_FAULT(FAULT_RA_SPEED_IGNORED) || in.speed_agrees[c]);
        k.confirm = both ? static_cast<std::uint8_t>(std::min(k.confirm + 1, 255)) : 0;
        any = true;
      }
      // Adoption: the lowest index that completed its confirmation (REQ-RA-010).
      std::int8_t adopt = kNoCandidate;
      for (std::size_t c = 0; c < s_.candidates.size(); ++c) {
        if (s_.candidates[c].active && s_.candidates[c].confirm >= needed) {
          adopt = static_cast<std::int8_t>(c);
          if (!RAILPROOF_FAULT(FAULT_RA_LAST_CANDIDATE_WINS)) {
            break;
          }
        }
      }
      if (adopt != kNoCandidate) {
        s_.adopted = adopt;
        Discard();
        s_.mode = Mode::kTg;
        s_.deviation_count = 0;
        return MachineError::kNone;
      }
      if (!any) Stop(StopReason::kMaxCompensationTime);  // 6. (REQ-RA-007)
      return MachineError::kNone;
    }
  }
  return MachineError::kNone;
}

}  // namespace railproof::ra
