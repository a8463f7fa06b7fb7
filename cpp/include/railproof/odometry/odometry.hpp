// On-board odometry (spec/design/odometry.md): sensor validation, TG processing, moving
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

#include "railproof/braking/patterns.hpp"
#include "railproof/generated/readhesion_params.hpp"
#include "railproof/odometry/readhesion_machine.hpp"

namespace railproof::odometry {

inline constexpr int kImuSamplesPerCycle = static_cast<int>(params::readhesion::imu_samples_per_cycle);
inline constexpr int kHistoryCycles = static_cast<int>(params::readhesion::history_cycles);
inline constexpr int kMaxSections = static_cast<int>(params::readhesion::max_sections);

// ---- sensor data (design note §2) ------------------------------------------------------
struct TgSample {
  std::int64_t time_us = 0;       // sample time
  std::int64_t pulses = 0;        // cumulative pulse count, never decreasing
  std::int64_t last_edge_us = 0;  // capture time of the latest pulse edge, <= time_us
};

// Body axes: x forward (running direction), y left, z up; at rest on the level az = +G.
struct ImuSample {
  std::int64_t time_us = 0;
  double ax = 0, ay = 0, az = 0;  // m/s^2
  double wx = 0, wy = 0, wz = 0;  // rad/s: roll, pitch, yaw
};

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
  kCycleTimeGap,          // time_ms != previous + cycle_ms (gap, repeat or backwards)
  kTgPulsesDecreasing,    // cumulative count below the previous one
  kTgEdgeInvalid,         // edge after the sample time, or before the previous edge with new pulses
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
  std::int64_t detect_threshold_mm_s2 = params::readhesion::detect_threshold_mm_s2;  // Ta of the line
  std::uint8_t start_points = static_cast<std::uint8_t>(params::readhesion::parallel_start_points);
  std::int64_t imu_rate_error_udeg_s = params::readhesion::imu_rate_error_udeg_s;
  std::int64_t length_correction_ppm = 1000;  // accumulated TG error (REQ-MB-002)
  // baseline method (max/min acceleration) only: vehicle bounds
  std::int64_t accel_max_mm_s2 = 920;
  std::int64_t decel_max_mm_s2 = 1400;
  const OdometrySection* sections = nullptr;  // copied at Create, ordered, contiguous
  int section_count = 0;
  std::int64_t initial_front_mm = 0;          // from the initial balise fix
};

enum class ConfigError : std::uint8_t {
  kNone,
  kWheelDiameter,       // not in 500..1500 mm
  kTrainLength,         // not in 1..1000 m
  kThreshold,           // Ta not in 50..2000 mm/s^2
  kStartPoints,         // not 1..2
  kRateError,           // negative or above 1 deg/s
  kSectionCount,        // 0 or > kMaxSections
  kSectionOrder,        // begin >= end, overlap or gap between consecutive sections
  kSectionGradient,     // negative or above 100 permille
  kSectionTime,         // max compensation time outside [min, limit] or not a whole cycle
  kSectionMargin,       // explicit margin below the error model (REQ-RA-009)
  kAccelBounds,         // baseline bounds not positive
  kInitialOutside,      // initial front outside the section table
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
  std::int64_t front_mm = 0;           // nominal front
  std::int64_t front_error_mm = 0;     // envelope ahead of the nominal front (>= 0)
  std::int64_t rear_error_mm = 0;      // envelope behind the nominal rear (>= 0)
  std::int64_t speed_mm_s = 0;         // nominal speed (>= 0)
  bool standstill = false;
  std::int64_t margin_mm = 0;          // margin in force (part of both errors)
  std::int64_t accumulated_error_mm = 0;  // TG error since the last balise (part of both errors)
  std::int64_t compensation_bound_mm = 0; // largest active candidate's error bound (0 in TG)
  std::int64_t last_balise_mm = 0;
  // diagnostics for the study and the evidence (not used by consumers)
  double ax_avg = 0, ap_avg = 0;       // m/s^2, the averaged signals compared for detection
  double v_tg = 0;                     // m/s, TG speed of this cycle
  std::array<double, kMaxStartPoints> v_comp{};  // m/s, active candidates' speeds
  std::int32_t start_age_cycles = 0;   // primary start point age at the last detection
  bool detected = false;
  std::int8_t adopted = kNoCandidate;
};

// Braking's position estimate from an output (errors as reported).
[[nodiscard]] braking::PositionEstimate ToPositionEstimate(const OdometryOutput& o) noexcept;
// The ground's position-report correction: max(front_error, rear_error), >= 0.
[[nodiscard]] std::int64_t ReportCorrectionMm(const OdometryOutput& o) noexcept;

// ---- error model (design note §6, REQ-RA-008) ------------------------------------------
// Delta_d(t, g) in mm rounded up: t in ms, g in permille x 10, rate error in udeg/s.
[[nodiscard]] std::int64_t ErrorBoundMm(std::int64_t t_ms, std::int32_t gradient_permille_x10,
                                        std::int64_t rate_error_udeg_s) noexcept;
// Same in metres (double), for the study and tests.
[[nodiscard]] double ErrorBoundM(double t_s, double gradient_permille, double rate_error_deg_s) noexcept;

// ---- the odometry ----------------------------------------------------------------------
class Odometry;
struct OdometryCreateResult;

class Odometry {
 public:
  // Validates and copies the configuration; all storage is inside the object.
  [[nodiscard]] static ConfigError Create(const OdometryConfig& cfg, Odometry& out) noexcept;
  Odometry() noexcept;

  // One 100 ms cycle. Never fails: a rejected input is reported in the output
  // (input_error) and handled as a sensor failure (REQ-RA-013).
  const OdometryOutput& Step(const CycleInput& in) noexcept;

  [[nodiscard]] const OdometryOutput& output() const noexcept { return out_; }
  [[nodiscard]] const ReadhesionMachine& machine() const noexcept { return machine_; }

 private:
  struct Impl;  // fixed-size state, defined in odometry.cpp
  // storage for Impl without heap: sized and aligned in odometry.cpp (static_assert)
  alignas(16) std::array<std::uint8_t, 1 << 17> storage_{};
  ReadhesionMachine machine_{MachineConfig{}};
  OdometryOutput out_{};
};

}  // namespace railproof::odometry
