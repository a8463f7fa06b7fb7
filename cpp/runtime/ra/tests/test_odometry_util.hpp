// Helpers of the odometry unit tests: a synthetic sensor stream (train kinematics, wheel
// slip, TG pulses with edge times, IMU cycle values) and the standard configuration.
// Header-only so that each test file builds alone (seeded-fault builds compile one file).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <vector>

#include "railproof/generated/ra_params.hpp"
#include "railproof/ra/odometry.hpp"

namespace railproof::ra::test {

inline constexpr double kG = 9.807;                                       // m/s^2
inline constexpr double kPulseUm = 3.14159265358979323846 * 860000.0 / 90.0;  // 30019.66 um
inline constexpr std::int64_t kInitialFrontMm = 1'000'000;                // 1 km
inline constexpr std::int64_t kTrainLengthMm = 60'000;

// One section over the whole test line: level, 20 s, margin from the error model.
inline std::vector<OdometrySection> LevelLine() {
  return {OdometrySection{0, 100'000'000, 0, 20'000, 0}};
}

inline OdometryConfig Config(const std::vector<OdometrySection>& sections, Method method = Method::kImu) {
  return OdometryConfig{.method = method,
                        .wheel_diameter_um = 860'000,
                        .train_length_mm = kTrainLengthMm,
                        .detect_threshold_mm_s2 = 340,
                        .start_points = 2,
                        .imu_rate_error_udeg_s = 2'500,
                        .length_correction_ppm = 1'000,
                        .accel_max_mm_s2 = OdometryConfig{}.accel_max_mm_s2,  // D1's figures
                        .decel_max_mm_s2 = OdometryConfig{}.decel_max_mm_s2,
                        .sections = sections.data(),
                        .section_count = static_cast<int>(sections.size()),
                        .initial_front_mm = kInitialFrontMm};
}

inline std::unique_ptr<Odometry> Make(const OdometryConfig& cfg) {
  auto od = std::make_unique<Odometry>();
  const ConfigError e = Odometry::Create(cfg, *od);
  EXPECT_EQ(e, ConfigError::kNone) << ToString(e);
  return od;
}

// IMU cycle values: every one of the 10 samples carries them.
struct ImuValues {
  double ax = 0, ay = 0, az = kG, wx = 0, wy = 0, wz = 0;
};

// At rest or at a constant speed on a constant gradient theta (rad): gravity along x and z.
inline ImuValues OnGradient(double theta) {
  ImuValues m;
  m.ax = kG * std::sin(theta);
  m.az = kG * std::cos(theta);
  return m;
}

// Train kinematics of one cycle: constant train acceleration `a`; the wheel's slip speed
// (wheel peripheral speed minus train speed) goes linearly to `slip_end` (m/s) over the cycle.
struct Kinematics {
  double a = 0;
  double slip_end = 0;
};

// Synthetic stream: integrates the train and the wheel in 1 ms steps, counts TG pulses
// (pulse length pi * 0.86 m / 90) and records each pulse edge time (linear interpolation
// within the ms, rounded to the us, strictly increasing).
// A hand-made cycle: TG values as given, IMU level and at rest unless changed.
inline CycleInput Cycle(std::int64_t time_ms, std::int64_t pulses, std::int64_t edge_us, const ImuValues& m = {}) {
  CycleInput in;
  in.time_ms = time_ms;
  in.tg.time_us = time_ms * 1000;
  in.tg.pulses = pulses;
  in.tg.last_edge_us = edge_us;
  for (int j = 0; j < kImuSamplesPerCycle; ++j) {
    const std::int64_t t_us = time_ms * 1000 - (9 - j) * 10'000;
    in.imu[static_cast<std::size_t>(j)] = ImuSample{t_us, m.ax, m.ay, m.az, m.wx, m.wy, m.wz};
  }
  return in;
}

class Stream {
 public:
  explicit Stream(double v0 = 0.0, std::int64_t t0_ms = 1'000) : v_(v0), time_ms_(t0_ms) {}

  CycleInput Next(const Kinematics& k = {}, const ImuValues& m = {},
                  std::optional<std::int64_t> balise_mm = std::nullopt) {
    time_ms_ += 100;
    const double slip0 = slip_;
    const std::int64_t t0_us = (time_ms_ - 100) * 1000;
    for (int ms = 1; ms <= 100; ++ms) {
      const double v1 = v_ + k.a * 0.001;
      x_ += 0.5 * (v_ + v1) * 0.001;
      const double s1 = slip0 + (k.slip_end - slip0) * ms / 100.0;
      const double w0 = v_ + slip_;
      const double w1 = v1 + s1;
      const double xw0 = xw_;
      xw_ += 0.5 * (w0 + w1) * 0.001;
      v_ = v1;
      slip_ = s1;
      while (std::floor(xw_ * 1e6 / kPulseUm) > static_cast<double>(pulses_)) {
        ++pulses_;
        const double target = static_cast<double>(pulses_) * kPulseUm * 1e-6;
        const double frac = (target - xw0) / (xw_ - xw0);
        std::int64_t edge = t0_us + (ms - 1) * 1000 + std::llround(frac * 1000.0);
        if (edge <= edge_us_) edge = edge_us_ + 1;
        edge_us_ = edge;
      }
    }
    slip_ = k.slip_end;
    if (first_) {
      // the odometry's reference is its first sample
      first_ = false;
      x_first_ = x_;
      pulses_first_ = pulses_;
    }
    CycleInput in = Cycle(time_ms_, pulses_, edge_us_, m);
    in.imu_count = static_cast<std::uint8_t>(kImuSamplesPerCycle);
    if (balise_mm) in.balise = BaliseFix{*balise_mm};
    return in;
  }

  // true line position of the front (mm): kInitialFrontMm at the first cycle's sample
  [[nodiscard]] double TrueFrontMm() const { return static_cast<double>(kInitialFrontMm) + (x_ - x_first_) * 1000.0; }
  // pulses since the first cycle's sample
  [[nodiscard]] std::int64_t PulsesSinceFirst() const { return pulses_ - pulses_first_; }
  [[nodiscard]] double speed() const { return v_; }
  [[nodiscard]] double x() const { return x_; }
  [[nodiscard]] std::int64_t pulses() const { return pulses_; }
  [[nodiscard]] std::int64_t time_ms() const { return time_ms_; }

 private:
  double v_ = 0, x_ = 0, slip_ = 0, xw_ = 0;
  bool first_ = true;
  double x_first_ = 0;
  std::int64_t pulses_first_ = 0;
  std::int64_t pulses_ = 0;
  std::int64_t edge_us_ = 0;
  std::int64_t time_ms_ = 0;
};


// The warm-up at standstill the odometry needs after its start (REQ-RA-015): the moving
// averages plus the TG window.
inline constexpr int kWarmupCycles =
    static_cast<int>((params::ra::moving_average_ms + params::ra::tg_window_ms) / params::ra::cycle_ms);

// A running train whose odometry is trusted (REQ-RA-015): a fresh odometry and a stream at
// standstill; the warm-up, a run-up to v0 at `accel` (the IMU measuring it; `level` are the
// IMU values at rest, e.g. OnGradient), then kSettleCycles at v0 so that the averages and
// the TG window hold the constant speed only. The test's own cycles follow; the stream's
// true front and pulse count stay relative to its first sample, taken at standstill.
inline constexpr int kSettleCycles = kWarmupCycles + 5;
inline std::vector<CycleInput> RunUpInputs(Stream& s, double v0, const ImuValues& level = {}, double accel = 1.0) {
  std::vector<CycleInput> v;
  for (int k = 0; k < kWarmupCycles; ++k) v.push_back(s.Next({}, level));
  while (s.speed() < v0 - 1e-9) {
    const double a = std::min(accel, (v0 - s.speed()) / 0.1);
    ImuValues m = level;
    m.ax += a;
    v.push_back(s.Next({a, 0.0}, m));
  }
  for (int k = 0; k < kSettleCycles; ++k) v.push_back(s.Next({}, level));
  return v;
}
inline void RunUp(Odometry& od, Stream& s, double v0, const ImuValues& level = {}, double accel = 1.0) {
  for (const CycleInput& in : RunUpInputs(s, v0, level, accel)) {
    EXPECT_FALSE(od.Step(in).detected) << "run-up, cycle at " << in.time_ms << " ms";
  }
  ASSERT_EQ(od.output().mode, Mode::kTg);
  ASSERT_TRUE(od.output().position_valid);
}

// After a stop demand: the train brakes to a standstill at 1 m/s^2 (the IMU measuring it)
// and stands for the warm-up, the stop demand held throughout; each cycle passes through
// `adjust` first (e.g. a restarted counter's offset). The history is then trusted again
// (REQ-RA-015) and the next balise ends the stop.
template <typename Adjust>
void BrakeAndWarmUp(Odometry& od, Stream& s, Adjust adjust) {
  while (s.speed() > 1e-9) {
    const double a = -std::min(1.0, s.speed() / 0.1);
    ImuValues m;
    m.ax = a;
    CycleInput in = s.Next({a, 0.0}, m);
    adjust(in);
    EXPECT_TRUE(od.Step(in).stop_demand) << "braking at " << s.speed() << " m/s";
  }
  for (int k = 0; k < kWarmupCycles; ++k) {
    CycleInput in = s.Next();
    adjust(in);
    EXPECT_TRUE(od.Step(in).stop_demand) << "warm-up cycle " << k;
  }
  EXPECT_TRUE(od.machine().state().trusted);
}
inline void BrakeAndWarmUp(Odometry& od, Stream& s) {
  BrakeAndWarmUp(od, s, [](CycleInput&) {});
}

// v[k] with an int index.
template <typename T>
const T& Get(const std::vector<T>& v, int k) {
  return v[static_cast<std::size_t>(k)];
}

inline std::uint64_t Bits(double v) {
  std::uint64_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  return u;
}

// Every field, doubles bit for bit.
inline bool SameOutput(const OdometryOutput& a, const OdometryOutput& b) {
  bool same = a.time_ms == b.time_ms && a.mode == b.mode && a.stop_reason == b.stop_reason &&
              a.input_error == b.input_error && a.position_valid == b.position_valid &&
              a.stop_demand == b.stop_demand && a.front_mm == b.front_mm && a.front_error_mm == b.front_error_mm &&
              a.rear_error_mm == b.rear_error_mm && a.speed_mm_s == b.speed_mm_s && a.standstill == b.standstill &&
              a.margin_mm == b.margin_mm && a.accumulated_error_mm == b.accumulated_error_mm &&
              a.compensation_bound_mm == b.compensation_bound_mm && a.last_balise_mm == b.last_balise_mm &&
              Bits(a.ax_avg) == Bits(b.ax_avg) && Bits(a.ap_avg) == Bits(b.ap_avg) && Bits(a.v_tg) == Bits(b.v_tg) &&
              a.start_age_cycles == b.start_age_cycles && a.detected == b.detected && a.adopted == b.adopted;
  for (std::size_t c = 0; c < a.v_comp.size(); ++c) {
    same = same && Bits(a.v_comp[c]) == Bits(b.v_comp[c]) && a.x_comp_mm[c] == b.x_comp_mm[c];
  }
  return same;
}

// A slip: the wheel's slip speed rises by `peak` m/s over `rise` cycles and falls back to
// zero over the same number (re-adhesion), starting at cycle `from`.
inline double TriangularSlip(int cycle, int from, int rise, double peak) {
  if (cycle < from) return 0.0;
  const int n = cycle - from + 1;
  if (n <= rise) return peak * n / rise;
  if (n <= 2 * rise) return peak * (2 * rise - n) / rise;
  return 0.0;
}

}  // namespace railproof::ra::test
