// Level-crossing units (spec/design/lc.md §2-§5), per call:
//   EarliestArrivalMs            5 km ahead over 20 restrictions (accelerate / cruise pieces)
//   CrossingProtection::Cycle    kMaxCrossings (32) crossings within 5 km, 20 restrictions,
//                                one report per crossing
//   CrossingController::Cycle    two requesters, one start time, barriers down
//   CentreScheduler::Cycle       32 crossings, one position report (recomputation of all;
//                                departure at 100 s: standing reports use the dwell variant)
// Positions cycle over 64 states so the branch pattern is not constant.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <vector>

#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"

namespace {

using namespace railproof::core;  // NOLINT(google-build-using-namespace)
using namespace railproof::lc;  // NOLINT(google-build-using-namespace)
using namespace railproof::lc::onboard;  // NOLINT(google-build-using-namespace)
using namespace railproof::messages;  // NOLINT(google-build-using-namespace)

constexpr std::int64_t kOrigin = 10'000'000;
constexpr std::int64_t kLookAhead = 5'000'000;

std::vector<RestrictionSegment> Restrictions() {
  std::vector<RestrictionSegment> r;
  for (std::int64_t i = 0; i < 20; ++i) {
    const std::int64_t begin = kOrigin + 100'000 + i * 220'000;
    r.push_back(RestrictionSegment{begin, begin + 100'000, 11'111 + (i % 6) * 2'778});
  }
  return r;
}

std::vector<CrossingData> Crossings() {
  std::vector<CrossingData> c;
  for (std::uint32_t i = 0; i < kMaxCrossings; ++i) {
    const std::int64_t near = kOrigin + 200'000 + static_cast<std::int64_t>(i) * (kLookAhead / 33);
    c.push_back(CrossingData{i + 1, near, near + 8'000, 30'000});
  }
  return c;
}

void BM_EarliestArrival(benchmark::State& state) {
  const std::vector<RestrictionSegment> r = Restrictions();
  std::int64_t k = 0;
  for (auto _ : state) {
    const std::int64_t front = kOrigin + (k % 64) * 1'000;
    benchmark::DoNotOptimize(
        railproof::lc::EarliestArrivalMs(front, kOrigin + kLookAhead, 20'000 + (k % 64) * 100, 600, r));
    ++k;
  }
}
BENCHMARK(BM_EarliestArrival);

void BM_ProtectionCycle(benchmark::State& state) {
  const std::vector<RestrictionSegment> r = Restrictions();
  const std::vector<CrossingData> c = Crossings();
  auto created = CrossingProtection::Create(railproof::lc::onboard::DefaultProtectionConfig(1, 200'000, 600));
  CrossingProtection& p = *created.protection;
  (void)p.LoadCrossings(c);
  std::vector<CrossingReport> reports;
  for (const CrossingData& x : c) {
    reports.push_back(CrossingReport{x.id, CrossingStatus::kWarning, 0, 0, false});
  }
  std::int64_t now = 0;
  for (auto _ : state) {
    railproof::lc::onboard::ProtectionInput in;
    in.now_ms = now;
    in.front_mm = kOrigin - (now / 100 % 64) * 100;
    in.speed_mm_s = 25'000;
    in.restrictions = r;
    in.reports = reports;
    benchmark::DoNotOptimize(p.Cycle(in));
    benchmark::DoNotOptimize(p.Output().stop_limit_mm);
    now += 100;
  }
}
BENCHMARK(BM_ProtectionCycle);

void BM_ControllerCycle(benchmark::State& state) {
  auto created = railproof::lc::wayside::CrossingController::Create(railproof::lc::wayside::DefaultControllerConfig(1));
  railproof::lc::wayside::CrossingController& c = *created.controller;
  const std::array<std::uint32_t, 2> trains{{11, 12}};
  const std::array<railproof::lc::wayside::StartTimeMessage, 1> st{{{1, 5, 1'000'000}}};
  std::int64_t now = 0;
  for (auto _ : state) {
    railproof::lc::wayside::ControllerInput in;
    in.now_ms = now;
    in.requests = trains;
    in.start_times = st;
    in.barrier_down = true;
    in.barrier_up = false;
    benchmark::DoNotOptimize(c.Cycle(in));
    now += 100;
  }
}
BENCHMARK(BM_ControllerCycle);

void BM_CentreCycle(benchmark::State& state) {
  const std::vector<RestrictionSegment> r = Restrictions();
  const std::vector<CrossingData> c = Crossings();
  auto created = railproof::lc::wayside::CentreScheduler::Create(railproof::lc::wayside::DefaultSchedulerConfig(600));
  railproof::lc::wayside::CentreScheduler& s = *created.scheduler;
  (void)s.StartDeparture({1, 1, 100'000, kOrigin - 500'000}, c, r, 0);
  std::int64_t now = 0;
  for (auto _ : state) {
    railproof::lc::wayside::SchedulerInput in;
    in.now_ms = now;
    in.restrictions = r;
    in.position = railproof::messages::CentrePositionReport{1, now, kOrigin - 500'000, kOrigin - 700'000, (now / 100 % 64) * 300};
    benchmark::DoNotOptimize(s.Cycle(in));
    now += 100;
  }
}
BENCHMARK(BM_CentreCycle);

}  // namespace
