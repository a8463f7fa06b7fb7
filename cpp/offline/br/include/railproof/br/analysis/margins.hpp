// Offline worst-case braking-margin verification (spec/design/br.md §5; REQ-BR-009,
// REQ-BR-010, REQ-BR-011, REQ-BR-014, with REQ-BR-005, REQ-BR-007 and REQ-SC-005 as the
// model's inputs). For every stop-limit location of a running line and a train type: the
// minimum over the uncertainty set and the admissible states of
//     margin = L - (worst-case stopping point of the true front)          [mm]
// by (1) corner + grid enumeration over the REAL runtime patterns (br::PatternCalculator),
// (2) an Ipopt NLP on a continuous relaxation of the same supervision (margins_nlp.cpp) and
// (3) an OMPL falsifier with the runtime supervision in the loop (falsifier.hpp).
//
// ---- model (units mm, mm/s, mm/s^2, ms; doubles in the physics) --------------------------
// Position error  E = odometry_ppm * (longest balise spacing of the running line) / 1e6
//                 + readhesion_margin_mm. The supervision uses x_s = x_m + E; the true front
//                 is in [x_m - E, x_m + E], worst x_m + E = x_s.
// Speed error     true speed v with |v - v_m| <= dV(v), dV the D3 total-error bound of the
//                 reference speed-check design (br::analysis::SpeedErrorBoundMmS). A train type
//                 whose allowance does not cover dV is refused (REQ-SC-005).
// Admissible      a check (cycle start) at which the runtime did NOT command the emergency
//                 brake: SupervisedSpeed(v_m) <= EmergencyPatternSpeed(x_s, L, E, E); the
//                 standstill state (v_m = 0, standstill, v_s = 0) included. The true speed is
//                 capped at the train's maximum speed.
// Physics         the offline train-motion model (railproof/offline/dynamics.hpp) without
//                 running resistance, integrated exactly over the gradient pieces.
// Worst case      from the admissible check: traction accel_max for the rest of the cycle
//                 (phase), the next check commands the emergency brake, reaction_ms and the
//                 free-running time (still under traction), then the real emergency
//                 deceleration beta on the true gradient until standstill. Gravity uses the
//                 most falling gradient under the train (front - length, front] plus the
//                 adversary's data error dg in [-gradient_error_x10, +gradient_error_x10]
//                 (physics constant gravity_mm_s2, as the runtime).
// Monotonicity (why corners suffice in the grid; the NLP and the falsifier search the box):
//   - beta: the stop distance of each braking piece is w / (2 b), b = beta + grav > 0, so it
//     falls with beta: worst beta = emergency_deceleration min.
//   - free-running time, cycle phase: they lengthen the run-up; continuing the run-up
//     instead of braking never shortens the stop, because the run-up acceleration
//     accel_max - grav(G) exceeds the braking deceleration -(beta + grav(G)) at every
//     position: worst = max free running, full cycle.
//   - gradient error dg: it lowers the braking capability and raises the run-up acceleration
//     at every position: worst dg = -gradient_error_x10.
//   - position error: shifting the whole trajectory forward: worst true front = x_s.
//   - speed error and initial speed: in v^2 form (d v^2 / dx = 2 a(x)) trajectories starting
//     at the same position with a higher speed stay faster at every position (a(x) depends on
//     position only), reach each position earlier and brake later: worst true speed = the
//     largest v with v - dV(v) <= v_m.
//   - traction: more traction, more acceleration: worst full traction.
//   The check position x_s and the pattern speed there are NOT monotone (gradients,
//   restrictions, integer patterns): the grid enumerates x_s at `resolution_mm`.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <tuple>
#include <string>
#include <utility>
#include <vector>

#include "railproof/br/analysis/speedcheck_design.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/br/patterns.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::br::analysis {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// Stop-limit location classes (D5 §5.1.4, REQ-BR-009).
// @implements REQ-BR-009 REQ-BR-011
enum class LocationClass : std::uint8_t {
  kPrecedingTrain,
  kPlatform,
  kRouteEnd,
  kHandover,
  kSystemBoundary,
  kPossession,
  kLevelCrossing,
  kEndOfTrack,
};
inline constexpr int kLocationClassCount = 8;

const char* ToString(LocationClass c) noexcept;

// One stop limit L = obstruction - class margin on a running line.
struct Location {
  LocationClass cls = LocationClass::kPlatform;
  std::string id;
  std::int64_t obstruction_mm = 0;
  std::int64_t class_margin_mm = 0;
  std::int64_t stop_limit_mm = 0;
};

struct LocationSet {
  std::vector<Location> analysed;
  std::vector<Location> skipped;  // too close to the line start for a full approach
};

// Every stop-limit location of the running line (design note §5); possession start and
// preceding-train rear at every virtual-block boundary and at every gradient and speed-limit
// change (and +- train length). Locations with L < min_approach_mm are skipped.
// @implements REQ-BR-009 REQ-BR-011
LocationSet EnumerateLocations(const offline::RunningLine& rl, std::int64_t train_length_mm,
                               std::int64_t min_approach_mm);

// Speed error of the uncertainty set: dV(v) of a speed-check design, with a linear upper
// envelope dV(v) <= c0 + c1 v (used by the NLP).
struct SpeedErrorModel {
  SpeedCheckDesign design;
  double c0_mm_s = 0.0;
  double c1 = 0.0;
  [[nodiscard]] std::int64_t Bound(std::int64_t true_speed_mm_s) const;
};

// The reference design (D3, spec/parameters/sc.yaml) at its optimum.
SpeedErrorModel ReferenceSpeedErrorModel();

// REQ-SC-005: "" if the train's allowance covers dV up to its maximum speed, else the reason.
// @implements REQ-SC-005 REQ-BR-007
std::string SpeedAllowanceFinding(const TrainType& t, const SpeedErrorModel& m);

// A point of the uncertainty box (the adversary's choice).
struct Adversary {
  double beta_mm_s2 = 0.0;           // real emergency deceleration
  double free_running_ms = 0.0;      // real emergency free-running time
  double gradient_error_x10 = 0.0;   // added to the data gradient (negative: more falling)
  double runup_cycle_ms = 0.0;       // part of the cycle run before the detecting check
  double traction = 1.0;             // fraction of accel_max
  double position_error_mm = 0.0;    // true front = x_m + this (in [-E, E])
  double speed_error_sign = 1.0;     // true speed = v_m + sign * dV (grid: +1)
};

// Result of the exact piecewise physics from a check.
struct Trajectory {
  double check_front_mm = 0.0;     // x_s (supervised front at the admissible check)
  std::int64_t measured_speed_mm_s = 0;
  std::int64_t supervised_speed_mm_s = 0;
  std::int64_t pattern_speed_mm_s = 0;  // runtime V_e(x_s) (-1: not evaluated)
  double true_front_mm = 0.0;
  double true_speed_mm_s = 0.0;
  double brake_front_mm = 0.0;     // where the real brake effort starts
  double brake_speed_mm_s = 0.0;
  double stop_mm = 0.0;
  double run_up_ms = 0.0;
  bool standstill_start = false;
  Adversary adversary;
  std::vector<std::pair<double, double>> points;  // (true front mm, speed mm/s)
};

struct ModelOptions {
  std::int64_t resolution_mm = 1000;  // grid step of the check position
};

// One running line x one train type: runtime patterns, profile, uncertainty set.
class MarginModel {
 public:
  MarginModel(const offline::RunningLine& rl, const TrainType& train, const SpeedErrorModel& speed_error);
  MarginModel(const MarginModel&) = delete;
  MarginModel& operator=(const MarginModel&) = delete;

  [[nodiscard]] const offline::RunningLine& running_line() const { return *rl_; }
  [[nodiscard]] const TrainType& train() const { return train_; }
  [[nodiscard]] const SpeedErrorModel& speed_error() const { return speed_error_; }
  [[nodiscard]] const br::PatternCalculator& patterns() const { return *calc_; }
  [[nodiscard]] const br::SupervisionParams& params() const { return params_; }
  [[nodiscard]] std::int64_t position_error_mm() const { return position_error_mm_; }
  [[nodiscard]] std::int64_t longest_balise_spacing_mm() const { return balise_spacing_mm_; }
  // Approach length: no admissible state farther than this before L can reach L.
  [[nodiscard]] std::int64_t approach_mm() const { return approach_mm_; }
  [[nodiscard]] std::int64_t train_max_speed_mm_s() const { return train_.MaxSpeedMmS(); }

  // Most falling data gradient under the train with the front at x: (x - length, x].
  [[nodiscard]] double GradientUnderTrain(double front_mm) const;
  // The piecewise-constant function above: piece starts (first = -inf sentinel) and values.
  [[nodiscard]] const std::vector<double>& piece_start() const { return piece_start_; }
  [[nodiscard]] const std::vector<std::int64_t>& piece_gradient() const { return piece_g_; }
  // Line ceiling of the emergency pattern at supervised front y (restriction + overspeed),
  // the runtime's ceiling semantics (REQ-BR-004); +inf (max_speed) outside restrictions.
  [[nodiscard]] double EmergencyCeilingMmS(double y) const;

  // The worst corner of the uncertainty box (see the header comment).
  [[nodiscard]] Adversary WorstCorner() const;
  // Largest true speed with v - dV(v) <= v_m, capped at the train's maximum speed.
  [[nodiscard]] double TrueSpeedMax(std::int64_t v_m) const;
  // Largest v_m (>= 1) with SupervisedSpeed(v_m) <= v_e; nullopt if none.
  [[nodiscard]] std::optional<std::int64_t> MaxMeasuredSpeed(std::int64_t v_e) const;

  // Exact piecewise physics: run-up (traction, gradient) for runup_cycle + reaction + free
  // running, then braking with beta until standstill. Returns the trajectory (points if asked).
  [[nodiscard]] Trajectory Simulate(double true_front_mm, double true_speed_mm_s, const Adversary& adv,
                                    bool keep_points) const;
  // The gravity of the physics (mm/s^2): the runtime's (gravity_mm_s2).
  [[nodiscard]] double Gravity() const;
  // Deceleration by gravity on gradient piece `piece` (piece_gradient) with the adversary's
  // gradient error (mm/s^2; negative on a falling gradient).
  [[nodiscard]] double Grade(std::size_t piece, const Adversary& adv) const;

 private:
  const offline::RunningLine* rl_;
  TrainType train_;
  SpeedErrorModel speed_error_;
  br::SupervisionParams params_{};
  std::optional<br::PatternCalculator> calc_;
  std::vector<br::RestrictionSegment> restrictions_;
  std::vector<double> piece_start_;
  std::vector<std::int64_t> piece_g_;
  std::int64_t position_error_mm_ = 0;
  std::int64_t balise_spacing_mm_ = 0;
  std::int64_t approach_mm_ = 0;
};

// Corner + grid over the runtime's integer patterns (method "grid").
struct GridResult {
  double margin_mm = 0.0;            // L - worst stop (all admissible states)
  Trajectory worst;
  // the two kinds of admissible state separately: moving (v_m > 0) and the restart from a
  // standstill (v_m = 0, v_s = 0 <= V_e), which the runtime admits wherever V_e = 0
  double moving_margin_mm = 0.0;
  double standstill_margin_mm = 0.0;
  Trajectory worst_moving;
  std::int64_t checks = 0;           // check positions evaluated
  // local minima of the margin over the check position (x_s, v_m, margin), worst first
  std::vector<std::tuple<double, std::int64_t, double>> minima;
};
// @implements REQ-BR-009 REQ-BR-011 REQ-BR-014
GridResult GridWorstCase(const MarginModel& m, const Location& loc, std::int64_t resolution_mm);

// ---- Ipopt NLP (margins_nlp.cpp) ---------------------------------------------------------
struct NlpOptions {
  int run_up_intervals = 20;       // collocation intervals of the run-up (time state)
  int braking_intervals = 4;       // intervals of the braking phase
  double smoothing_mm = 200.0;     // width of the logistic smoothing of gradient steps
  int print_level = 0;
  std::string output_file;         // Ipopt output file (derivative checker)
  bool derivative_test = false;    // derivative_test = second-order
  double derivative_test_perturbation = 1e-8;
  int max_iter = 300;
};

struct NlpResult {
  bool solved = false;
  std::string status;
  int iterations = 0;
  double objective_m = 0.0;        // NLP objective (x_stop - L in m, continuous model)
  double margin_mm = 0.0;          // exact physics from the NLP's worst state (L - stop)
  bool runtime_admissible = false; // the runtime supervision admits the NLP's worst state
  Trajectory worst;
  double wall_s = 0.0;
};

struct NlpSeed {
  double check_front_mm = 0.0;  // x_s
  double measured_speed_mm_s = 0.0;
};

// Maximises the stopping point by Ipopt from each seed; returns the best solution.
// @implements REQ-BR-009 REQ-BR-014 REQ-BR-005 REQ-BR-007
NlpResult NlpWorstCase(const MarginModel& m, const Location& loc, const std::vector<NlpSeed>& seeds,
                       const NlpOptions& opt = {});

// Grid search over the NLP's continuous model (same relaxation, smoothing and collocation)
// at check-position step `step_mm` with the uncertain parameters at their worst corners;
// `params_per_axis` > 1 also grids the six uncertain parameters (no monotonicity assumed).
// Used to compare the cost of the NLP with a grid of equal accuracy (--compare-methods).
struct ContinuousGridResult {
  double objective_m = 0.0;  // max over the grid of x_stop - L (m)
  std::int64_t evaluations = 0;
  double wall_s = 0.0;
};
ContinuousGridResult ContinuousGridWorstCase(const MarginModel& m, const Location& loc, double step_mm,
                                             int params_per_axis, const NlpOptions& opt = {});

}  // namespace railproof::br::analysis
