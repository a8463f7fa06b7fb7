// The synthetic sensor stream of the benchmarks that drive an odometry (bench_odometry.cpp)
// or the on-board unit around it (cpp/runtime/units/bench): a train that stands for the
// warm-up, runs up to 12 m/s at 1 m/s^2 (the IMU measuring it), settles, and runs on at
// 12 m/s with an optional wheel slip; 90-tooth TG on a 0.86 m wheel, 10 IMU samples a cycle.
// Benchmark code (allocates).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "railproof/ra/odometry.hpp"

namespace railproof::ra::bench {

inline constexpr double kPulseM = 3.14159265358979323846 * 0.86 / 90.0;
inline constexpr double kSpeed = 12.0;    // m/s
inline constexpr double kAccel = 1.0;     // m/s^2 of the run-up
inline constexpr int kRunUpCycles = 120;  // 12 m/s at 1 m/s^2

// Cycles before the constant-speed part: the warm-up, the run-up and the warm-up again at
// 12 m/s (the averages and the TG window hold the constant speed only).
inline int PrefixCycles(int warmup_cycles) { return warmup_cycles + kRunUpCycles + warmup_cycles; }

// A fresh start: the train stands for `warmup_cycles`, runs up to 12 m/s (the IMU measuring it)
// and runs at 12 m/s; `cycles` counts the cycles after the prefix. From cycle `slip_from`
// of them the wheel slips with a slip speed rising 0.3 m/s per cycle to 3 m/s and staying
// there (no re-adhesion). With `noisy_jerk` the IMU a_x alternates +1, +1, -1, -1 m/s^2 at
// constant speed so the jerk conditions fail in every cycle (the start-point search falls
// back to the oldest point).
inline std::vector<CycleInput> MakeStream(int warmup_cycles, int cycles, int slip_from, bool noisy_jerk) {
  std::vector<CycleInput> out;
  out.reserve(static_cast<std::size_t>(PrefixCycles(warmup_cycles) + cycles));
  double v = 0;
  double xw = 0, slip = 0;  // wheel distance and slip speed
  std::int64_t pulses = 0, edge = 0, t_ms = 1'000;
  for (int n = 0; n < PrefixCycles(warmup_cycles) + cycles; ++n) {
    const int k = n - PrefixCycles(warmup_cycles);  // cycle of the constant-speed part (< 0 before it)
    const bool running_up = n >= warmup_cycles && n < warmup_cycles + kRunUpCycles;
    const double v_end = running_up ? std::min(kSpeed, v + kAccel * 0.1) : v;
    t_ms += 100;
    const double slip_end = k < slip_from ? 0.0 : std::min(3.0, 0.3 * (k - slip_from + 1));
    for (int ms = 1; ms <= 100; ++ms) {
      const double s1 = slip + (slip_end - slip) * ms / 100.0;
      const double v1 = v + (v_end - v) * ms / 100.0;
      const double xw0 = xw;
      xw += (v1 + s1) * 0.001;
      while (std::floor(xw / kPulseM) > static_cast<double>(pulses)) {
        ++pulses;
        const double frac = (static_cast<double>(pulses) * kPulseM - xw0) / (xw - xw0);
        edge = std::max<std::int64_t>(edge + 1, (t_ms - 100) * 1000 + (ms - 1) * 1000 + std::llround(frac * 1000.0));
      }
    }
    slip = slip_end;
    v = v_end;
    CycleInput in;
    in.time_ms = t_ms;
    in.tg.time_us = t_ms * 1000;
    in.tg.pulses = pulses;
    in.tg.last_edge_us = edge;
    for (int j = 0; j < 10; ++j) {
      auto& s = in.imu[static_cast<std::size_t>(j)];
      s.time_us = t_ms * 1000 - (9 - j) * 10'000;
      if (running_up) {
        s.ax = kAccel;
      } else if (k < 0) {
        s.ax = 0.0;
      } else {
        s.ax = noisy_jerk ? ((k % 4 < 2) ? 1.0 : -1.0) : 0.01 * std::sin(0.3 * j + k);
      }
      s.ay = 0.02;
      s.az = 9.807;
      s.wx = 0.001;
      s.wy = 0.0005;
      s.wz = 0.002;
    }
    out.push_back(in);
  }
  return out;
}

}  // namespace railproof::ra::bench
