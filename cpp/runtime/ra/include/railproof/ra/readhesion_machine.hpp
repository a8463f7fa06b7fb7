// Re-adhesion state machine of the on-board odometry (spec/design/ra.md §5; model:
// models/ra.pml, cycle() there). One Step per 100 ms odometry cycle turns the
// abstract predicates of the cycle (deviation, per-candidate speed agreement, sensor
// health, balise, TG motion, section limits, start-point age) into the odometry mode: TG
// odometry, compensating (one or two candidates from parallel start points) or stopped
// (start-up, maximum compensation time exceeded or a sensor failed), with the stop demand,
// the position validity, the margin and maximum compensation time in force, and whether the
// TG history is trusted (a warm-up at standstill since the last stop, REQ-RA-015).
//
// Runtime module: no heap, no exceptions, no recursion, deterministic. Integers only, so
// the conformance vectors of the model replay exactly (times in cycles, margins in mm).
#pragma once

#include "railproof/core/enum_names.hpp"

#include <array>
#include <cstdint>

namespace railproof::ra {

inline constexpr int kMaxStartPoints = 2;
inline constexpr std::int8_t kNoCandidate = -1;

// @implements REQ-RA-003 REQ-RA-006 REQ-RA-007 REQ-RA-013 REQ-RA-015
enum class Mode : std::uint8_t { kTg, kCompensating, kStopped };
enum class StopReason : std::uint8_t {
  kNone,
  kMaxCompensationTime,
  kImuFailure,
  kTgFailure,
  kStartUp,        // the start-up: held until the warm-up at standstill is complete
  kStartInMotion,  // a TG pulse before the warm-up was complete: held until trusted and a balise
};

constexpr const char* ToString(Mode m) noexcept {
  return core::EnumName(m, std::array<const char*, 3>{"TG", "COMPENSATING", "STOPPED"});
}
constexpr const char* ToString(StopReason r) noexcept {
  return core::EnumName(r, std::array<const char*, 6>{"NONE", "MAX_COMPENSATION_TIME", "IMU_FAILURE", "TG_FAILURE",
                                                      "START_UP", "START_IN_MOTION"});
}

// Limits of the odometry sections under the train this cycle (design note §6): the
// shortest maximum compensation time and the largest margin among them.
struct SectionLimits {
  std::int32_t max_compensation_cycles = 0;  // T_s, >= 1
  std::int64_t margin_mm = 0;                // M_s, >= 0
};

// The predicates of one cycle (design note §4).
struct Predicates {
  bool deviation = false;                                // |a_x - Ap| > Ta
  std::array<bool, kMaxStartPoints> speed_agrees{};      // |v_TG - v_c| <= rate * t_c, per candidate
  bool imu_ok = true;
  bool tg_ok = true;
  bool balise = false;                                   // a balise fix accepted this cycle
  bool tg_moving = false;                                // a TG pulse this cycle (or no count to compare)
  SectionLimits section{};
  std::int32_t start_age_cycles = 0;                     // age of the primary start point, read on detection
};

struct Candidate {
  bool active = false;
  std::int32_t age_cycles = 0;    // compensation time t_c in cycles
  std::uint8_t confirm = 0;       // consecutive cycles with both re-adhesion conditions
};

// The state after a cycle plus the per-cycle events (adopted, balise_reset, detected).
// The machine starts stopped at start-up (REQ-RA-015).
struct MachineState {
  Mode mode = Mode::kStopped;
  StopReason stop_reason = StopReason::kStartUp;
  std::uint8_t deviation_count = 0;
  std::array<Candidate, kMaxStartPoints> candidates{};
  std::int32_t max_compensation_cycles = 0;  // t_max in force
  std::int64_t margin_mm = 0;                // margin in force
  bool stop_demand = true;
  bool position_valid = false;
  bool trusted = false;            // the TG history is trusted: a warm-up at standstill since the last stop
  std::int32_t rest_cycles = 0;    // healthy cycles without a TG pulse in a row, while not trusted
  // events of the last cycle
  bool detected = false;
  std::int8_t adopted = kNoCandidate;
  bool balise_reset = false;
};

struct MachineConfig {
  std::uint8_t confirm_cycles = 3;
  std::uint8_t start_points = 2;              // 1 or 2
  std::int32_t spacing_cycles = 25;           // age difference of the second start point
  std::int32_t warmup_cycles = 0;             // the warm-up at standstill (1..10000; the odometry: 3 s + 1 s)
};

enum class MachineError : std::uint8_t {
  kNone,
  kConfirmCyclesInvalid,   // not in 1..100
  kStartPointsInvalid,     // not 1..kMaxStartPoints
  kSpacingInvalid,         // not in 1..10000
  kWarmupInvalid,          // not in 1..10000
  kSectionInvalid,         // max_compensation_cycles < 1 or margin_mm < 0
  kStartAgeInvalid,        // start_age_cycles < 0 on a detection cycle
};

constexpr const char* ToString(MachineError e) noexcept {
  return core::EnumName(e, std::array<const char*, 7>{"none", "confirm_cycles not in 1..100", "start_points not in 1..2", "spacing_cycles not in 1..10000", "warmup_cycles not in 1..10000", "section limits invalid (time < 1 cycle or margin < 0)", "start-point age negative"}, "unknown");
}

class ReadhesionMachine {
 public:
  // Validates the configuration; kNone on success (then Step may be called).
  [[nodiscard]] static MachineError Validate(const MachineConfig& cfg) noexcept;

  // Starts stopped (START_UP) with the limits of the first cycle taken from its Step.
  explicit ReadhesionMachine(const MachineConfig& cfg) noexcept : cfg_(cfg) {}

  // One cycle in the order of design note §5. Returns kSectionInvalid / kStartAgeInvalid
  // (and changes nothing) for invalid predicates; the caller treats that as a fault.
  [[nodiscard]] MachineError Step(const Predicates& in) noexcept;

  [[nodiscard]] const MachineState& state() const noexcept { return s_; }
  [[nodiscard]] const MachineConfig& config() const noexcept { return cfg_; }

 private:
  void Discard() noexcept;
  void Stop(StopReason reason) noexcept;
  void WarmUp(bool tg_moving) noexcept;
  MachineConfig cfg_;
  MachineState s_{};
};

}  // namespace railproof::ra
