// One odometry cycle (spec/design/ra.md; budget <= 50 us per 100 ms cycle on one
// core): Odometry::Step in TG odometry, in a compensating cycle with both parallel start
// points active, and on the detection cycle with the deepest catch-up (start point at the
// oldest allowed point d - 75, the second at d - 100: 175 candidate cycles integrated from
// the history). Synthetic 12 m/s stream, level line, 90-tooth TG, 10 IMU samples a cycle;
// each stream begins with the start-up the odometry needs (REQ-RA-015: a warm-up at
// standstill, a run-up to 12 m/s, the averages settling), which is never timed.
// The compensating and detection cycles are timed manually around Step (the state is
// restored from a copy outside the timed region).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "railproof/ra/odometry.hpp"

namespace {

using namespace railproof::ra;  // NOLINT(google-build-using-namespace)

constexpr double kPulseM = 3.14159265358979323846 * 0.86 / 90.0;

constexpr double kSpeed = 12.0;   // m/s
constexpr double kAccel = 1.0;    // m/s^2 of the run-up
constexpr int kRunUpCycles = 120;  // 12 m/s at 1 m/s^2
std::unique_ptr<Odometry> Make();

// The warm-up at standstill the odometry needs after its start before it trusts its TG
// history (REQ-RA-015), as its re-adhesion machine is configured.
int WarmupCycles() {
  static const int cycles = Make()->machine().config().warmup_cycles;
  return cycles;
}
// Cycles before the constant-speed part: the warm-up, the run-up and the warm-up again at
// 12 m/s (the averages and the TG window hold the constant speed only).
int PrefixCycles() { return WarmupCycles() + kRunUpCycles + WarmupCycles(); }

// A fresh start: the train stands for the warm-up, runs up to 12 m/s (the IMU measuring it)
// and runs at 12 m/s; `cycles` counts the cycles after the prefix. From cycle `slip_from`
// of them the wheel slips with a slip speed rising 0.3 m/s per cycle to 3 m/s and staying
// there (no re-adhesion). With `noisy_jerk` the IMU a_x alternates +1, +1, -1, -1 m/s^2 at
// constant speed so the jerk conditions fail in every cycle (the start-point search falls
// back to the oldest point).
std::vector<CycleInput> MakeStream(int cycles, int slip_from, bool noisy_jerk) {
  std::vector<CycleInput> out;
  out.reserve(static_cast<std::size_t>(PrefixCycles() + cycles));
  double v = 0;
  double xw = 0, slip = 0;  // wheel distance and slip speed
  std::int64_t pulses = 0, edge = 0, t_ms = 1'000;
  for (int n = 0; n < PrefixCycles() + cycles; ++n) {
    const int k = n - PrefixCycles();  // cycle of the constant-speed part (< 0 before it)
    const bool running_up = n >= WarmupCycles() && n < WarmupCycles() + kRunUpCycles;
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

const std::vector<OdometrySection>& Sections() {
  static const std::vector<OdometrySection> s = {{0, 100'000'000, 0, 20'000, 0}};
  return s;
}

std::unique_ptr<Odometry> Make() {
  OdometryConfig cfg;
  cfg.method = Method::kImu;
  cfg.train_length_mm = 60'000;
  cfg.sections = Sections().data();
  cfg.section_count = static_cast<int>(Sections().size());
  cfg.initial_front_mm = 1'000'000;
  auto od = std::make_unique<Odometry>();
  if (Odometry::Create(cfg, *od) != railproof::ra::ConfigError::kNone) std::abort();
  return od;
}

// A fresh odometry stepped through the stream up to its first detection cycle: the cycle and
// the state after it (with `before`: the state before it).
struct Detection {
  std::size_t cycle = 0;
  std::unique_ptr<Odometry> state;  // null: no detection (the benchmark is skipped)
};

Detection RunToDetection(benchmark::State& state, const std::vector<CycleInput>& stream, bool before) {
  auto od = Make();
  for (std::size_t k = 0; k < stream.size(); ++k) {
    const Odometry previous(*od);
    if (od->Step(stream[k]).detected) {
      if (before) {
        *od = previous;
      }
      return {k, std::move(od)};
    }
  }
  state.SkipWithError("no detection");
  return {};
}

// One Step timed by hand (the benchmarks below use manual time); its output.
const OdometryOutput& TimedStep(benchmark::State& state, Odometry& od, const CycleInput& in) {
  const auto t0 = std::chrono::steady_clock::now();
  const OdometryOutput& o = od.Step(in);
  benchmark::DoNotOptimize(o);
  const auto t1 = std::chrono::steady_clock::now();
  state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  return o;
}

// The odometry after the start-up prefix of a stream (warm-up, run-up, settling).
std::unique_ptr<Odometry> AfterPrefix(const std::vector<CycleInput>& stream) {
  auto od = Make();
  for (std::size_t k = 0; k < static_cast<std::size_t>(PrefixCycles()); ++k) {
    od->Step(stream[k]);
  }
  return od;
}

// TG odometry: every constant-speed cycle of a stream of 4096 of them without slip (the
// odometry re-created after the start-up prefix at the stream's end, untimed).
void BM_OdometryStepTg(benchmark::State& state) {
  const auto stream = MakeStream(4'096, 1'000'000, false);
  auto od = AfterPrefix(stream);
  if (od->output().mode != Mode::kTg || !od->output().position_valid) {
    state.SkipWithError("not in TG odometry after the start-up");
    return;
  }
  std::size_t i = static_cast<std::size_t>(PrefixCycles());
  for (auto _ : state) {
    if (i == stream.size()) {
      state.PauseTiming();
      od = AfterPrefix(stream);
      i = static_cast<std::size_t>(PrefixCycles());
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(od->Step(stream[i]));
    ++i;
  }
  if (od->output().mode != Mode::kTg) state.SkipWithError("not in TG odometry");
  state.SetLabel("TG mode, 12 m/s");
}
BENCHMARK(BM_OdometryStepTg);

// Compensating with both start points active: the cycles after the detection until the
// older candidate times out, replayed from a copy of the state after the detection.
void BM_OdometryStepCompensatingTwoCandidates(benchmark::State& state) {
  const auto stream = MakeStream(400, 200, false);
  const Detection at = RunToDetection(state, stream, false);
  if (!at.state) {
    return;
  }
  const std::size_t d = at.cycle;
  auto od = std::make_unique<Odometry>(*at.state);
  std::size_t i = d + 1;
  for (auto _ : state) {
    const auto& st = od->machine().state();
    if (i == stream.size() || !(st.candidates[0].active && st.candidates[1].active)) {
      *od = *at.state;
      i = d + 1;
    }
    TimedStep(state, *od, stream[i]);
    ++i;
  }
  state.SetLabel("two candidates active");
}
BENCHMARK(BM_OdometryStepCompensatingTwoCandidates)->UseManualTime();

// The detection cycle with the deepest catch-up (start point d - 75, second d - 100).
void BM_OdometryStepDetectionWorstCase(benchmark::State& state) {
  const auto stream = MakeStream(300, 200, true);
  const Detection at = RunToDetection(state, stream, true);
  if (!at.state) {
    return;
  }
  auto od = std::make_unique<Odometry>(*at.state);
  std::int32_t age = 0;
  for (auto _ : state) {
    *od = *at.state;
    age = TimedStep(state, *od, stream[at.cycle]).start_age_cycles;
  }
  if (age != 75) state.SkipWithError("not the deepest catch-up");
  state.SetLabel("catch-up 75 + 100 cycles");
}
BENCHMARK(BM_OdometryStepDetectionWorstCase)->UseManualTime();

}  // namespace
