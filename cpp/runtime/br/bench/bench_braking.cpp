// One on-board supervision cycle (REQ-BR-013: <= 20 us with a 5 km look-ahead and 50
// profile changes): PatternCalculator::Evaluate (v_s, emergency pattern, service pattern at
// the front and at the 6N/5N/4N/release leads, each a bisection over O(log n) checks) plus
// Supervisor::Step, on an emu3_d1 train with 30 gradient segments and 20 speed restrictions
// in the 5 km ahead and a stop limit 4.5 km ahead; positions and speeds cycle over 64 states
// between the train and the stop limit. Also measured: SetProfile alone (when the profile
// changes) and SetProfile + cycle (profile re-sent every cycle).
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <optional>
#include <vector>

#include "railproof/br/patterns.hpp"
#include "railproof/br/supervisor.hpp"

namespace {

using namespace railproof::br;  // NOLINT(google-build-using-namespace)

constexpr std::int64_t kOrigin = 10'000'000;       // train front at km 10
constexpr std::int64_t kLookAhead = 5'000'000;     // params::br::lookahead_mm
constexpr std::int64_t kStopLimit = kOrigin + 4'500'000;

struct BenchProfile {
  std::vector<GradientSegment> gradients;
  std::vector<RestrictionSegment> restrictions;
  std::array<PositionEstimate, 64> positions{};

  BenchProfile() {
    // 30 gradient changes: segments of ~167 m, -25..+25 permille, a few gaps (level)
    for (std::int64_t i = 0; i < 30; ++i) {
      const std::int64_t begin = kOrigin - 200'000 + i * (kLookAhead + 200'000) / 30;
      const std::int64_t end = begin + (kLookAhead + 200'000) / 30 - (i % 4 == 0 ? 20'000 : 0);
      gradients.push_back(GradientSegment{begin, end, ((i * 37) % 51 - 25) * 10});
    }
    // 20 restrictions: 100 m each every 220 m, 40..90 km/h
    for (std::int64_t i = 0; i < 20; ++i) {
      const std::int64_t begin = kOrigin + 100'000 + i * 220'000;
      restrictions.push_back(RestrictionSegment{begin, begin + 100'000, 11'111 + (i % 6) * 2'778});
    }
    for (std::size_t i = 0; i < positions.size(); ++i) {
      const auto k = static_cast<std::int64_t>(i);
      positions[i] = PositionEstimate{kOrigin + k * 60'000, 40'000, 40'000, 8'000 + (k * 997) % 15'000, false};
    }
  }
};

TrainData Emu3() { return TrainData{60'000, 920, 1'000, 900, 1'500, 2'500, 1'389, 2'500, 174}; }

PatternCalculator MakeCalculator(const BenchProfile& p) {
  auto created = PatternCalculator::Create(Emu3(), DefaultSupervisionParams());
  if (!created.calculator || created.calculator->SetProfile(p.gradients, p.restrictions).verdict !=
                                 ProfileVerdict::kAccept) {
    std::abort();
  }
  return std::move(*created.calculator);
}

// Evaluate + Step: one supervision cycle.
void BM_BrakingSupervisionCycle(benchmark::State& state) {
  const BenchProfile profile;
  const PatternCalculator calc = MakeCalculator(profile);
  Supervisor supervisor;
  std::size_t i = 0;
  for (auto _ : state) {
    const auto e = calc.Evaluate(profile.positions[i], kStopLimit);
    const auto d = supervisor.Step(e.speeds, DriverInputs{false, true, true});
    benchmark::DoNotOptimize(d);
    i = (i + 1) % profile.positions.size();
  }
  state.SetLabel("5 km look-ahead, 30 gradients + 20 restrictions");
}
BENCHMARK(BM_BrakingSupervisionCycle);

// SetProfile alone (50 profile entries).
void BM_BrakingSetProfile(benchmark::State& state) {
  const BenchProfile profile;
  PatternCalculator calc = MakeCalculator(profile);
  for (auto _ : state) {
    const auto r = calc.SetProfile(profile.gradients, profile.restrictions);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_BrakingSetProfile);

// SetProfile + Evaluate + Step: the profile re-sent and re-installed every cycle.
void BM_BrakingCycleWithProfile(benchmark::State& state) {
  const BenchProfile profile;
  PatternCalculator calc = MakeCalculator(profile);
  Supervisor supervisor;
  std::size_t i = 0;
  for (auto _ : state) {
    (void)calc.SetProfile(profile.gradients, profile.restrictions);
    const auto e = calc.Evaluate(profile.positions[i], kStopLimit);
    const auto d = supervisor.Step(e.speeds, DriverInputs{false, true, true});
    benchmark::DoNotOptimize(d);
    i = (i + 1) % profile.positions.size();
  }
}
BENCHMARK(BM_BrakingCycleWithProfile);

}  // namespace
