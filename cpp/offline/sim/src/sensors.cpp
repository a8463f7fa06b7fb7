// The on-board sensors of a simulated train (sensors.hpp).
#include "railproof/sim/sensors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "railproof/generated/ra_params.hpp"

namespace railproof::sim {

namespace {

constexpr double kTeeth = static_cast<double>(params::ra::tg_teeth);
constexpr std::int64_t kCycleMs = params::ra::cycle_ms;
constexpr std::int64_t kImuSampleMs = params::ra::imu_sample_ms;

}  // namespace

SensorModel::SensorModel(const SensorConfig& cfg) : cfg_(cfg), prng_(cfg.seed) {
  const double share = static_cast<double>(cfg.length_correction_ppm) / 1e6 * cfg.diameter_error_share;
  error_ = share * (2.0 * prng_.Uniform() - 1.0);
  nominal_pulse_m_ = std::numbers::pi * static_cast<double>(cfg.nominal_wheel_diameter_um) / 1e6 / kTeeth;
  pulse_m_ = nominal_pulse_m_ * (1.0 + error_);
}

double SensorModel::Gauss() {
  // Box-Muller on the simulator's own generator (deterministic across platforms)
  const double u1 = std::max(prng_.Uniform(), 1e-300);
  const double u2 = prng_.Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

ra::CycleInput SensorModel::Cycle(const TrueCycle& c) {
  ra::CycleInput in;
  in.time_ms = c.time_ms;
  const double dt = static_cast<double>(kCycleMs) / 1000.0;
  const std::int64_t t0_us = (c.time_ms - kCycleMs) * 1000;
  // tachogenerator: every pulse the wheel completes in the cycle, its edge at the exact time
  const offline::Motion wheel = c.axle ? offline::Motion{c.start.position, c.axle->speed_mps} : c.start;
  const double wheel_accel = c.axle ? c.axle->accel_mps2 : c.accel_mps2;
  const offline::Motion end = offline::Advance(wheel, wheel_accel, dt);
  const double rolled = end.position - wheel.position;
  const double before = wheel_m_;
  wheel_m_ += rolled;
  const auto pulses_now = static_cast<std::int64_t>(std::floor(wheel_m_ / pulse_m_));
  if (pulses_now > pulses_) {
    const double to_last = static_cast<double>(pulses_now) * pulse_m_ - before;
    const double t = std::clamp(offline::TimeToCover(wheel.speed, wheel_accel, to_last), 0.0, dt);
    const std::int64_t edge = t0_us + std::llround(t * 1e6);
    last_edge_us_ = std::max(edge, last_edge_us_ + 1);
    pulses_ = pulses_now;
  }
  in.tg.time_us = c.time_ms * 1000;
  in.tg.pulses = pulses_;
  in.tg.last_edge_us = std::min(last_edge_us_, in.tg.time_us);
  // IMU: gravity along the pitched body axes, the train's acceleration while it moves
  const double theta = std::atan(c.gradient_permille / 1000.0);
  const double theta_prev = first_ ? theta : theta_;
  const double pitch_rate = (theta - theta_prev) / dt;
  first_ = false;
  theta_ = theta;
  constexpr double g = offline::kGravity;
  for (int j = 0; j < ra::kImuSamplesPerCycle; ++j) {
    const double ts = static_cast<double>((j + 1) * kImuSampleMs) / 1000.0;
    const offline::Motion m = offline::Advance(c.start, c.accel_mps2, ts);
    const bool moving = m.speed > 0.0 || c.accel_mps2 > 0.0;
    const double a = moving ? c.accel_mps2 : 0.0;
    const double th = theta_prev + (theta - theta_prev) * ts / dt;
    ra::ImuSample& s = in.imu[static_cast<std::size_t>(j)];
    s.time_us = t0_us + (j + 1) * kImuSampleMs * 1000;
    s.ax = a + g * std::sin(th) + cfg_.imu_noise_mps2 * Gauss();
    s.ay = cfg_.imu_noise_mps2 * Gauss();
    s.az = g * std::cos(th) + cfg_.imu_noise_mps2 * Gauss();
    s.wx = cfg_.imu_rate_noise_rad_s * Gauss();
    s.wy = pitch_rate + cfg_.imu_rate_noise_rad_s * Gauss();
    s.wz = cfg_.imu_rate_noise_rad_s * Gauss();
  }
  in.imu_count = static_cast<std::uint8_t>(ra::kImuSamplesPerCycle);
  if (c.balise_mm) {
    in.balise = ra::BaliseFix{*c.balise_mm};
  }
  return in;
}

}  // namespace railproof::sim
