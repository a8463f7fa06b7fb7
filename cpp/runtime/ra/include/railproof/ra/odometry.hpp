// On-board odometry (spec/design/ra.md): sensor validation, TG processing, moving
// averages, slip/slide predicates, start-point search, IMU 6-axis compensation from one or
// two parallel start points, the D1 error model, the permanent margin per odometry section,
// and the position envelope consumed by the braking supervision and the ground.
//
// Runtime module: no heap after Create, no exceptions, no recursion, bounded loops,
// deterministic. The inertial numerics use IEEE double (design note §3); every output is an
// integer (mm, mm/s) rounded to the safe side. The discrete part is ReadhesionMachine.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "railproof/core/track.hpp"
#include "railproof/core/units.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/readhesion_machine.hpp"

namespace railproof::ra {

inline constexpr int kImuSamplesPerCycle = static_cast<int>(params::ra::imu_samples_per_cycle);
inline constexpr int kHistoryCycles = static_cast<int>(params::ra::history_cycles);
inline constexpr int kMaxSections = static_cast<int>(params::ra::max_sections);

// ---- sensor data (design note §2) ------------------------------------------------------
// Sample time within the cycle: (time_ms - cycle_ms) * 1000 - imu_jitter_us <= time_us <=
// time_ms * 1000 + imu_jitter_us. last_edge_us is unchanged while no pulse arrives and
// strictly later than the previous edge when pulses arrived.
struct TgSample {
  std::int64_t time_us = 0;       // sample time
  std::int64_t pulses = 0;        // cumulative pulse count, never decreasing
  std::int64_t last_edge_us = 0;  // capture time of the latest pulse edge, <= time_us
};

// Body axes: x forward (running direction), y left, z up; at rest on the level az = +G.
// Signs as in design note §7: pitch theta is positive nose up and wy is its rate (d theta/dt,
// so on a rising gradient at rest ax = +G sin theta); roll Psi is positive left side up and
// wx is its rate; wz is the yaw rate, positive turning left (a left curve at speed v reads
// ay = v * wz + G sin Psi approximately). Sample times: strictly increasing by
// imu_sample_ms +- imu_jitter_us, also from the last sample of the previous cycle, and within
// [(time_ms - cycle_ms) * 1000 - imu_jitter_us, time_ms * 1000 + imu_jitter_us].
struct ImuSample {
  std::int64_t time_us = 0;
  double ax = 0, ay = 0, az = 0;  // m/s^2
  double wx = 0, wy = 0, wz = 0;  // rad/s: roll, pitch, yaw
};

// A fix outside the section table's range is not accepted (ignored).
struct BaliseFix {
  std::int64_t front_mm = 0;  // line position of the front from the checked track database
};

struct CycleInput {
  std::int64_t time_ms = 0;  // cycle time: exactly previous + cycle_ms
  TgSample tg{};
  std::array<ImuSample, kImuSamplesPerCycle> imu{};
  std::uint8_t imu_count = kImuSamplesPerCycle;  // samples delivered (must be 10)
  std::optional<BaliseFix> balise{};
};

// Typed rejection reasons of a cycle's sensor data (REQ-RA-013). kNone = accepted.
enum class InputError : std::uint8_t {
  kNone,
  kCycleTimeGap,          // time_ms != previous + cycle_ms (gap, repeat or backwards); a TG failure
  kTgPulsesDecreasing,    // cumulative count below the previous one
  kTgEdgeInvalid,         // edge after the sample time, not later than the previous edge with new
                          // pulses, changed without a new pulse, or sample time outside the cycle
  kTgImplausibleRate,     // more pulses than max_speed_mm_s allows in one cycle (+1)
  kImuSampleCount,        // imu_count != imu_samples_per_cycle
  kImuTimestamps,         // not strictly increasing by imu_sample_ms +- imu_jitter_us, or outside the cycle
  kImuNotFinite,          // NaN or infinite value
  kImuOutOfRange,         // |a| > imu_max_accel or |w| > imu_max_rate
};
const char* ToString(InputError e) noexcept;
[[nodiscard]] constexpr bool IsImuError(InputError e) noexcept {
  return e == InputError::kImuSampleCount || e == InputError::kImuTimestamps ||
         e == InputError::kImuNotFinite || e == InputError::kImuOutOfRange;
}

// ---- configuration (design note §6, §8) ------------------------------------------------
enum class Method : std::uint8_t { kImu, kMaxMinAcceleration };

struct OdometrySection {
  std::int64_t begin_mm = 0;           // [begin, end) in line coordinates
  std::int64_t end_mm = 0;
  std::int32_t gradient_permille_x10 = 0;  // steepest gradient magnitude in the section, >= 0
  std::int64_t max_compensation_ms = 0;    // in [min_compensation_ms, max_compensation_limit_ms]
  std::int64_t margin_mm = 0;              // 0 = computed from the error model; else must be >= it
};

struct OdometryConfig {
  Method method = Method::kImu;
  std::int64_t wheel_diameter_um = 860'000;
  std::int64_t train_length_mm = 0;
  std::int64_t detect_threshold_mm_s2 = params::ra::detect_threshold_mm_s2;  // Ta of the line
  std::uint8_t start_points = static_cast<std::uint8_t>(params::ra::parallel_start_points);
  std::int64_t imu_rate_error_udeg_s = params::ra::imu_rate_error_udeg_s;
  std::int64_t length_correction_ppm = 1000;  // accumulated TG error (REQ-MB-002)
  // baseline method (max/min acceleration) only: vehicle bounds, by default D1's figures
  // (3.3 and 5.2 km/h/s) rounded up to mm/s^2 (the wider envelope)
  std::int64_t accel_max_mm_s2 = (params::ra::former_accel_max_kmh_s_x1000 * 10 + 35) / 36;
  std::int64_t decel_max_mm_s2 = (params::ra::former_decel_max_kmh_s_x1000 * 10 + 35) / 36;
  const OdometrySection* sections = nullptr;  // copied at Create, ordered, contiguous
  int section_count = 0;
  std::int64_t initial_front_mm = 0;          // front at the first cycle (initial balise fix)
};

// The lowest detection threshold Ta a line's sections allow (design note §4, ASM-028): the
// gravity component of the steepest gradient (G g / 1000, rounded up) plus the TG and IMU
// acceleration errors; with Ta at the bare gravity component, sensor noise on the steepest
// gradient alone raises deviations.
[[nodiscard]] constexpr std::int64_t DetectThresholdFloorMmS2(const OdometrySection* sections, int count) noexcept {
  std::int64_t steepest_x10 = 0;
  for (int i = 0; i < count; ++i) {
    steepest_x10 = sections[i].gradient_permille_x10 > steepest_x10 ? sections[i].gradient_permille_x10 : steepest_x10;
  }
  return (params::ra::gravity_mm_s2 * steepest_x10 + 9999) / 10000 + params::ra::tg_accel_error_mm_s2 +
         params::ra::imu_accel_error_mm_s2;
}

enum class ConfigError : std::uint8_t {
  kNone,
  kWheelDiameter,       // not in 500..1500 mm
  kTrainLength,         // not in 1..1000 m
  kThreshold,           // Ta not in 50..2000 mm/s^2
  kStartPoints,         // not 1..2
  kRateError,           // negative or above 1 deg/s
  kSectionCount,        // 0 or > kMaxSections, or no section array
  kSectionOrder,        // begin >= end, overlap or gap between consecutive sections
  kSectionGradient,     // negative or above 100 permille
  kSectionTime,         // max compensation time outside [min, limit] or not a whole cycle
  kSectionMargin,       // explicit margin below the error model (REQ-RA-009)
  kAccelBounds,         // baseline bounds not positive
  kInitialOutside,      // initial front outside the section table
  kLengthCorrection,    // length_correction_ppm not in 0..100000
};
const char* ToString(ConfigError e) noexcept;

// ---- output (design note §8) -----------------------------------------------------------
struct OdometryOutput {
  std::int64_t time_ms = 0;
  Mode mode = Mode::kTg;
  StopReason stop_reason = StopReason::kNone;
  InputError input_error = InputError::kNone;  // rejection of this cycle's data, if any
  bool position_valid = true;
  bool stop_demand = false;
  std::int64_t front_mm = 0;           // nominal front (TG, or the lowest active candidate, nearest mm)
  std::int64_t front_error_mm = 0;     // envelope ahead of the nominal front (>= 0)
  std::int64_t rear_error_mm = 0;      // envelope behind the nominal rear (>= 0)
  std::int64_t speed_mm_s = 0;         // speed rounded up (>= 0): TG, or while compensating the
                                       // highest active candidate's (baseline: its upper bound);
                                       // kept from the last accepted cycle on a rejected one
  bool standstill = false;
  std::int64_t margin_mm = 0;          // margin in force (part of both errors)
  std::int64_t accumulated_error_mm = 0;  // TG error since the last balise (part of both errors)
  std::int64_t compensation_bound_mm = 0; // largest active candidate's error bound (0 in TG;
                                          // baseline: the larger envelope extension)
  std::int64_t last_balise_mm = 0;
  // diagnostics for the study and the evidence (not used by consumers)
  double ax_avg = 0, ap_avg = 0;       // m/s^2, the averaged signals compared for detection
  double v_tg = 0;                     // m/s, TG speed of this cycle
  double tg_lag_s = 0;                 // s, mean delay of v_tg (sample time - middle of the interval)
  std::array<double, kMaxStartPoints> v_comp{};  // m/s, active candidates' speeds (baseline: upper bound)
  std::array<std::int64_t, kMaxStartPoints> x_comp_mm{};  // active candidates' fronts (IMU method)
  std::int32_t start_age_cycles = 0;   // primary start point age at the last detection
  Predicates predicates{};             // what the state machine was given this cycle (design note §4)
  bool detected = false;
  std::int8_t adopted = kNoCandidate;
};

// Braking's position estimate from an output (errors as reported).
[[nodiscard]] core::PositionEstimate ToPositionEstimate(const OdometryOutput& o) noexcept;
// The ground's position-report correction: max(front_error, rear_error), >= 0.
[[nodiscard]] std::int64_t ReportCorrectionMm(const OdometryOutput& o) noexcept;

// ---- error model (design note §6, REQ-RA-008) ------------------------------------------
// Delta_d(t, g) in mm rounded up: t in ms, g in permille x 10, rate error in udeg/s.
[[nodiscard]] std::int64_t ErrorBoundMm(std::int64_t t_ms, std::int32_t gradient_permille_x10,
                                        std::int64_t rate_error_udeg_s) noexcept;
// Same in metres (double), for the study and tests.
[[nodiscard]] double ErrorBoundM(double t_s, double gradient_permille, double rate_error_deg_s) noexcept;

// ---- the odometry ----------------------------------------------------------------------
class Odometry {
 public:
  // Validates and copies the configuration; all storage is inside the object.
  [[nodiscard]] static ConfigError Create(const OdometryConfig& cfg, Odometry& out) noexcept;
  Odometry() noexcept;

  // One 100 ms cycle. Never fails: a rejected input is reported in the output
  // (input_error) and handled as a sensor failure (REQ-RA-013): nothing of the cycle is
  // used, the history restarts with the next accepted cycle, which starts a new baseline for
  // the continuity checks (a restarted TG counter becomes valid again; the TG distance
  // continues from the last accepted count when the count went on plausibly), and the state
  // machine stops the train until a balise fix in a cycle with both sensors valid.
  // Start-up: the first accepted cycle has no TG speed; the deviation predicate and the
  // start-point jerk conditions are evaluated only once the averages cover full windows
  // (moving_average_ms + tg_window_ms after a start or a rejected cycle).
  const OdometryOutput& Step(const CycleInput& in) noexcept;

  [[nodiscard]] const OdometryOutput& output() const noexcept { return out_; }
  [[nodiscard]] const ReadhesionMachine& machine() const noexcept { return machine_; }

 private:
  // ---- fixed-size state (no heap): design note §2-§8 ------------------------------------
  // One accepted cycle of the history ring (design note §7).
  struct HistoryEntry {
    std::int64_t time_ms = 0;
    std::int64_t pulses = 0;
    std::int64_t edge_us = 0;
    std::int64_t front_um = 0;    // nominal front after the cycle (line position, um)
    std::int64_t balise_um = 0;   // balise fix of the cycle (um), if `balise`
    std::int64_t ax_nano = 0;     // cycle mean of a_x in 1e-9 m/s^2 (exact running sum)
    std::int64_t tg_time_us = 0;
    double v_tg = 0;              // m/s
    double tg_lag_s = 0;          // mean delay of v_tg: sample time - middle of its interval
    double ax = 0, ay = 0, az = 0, wx = 0, wy = 0, wz = 0;  // cycle means (SI)
    double ax_avg = 0, ap = 0;    // 3 s averages (m/s^2)
    bool jerk_ok = false;         // the three jerk conditions held in this cycle
    bool balise = false;
    // Compensation: each active candidate's state at this cycle, and whether the TG values
    // of the cycle were replaced by a compensation (after its adoption or time-out): then
    // v_tg and front_um are the compensation's and theta_comp its pitch.
    std::array<double, kMaxStartPoints> cand_v{}, cand_theta{}, cand_x_um{};
    double theta_comp = 0;
    bool comp = false;
  };
  // One compensation candidate (IMU method) or speed/position envelope (baseline).
  struct CandidateState {
    bool active = false;
    std::int64_t start = 0;       // history index of the start point
    std::int32_t cycles = 0;      // cycles integrated since the start point
    double theta = 0, psi = 0;    // pitch, roll (rad)
    double v = 0, d = 0;          // compensated speed (m/s), distance since the start (m)
    double ax_prev = 0;           // A_x of the previous cycle (m/s^2)
    double base_um = 0;           // position base: x(start), or the balise fix since
    double base_d = 0;            // d at the position base
    // baseline (max/min acceleration): speed and position bounds
    bool slip = false;               // detected as a slip (TG accelerating more than the IMU)
    double a_front = 0, a_rear = 0;  // m/s^2
    double v_hi = 0, v_lo = 0;       // m/s
    double x_hi_um = 0, x_lo_um = 0;
  };
  struct SectionEntry {
    std::int64_t begin_mm = 0, end_mm = 0;
    std::int32_t gradient_x10 = 0;
    std::int32_t t_cycles = 0;
    std::int64_t margin_mm = 0;
  };
  struct Limits {
    SectionLimits limits{};
    std::int32_t gradient_x10 = 0;
  };

  void Init(const OdometryConfig& cfg) noexcept;
  [[nodiscard]] InputError ValidateTg(const CycleInput& in) const noexcept;
  [[nodiscard]] InputError ValidateImu(const CycleInput& in) const noexcept;
  void Reject(const CycleInput& in, InputError imu_error, InputError tg_error) noexcept;
  void Accept(const CycleInput& in) noexcept;
  void PushHistory(const CycleInput& in, bool balise) noexcept;
  [[nodiscard]] HistoryEntry& At(std::int64_t index) noexcept;
  [[nodiscard]] const HistoryEntry& At(std::int64_t index) const noexcept;
  [[nodiscard]] std::int64_t Oldest() const noexcept;
  [[nodiscard]] std::int64_t OldestUsable() const noexcept;
  [[nodiscard]] Limits SectionLimitsAt(std::int64_t front_mm, std::int64_t extension_mm) const noexcept;
  [[nodiscard]] std::int64_t StartPoint(std::int64_t detection) const noexcept;
  void InitCandidate(CandidateState& c, std::int64_t start, bool slip) const noexcept;
  void BaselineAccelerations(CandidateState& c, bool slip) const noexcept;
  void AdvanceCandidate(CandidateState& c, const HistoryEntry& e) const noexcept;
  [[nodiscard]] double CandidateFrontUm(const CandidateState& c) const noexcept;
  void Record(std::size_t c, HistoryEntry& e) const noexcept;
  void ReplaceTg(std::size_t c, std::int64_t last) noexcept;
  [[nodiscard]] double CandidateSpeed(const CandidateState& c) const noexcept;
  void RebaseTg(std::int64_t front_um, std::int64_t pulses) noexcept;
  [[nodiscard]] std::int64_t TgFrontUm(std::int64_t pulses) const noexcept;
  void FillOutput(const CycleInput& in, InputError error, bool accepted, const HistoryEntry* e,
                  bool machine_fault) noexcept;

  bool created_ = false;
  OdometryConfig cfg_{};                       // sections pointer cleared (copied below)
  std::array<SectionEntry, kMaxSections> sections_{};
  int section_count_ = 0;
  double pulse_um_ = 0;                        // pi * D / teeth
  std::int64_t max_pulses_per_cycle_ = 0;      // plausibility limit (+1 pulse)
  // cycle time base and the last accepted samples
  bool have_time_ = false;
  std::int64_t last_time_ms_ = 0;
  bool have_prev_ = false;                     // the previous cycle was accepted: continuity checks
  bool have_tg_ = false;                       // a cycle was accepted (the TG reference is set)
  std::int64_t prev_pulses_ = 0, prev_edge_us_ = 0, prev_imu_us_ = 0;  // of the last accepted cycle
  std::int64_t prev_accepted_ms_ = 0;
  // history ring (cleared after a rejected cycle)
  std::array<HistoryEntry, kHistoryCycles> hist_{};
  std::int64_t count_ = 0;                     // entries pushed since the last clear
  std::int64_t ax_sum_nano_ = 0;               // sum of the last min(count, 30) ax_nano
  // position
  std::int64_t tg_ref_um_ = 0, tg_ref_pulses_ = 0;
  std::int64_t front_um_ = 0;                  // nominal front after the last cycle
  std::int64_t last_balise_um_ = 0;
  std::int64_t prev_margin_mm_ = 0;            // M_prev of the section look-up
  std::int32_t episode_gradient_x10_ = 0;
  // baseline: extension kept from re-adhesion until the next balise
  std::int64_t kept_front_mm_ = 0, kept_rear_mm_ = 0;
  std::array<CandidateState, kMaxStartPoints> cand_{};
  ReadhesionMachine machine_{MachineConfig{}};
  OdometryOutput out_{};
};

}  // namespace railproof::ra
