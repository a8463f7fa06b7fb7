// OMPL kinodynamic falsifier of the braking supervision (spec/design/br.md §5, method 3):
// searches (ompl::control::KPIECE1) for an adversarial run inside the uncertainty envelope that
// takes the true front beyond the stop limit L, with the REAL runtime supervision in the loop
// every cycle (br::PatternCalculator::Evaluate + br::Supervisor::Step).
//
// State (per cycle boundary): true front x (m, relative to L), true speed v (m/s), time
// since the emergency command (s, -1: none). Control (held for whole cycles): traction
// fraction [0, 1], speed-measurement error [-1, 1] x dV(v), real emergency deceleration
// [min, max], free-running time [min, max], gradient data error [-ge, +ge], position error
// [-E, E] (true front = estimate + error), stale stop limit: the supervision still uses an
// older, shorter limit L - stale (stale in [0, 100 m]; a stop limit is only ever extended).
// Goal: x > 0. A violation is written as a regression case (JSON, ReplayCase re-runs it).
//
// Offline module.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/br/analysis/margins.hpp"

namespace railproof::br::analysis {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// One adversary control, held for `cycles` supervision cycles.
struct AdversaryStep {
  int cycles = 1;
  double traction = 1.0;
  double speed_error = 0.0;         // fraction of dV(v): measured = true - this * dV
  double beta_mm_s2 = 0.0;
  double free_running_ms = 0.0;
  double gradient_error_x10 = 0.0;  // added to the data gradient
  double position_error_mm = 0.0;   // true front = estimated front + this
  double stale_mm = 0.0;            // supervised limit = L - stale
};

struct FalsifierOptions {
  double budget_s = 1.0;
  std::uint32_t seed = 1;
  // true (design note §5): a measured speed of zero sets the runtime's standstill input
  // (v_s = 0), so a standing - or creeping below dV - train may restart where V_e = 0.
  // false: the standstill input is never set (judges the moving states only).
  bool admit_standstill_restart = true;
};

struct FalsifierResult {
  bool violation = false;
  double max_overrun_mm = 0.0;  // largest x - L reached by the best path found (<= 0 if safe)
  double wall_s = 0.0;
  std::uint64_t propagations = 0;
  nlohmann::ordered_json regression_case;  // set when violation
};

// Searches for a violation at one location within the time budget.
// @implements REQ-BR-009 REQ-BR-014
FalsifierResult Falsify(const MarginModel& m, const Location& loc, const std::string& line_name,
                        const FalsifierOptions& opt);

// Re-runs a regression case with the runtime supervision for a train type (controls
// clamped into that train's envelope). Returns the largest x - L (mm) reached; > 0 means
// the front passed the stop limit. Throws offline::InputError on a malformed case.
struct ReplayResult {
  double max_overrun_mm = 0.0;
  bool emergency_commanded = false;
  int cycles = 0;
};
// @implements REQ-BR-009 REQ-BR-014
ReplayResult ReplayCase(const nlohmann::json& regression_case, const TrainType& train, const std::string& file,
                        bool admit_standstill_restart = true);

}  // namespace railproof::br::analysis
