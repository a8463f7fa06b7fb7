// One full ground cycle of the moving-block ground unit (issue target: <= 25 ms for 1,000
// trains on 10,000 virtual blocks, 5 % of the 500 ms ground cycle, on one core): one
// position report per train (validation, tracking update) and Cycle (tracking timeouts,
// in_use index, interlocking, possessions, stop limits with telegrams, virtual-block
// occupancy), for 10, 100, 1,000 and 10,000 trains on a 500 km line of 10,000 blocks of
// 50 m with stations (fixed blocks), junctions (points, routes), radio handover points,
// no-stop sections, possessions and confirmed speed restrictions.
// The cost should grow no worse than (trains + blocks) log(trains).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "railproof/generated/mb_params.hpp"
#include "railproof/mb/wayside/ground.hpp"
#include "bench_line.hpp"

namespace {

using namespace railproof::core;  // NOLINT(google-build-using-namespace)
using namespace railproof::mb::wayside;  // NOLINT(google-build-using-namespace)
using namespace railproof::messages;  // NOLINT(google-build-using-namespace)

using railproof::mb::wayside::bench::BenchLine;
using railproof::mb::wayside::bench::kBlocks;

struct Scenario {
  BenchLine line;
  std::unique_ptr<Ground> ground;
  std::vector<std::int64_t> fronts;
  std::int64_t length_mm = 0;
  std::int64_t now = 0;

  explicit Scenario(std::int64_t trains) {
    Capacity cap = railproof::mb::wayside::DefaultCapacity();
    cap.blocks = static_cast<std::size_t>(kBlocks);
    auto created = Ground::Create(line.Config(), cap);
    if (created.error != ConfigError::kNone) {
      std::abort();
    }
    ground = std::move(created.ground);
    // trains evenly spread over [10 km, 490 km]
    const std::int64_t spacing = 480'000'000 / trains;
    length_mm = std::min<std::int64_t>(200'000, spacing / 2);
    for (std::int64_t i = 0; i < trains; ++i) {
      const std::int64_t front = 10'000'000 + i * spacing + length_mm;
      fronts.push_back(front);
      const auto init = i % 2 == 0 ? InitialPosition::kEntryBalise : InitialPosition::kStabledProvisional;
      if (ground->RegisterTrain({static_cast<std::uint32_t>(i + 1), length_mm, front, 500, init}) !=
          RegisterStatus::kRegistered) {
        std::abort();
      }
      if (i % 3 == 0) {
        (void)ground->SecureHandover(static_cast<std::uint32_t>(i + 1), 2);
      }
    }
    (void)ground->RequestPossession({200'000'000, 201'000'000});
    for (std::int64_t k = 0; k < 20; ++k) {
      const auto r = ground->RequestSpeedRestriction({k * 20'000'000, k * 20'000'000 + 500'000}, 16'667);
      (void)ground->ConfirmSpeedRestriction(r.id);
    }
    (void)ground->Cycle(now);
  }

  // One ground cycle: every train reports (one millimetre further, so that nothing runs off
  // the line however many iterations), then Cycle.
  void FullCycle() {
    now += railproof::params::mb::ground_cycle_ms;
    for (std::size_t i = 0; i < fronts.size(); ++i) {
      fronts[i] += 1;
      const auto pos = ground->LocateFront(fronts[i]);
      const PositionReport r{static_cast<std::uint32_t>(i + 1), pos->block, pos->offset_mm, length_mm,
                             static_cast<std::int64_t>(i % 2'000), 0, 10'000, Direction::kNominal};
      if (ground->OnReport(r) != ReportStatus::kAccepted) {
        std::abort();
      }
    }
    if (ground->Cycle(now) != CycleStatus::kDone) {
      std::abort();
    }
  }
};

void BM_GroundFullCycle(benchmark::State& state) {
  Scenario s(state.range(0));
  for (auto _ : state) {
    s.FullCycle();
    benchmark::DoNotOptimize(s.ground->Telegrams().data());
  }
  state.counters["trains"] = static_cast<double>(state.range(0));
  state.counters["blocks"] = static_cast<double>(kBlocks);
  state.counters["telegrams"] = static_cast<double>(s.ground->Telegrams().size());
}
BENCHMARK(BM_GroundFullCycle)->Arg(10)->Arg(100)->Arg(1'000)->Arg(10'000)->Unit(benchmark::kMillisecond);

}  // namespace
