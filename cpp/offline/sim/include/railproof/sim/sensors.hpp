// The on-board sensors of a simulated train: from the train's true motion (the one
// train-motion model, railproof/offline/dynamics.hpp) to the streams the on-board unit's
// odometry reads, one ra::CycleInput per 100 ms cycle (spec/design/ra.md §2):
//   tachogenerator  cumulative pulse count of a 90-tooth wheel whose true diameter differs
//                   from the nominal one by a drawn share of the length correction (wheel
//                   wear and calibration; the odometry counts with the nominal diameter), and
//                   the capture time of the latest edge, solved exactly from the motion;
//   IMU             ten samples at 10 ms: a_x = train acceleration + g sin(theta), a_z =
//                   g cos(theta), pitch rate from the change of the gradient under the train,
//                   plus seeded white noise (0.02 m/s^2, 0.0005 rad/s: below the wheel-rail
//                   simulator's ASM-027 levels; the system simulation is not an odometry
//                   study, whose errors cpp/offline/ra exercises);
//   balise          the fix of a balise the front passed during the cycle (line position).
// The TG wheel rolls with the train unless the cycle gives the measured axle's own motion: a
// train on the wheel-rail vehicle (wheel_rail_train.hpp), whose axle slips under traction and
// slides under braking on a low-adhesion section; its pulses and edge times are derived from
// that motion the same way, the IMU from the car body's.
//
// Offline module; deterministic for a seed.
#pragma once

#include <cstdint>
#include <optional>

#include "railproof/offline/dynamics.hpp"
#include "railproof/ra/odometry.hpp"
#include "railproof/sim/channel.hpp"

namespace railproof::sim {

struct SensorConfig {
  std::int64_t nominal_wheel_diameter_um = 860'000;  // what the odometry is configured with
  // The true diameter is nominal * (1 + e), e drawn uniformly in [-share, +share] of the
  // length correction (REQ-MB-002: the accumulated TG error the ground adds).
  double diameter_error_share = 0.9;
  std::int64_t length_correction_ppm = 1000;
  double imu_noise_mps2 = 0.02;     // white noise of each acceleration sample (1 sigma)
  double imu_rate_noise_rad_s = 0.0005;
  std::uint64_t seed = 1;
};

// The measured axle's surface speed over a cycle: at its start and its constant change.
struct AxleMotion {
  double speed_mps = 0.0;
  double accel_mps2 = 0.0;
};

// One cycle's true motion: the front at the cycle's start, the constant acceleration over
// the cycle (the simulator's step), and the mean gradient under the train (per mille).
struct TrueCycle {
  std::int64_t time_ms = 0;  // end of the cycle (the odometry's cycle time)
  offline::Motion start;     // m, m/s
  double accel_mps2 = 0.0;
  double gradient_permille = 0.0;
  std::optional<std::int64_t> balise_mm;  // a balise the front passed in the cycle
  std::optional<AxleMotion> axle;         // the TG axle's own motion (else it rolls with the train)
};

class SensorModel {
 public:
  // The pulse count starts at 0; the diameter error is drawn here.
  explicit SensorModel(const SensorConfig& cfg);

  // The sensor data of one cycle (time_ms strictly increasing by the odometry's cycle).
  [[nodiscard]] ra::CycleInput Cycle(const TrueCycle& c);

  [[nodiscard]] double true_pulse_m() const { return pulse_m_; }
  [[nodiscard]] double nominal_pulse_m() const { return nominal_pulse_m_; }
  [[nodiscard]] double diameter_error() const { return error_; }

 private:
  double Gauss();

  SensorConfig cfg_;
  Prng prng_;
  double error_ = 0.0;
  double nominal_pulse_m_ = 0.0;
  double pulse_m_ = 0.0;
  double wheel_m_ = 0.0;         // distance rolled by the wheel since the start
  std::int64_t pulses_ = 0;
  std::int64_t last_edge_us_ = 0;
  double theta_ = 0.0;           // pitch at the end of the previous cycle (rad)
  bool first_ = true;
};

}  // namespace railproof::sim
