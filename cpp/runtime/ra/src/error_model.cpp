// Error model of the IMU compensation (spec/design/ra.md §6), the conversions of the
// odometry output for the braking supervision and the ground (§8) and the reason names.
//
// Seeded fault (negative test, cpp/runtime/ra/tests/test_odometry.cpp kills it):
//   FAULT_RA_NO_GRADIENT_TERM   Delta_a without the gradient term Delta_a_g
// Active only in the test-only schemata variant (spec/design/seeded-faults.md).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/seeded_fault.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/odometry.hpp"

namespace railproof::ra {
namespace {

namespace p = params::ra;

constexpr double kPi = 3.14159265358979323846;

// Delta_a in the unit of `gravity` (mm/s^2 or m/s^2) for t in seconds, gradient in permille
// (magnitude) and the rate error in degrees per second.
double DeltaA(double gravity, double tg_error, double imu_error, double t_s, double gradient_permille,
              double rate_error_deg_s) noexcept {
  const double drift = gravity * std::sin(rate_error_deg_s * kPi / 180.0 * t_s);
  const double grade = RAILPROOF_FAULT(FAULT_RA_NO_GRADIENT_TERM) ? 0.0 : gravity * gradient_permille / 1000.0;
  return tg_error + imu_error + drift + grade;
}

}  // namespace

// @implements REQ-RA-008
std::int64_t ErrorBoundMm(std::int64_t t_ms, std::int32_t gradient_permille_x10,
                          std::int64_t rate_error_udeg_s) noexcept {
  if (t_ms <= 0) return 0;
  const double t_s = static_cast<double>(t_ms) / 1000.0;
  const double g = std::fabs(static_cast<double>(gradient_permille_x10)) / 10.0;
  const double rate = std::fabs(static_cast<double>(rate_error_udeg_s)) * 1e-6;
  const double da = DeltaA(static_cast<double>(p::gravity_mm_s2), static_cast<double>(p::tg_accel_error_mm_s2),
                           static_cast<double>(p::imu_accel_error_mm_s2), t_s, g, rate);
  const double dd = 0.5 * da * t_s * t_s;  // mm
  // Rounded up to the next mm (REQ-RA-008). The argument is bounded (t <= 1e7 s would be
  // needed to leave the int64 range), so the conversion is exact after std::ceil.
  const double capped = std::min(std::ceil(dd), 1e15);
  return static_cast<std::int64_t>(capped);
}

// @implements REQ-RA-008
double ErrorBoundM(double t_s, double gradient_permille, double rate_error_deg_s) noexcept {
  if (!(t_s > 0.0)) return 0.0;
  const double g_ms2 = static_cast<double>(p::gravity_mm_s2) / 1000.0;
  const double da = DeltaA(g_ms2, static_cast<double>(p::tg_accel_error_mm_s2) / 1000.0,
                           static_cast<double>(p::imu_accel_error_mm_s2) / 1000.0, t_s,
                           std::fabs(gradient_permille), std::fabs(rate_error_deg_s));
  return 0.5 * da * t_s * t_s;
}

// @implements REQ-RA-012
core::PositionEstimate ToPositionEstimate(const OdometryOutput& o) noexcept {
  core::PositionEstimate e;
  e.front_mm = o.front_mm;
  e.front_error_mm = std::max<std::int64_t>(o.front_error_mm, 0);
  e.rear_error_mm = std::max<std::int64_t>(o.rear_error_mm, 0);
  e.speed_mm_s = std::max<std::int64_t>(o.speed_mm_s, 0);
  e.standstill = o.standstill;
  return e;
}

// @implements REQ-RA-012
std::int64_t ReportCorrectionMm(const OdometryOutput& o) noexcept {
  return std::max<std::int64_t>({o.front_error_mm, o.rear_error_mm, 0});
}

const char* ToString(InputError e) noexcept {
  return core::EnumName(e, std::array<const char*, 9>{"none", "cycle time not one cycle after the previous (gap or non-monotonic)", "TG pulse count decreasing", "TG edge or sample time invalid", "TG pulse rate above the maximum speed", "IMU sample count not imu_samples_per_cycle", "IMU timestamps not spaced imu_sample_ms within the cycle", "IMU value not finite", "IMU value out of range"}, "unknown");
}

const char* ToString(ConfigError e) noexcept {
  return core::EnumName(e, std::array<const char*, 14>{"none", "wheel diameter not in 500..1500 mm", "train length not in 1..1000 m", "detection threshold not in 50..2000 mm/s^2", "start points not 1..2", "IMU rate error negative or above 1 deg/s", "section count 0, above the capacity, or no section array", "sections not ordered and contiguous (begin >= end, overlap or gap)", "section gradient negative or above 100 permille", "section maximum compensation time outside [min, limit] or not whole cycles", "section margin below the error model", "baseline acceleration bounds not positive", "initial front outside the section table", "length correction not in 0..100000 ppm"}, "unknown");
}

}  // namespace railproof::ra
