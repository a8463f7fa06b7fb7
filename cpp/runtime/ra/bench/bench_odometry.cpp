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
#include "slip_stream.hpp"

namespace {

using namespace railproof::ra;  // NOLINT(google-build-using-namespace)

std::unique_ptr<Odometry> Make();

// The warm-up at standstill the odometry needs after its start before it trusts its TG
// history (REQ-RA-015), as its re-adhesion machine is configured.
int WarmupCycles() {
  static const int cycles = Make()->machine().config().warmup_cycles;
  return cycles;
}
int PrefixCycles() { return bench::PrefixCycles(WarmupCycles()); }

std::vector<CycleInput> MakeStream(int cycles, int slip_from, bool noisy_jerk) {
  return bench::MakeStream(WarmupCycles(), cycles, slip_from, noisy_jerk);
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
