// libFuzzer target: the line-scenario loader of line_sim (sim::ParseScenario and the fit to
// its line, sim::SelectRunningLine and sim::CheckScenarioAgainstLine; cpp/offline/sim/src/
// scenario.cpp) on any bytes, structure-aware (json_fuzz.hpp). Seeds: the committed corpus
// and spec/scenarios; the lines are the generated ones (build/gen/lines) and the simulator's
// test line. Oracle: every rejection is the project's input error in the one form
// "<file>: <entry>: <reason>", no crash and no undefined behaviour (ASan+UBSan), and an
// accepted scenario is one the simulation models: times within the run (every train departs
// and every fault begins before the end, so nothing is silently dropped), positions within
// the line coordinate range (converted to mm without leaving the integers), the channel within
// its ranges, unique train ids other than the ground's, steps dividing the cycles.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "json_fuzz.hpp"
#include "railproof/core/units.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/sim/scenario.hpp"

namespace {

namespace sim = railproof::sim;
using railproof::fuzz::Require;

const std::string kFile = "scenario.json";

// The lines a scenario may name, by name.
const std::map<std::string, railproof::offline::Line>& Lines() {
  static const std::map<std::string, railproof::offline::Line> lines = [] {
    std::map<std::string, railproof::offline::Line> out;
    for (const char* dir : {RAILPROOF_FUZZ_LINES_DIR, RAILPROOF_FUZZ_TEST_LINES_DIR}) {
      for (const auto& e : std::filesystem::directory_iterator(dir)) {
        if (e.path().extension() == ".json" && e.path().stem().string().find("line") != std::string::npos) {
          railproof::offline::Line line = railproof::offline::LoadLine(e.path());
          out.emplace(line.name, std::move(line));
        }
      }
    }
    return out;
  }();
  return lines;
}

bool Finite(double v, double lo, double hi) { return std::isfinite(v) && lo <= v && v <= hi; }

void CheckAccepted(const sim::Scenario& sc) {
  constexpr std::int64_t kWeekMs = 7LL * 24 * 3600 * 1000;
  const std::int64_t max_mm = railproof::core::kMaxPositionMm;
  Require(sc.duration_ms >= sc.step_ms && sc.duration_ms <= kWeekMs, "duration of at least one step, at most a week");
  Require(sc.step_ms >= 1 && sc.step_ms <= 1000 && sc.ground_cycle_ms % sc.step_ms == 0 &&
              sc.report_period_ms % sc.step_ms == 0,
          "step dividing the cycles");
  Require(Finite(sc.handover_secure_ahead_m, 0.0, 1e7), "handover look-ahead within the line range");
  Require(Finite(sc.channel.loss_probability, 0.0, 1.0) && Finite(sc.channel.corrupt_probability, 0.0, 1.0) &&
              sc.channel.min_delay_ms >= 0 && sc.channel.min_delay_ms <= sc.channel.max_delay_ms &&
              sc.channel.max_delay_ms <= 60'000,
          "channel within its ranges");
  Require(!sc.trains.empty(), "a train");
  std::set<std::uint16_t> ids;
  for (const sim::TrainSpec& t : sc.trains) {
    Require(ids.insert(t.id).second && t.id != railproof::params::tg::ground_id, "unique train ids, not the ground's");
    Require(0 <= t.enter_ms && t.enter_ms <= t.depart_ms && t.depart_ms < sc.duration_ms,
            "every train enters, then departs before the end");
    Require(0 <= t.initial_front_mm && t.initial_front_mm <= max_mm, "initial front within the line range");
    const auto& p = t.performance;
    Require(Finite(p.length_m, 0.0, 2000.0) && p.length_m > 0.0 && Finite(p.max_speed_mps, 0.0, 400.0 / 3.6) &&
                Finite(p.accel_mps2, 0.0, 5.0) && Finite(p.emergency_decel_mps2, p.service_decel_mps2, 5.0) &&
                p.service_decel_mps2 > 0.0,
            "train performance within its ranges");
    Require(Finite(p.resistance.a0, 0.0, 100.0) && Finite(p.resistance.a1, 0.0, 10.0) && Finite(p.resistance.a2, 0.0, 1.0),
            "running resistance within its range");
    for (const sim::StopSpec& s : t.stops) {
      Require(0 <= s.dwell_ms && s.dwell_ms <= kWeekMs, "dwell within a week");
    }
  }
  for (const sim::FaultSpec& f : sc.faults) {
    Require(0 <= f.from_ms && f.from_ms < f.to_ms && f.from_ms < sc.duration_ms && f.to_ms <= kWeekMs,
            "every fault begins before the end and ends after it begins");
    Require(0 <= f.begin_mm && f.begin_mm <= f.end_mm && f.end_mm <= max_mm, "fault sections within the line range");
  }
  if (sc.gap) {
    Require(sc.gap->from_ms < sc.gap->to_ms && sc.gap->to_ms <= sc.duration_ms, "gap window within the run");
  }
  const auto line = Lines().find(sc.line);
  if (line != Lines().end()) {
    sim::CheckScenarioAgainstLine(sc, sim::SelectRunningLine(sc, line->second));
  }
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)Lines();  // loaded before the first input: their errors are not the scenario's
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { CheckAccepted(sim::ParseScenario(text, kFile)); });
}
