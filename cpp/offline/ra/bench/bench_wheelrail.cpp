// Wheel-rail simulator throughput: the 10-minute scenario of the suite
// (spec/wheelrail/long_run_10min.json: 600 s at a 1 ms Box2D step, 4 wheelsets with 10
// spin sub-steps each, IMU every 10 ms, 6000 odometry cycles). Target: at least 100 times
// faster than real time, i.e. one run in under 6 s. Counters: realtime_factor = simulated
// seconds per wall-clock second; cpu_factor = simulated seconds per CPU second of the
// process (independent of other load on the machine).
#include <benchmark/benchmark.h>

#include <ctime>
#include <filesystem>

#include "railproof/ra/analysis/wheel_rail.hpp"

namespace {

const std::filesystem::path kScenario =
    std::filesystem::path(RAILPROOF_TEST_SOURCE_DIR) / "spec" / "wheelrail" / "long_run_10min.json";

void BM_WheelRailLongRun(benchmark::State& state) {
  const auto sc = railproof::ra::analysis::LoadWheelRailScenario(kScenario);
  double simulated = 0.0;
  std::size_t cycles = 0;
  const std::clock_t cpu0 = std::clock();
  for (auto _ : state) {
    const auto run = railproof::ra::analysis::SimulateWheelRail(sc);
    simulated += run.simulated_s;
    cycles = run.cycles.size();
    benchmark::DoNotOptimize(run.truth.back().front_m);
  }
  const double cpu_s = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  state.counters["realtime_factor"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["cpu_factor"] = cpu_s > 0.0 ? simulated / cpu_s : 0.0;
  state.counters["cycles"] = static_cast<double>(cycles);
}
BENCHMARK(BM_WheelRailLongRun)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(3);

}  // namespace
