// D2's headway-minimising follower control (spec/design/fc.md): the safety buffers and the
// speed-limit start position (D2 §3.1), the corridor a train runs along (speed limits with
// buffered start and end, gradients, braking curves), the approach point as a one-variable
// optimisation (Ipopt, cross-checked on a grid), the optimal outside-station stop, the
// per-section trajectories with two parameters and the slowing rule, and the simulation of a
// leader and a follower under the controlled policy and the two baselines (moving block at
// maximum speed to the furthest permitted point; fixed-block operation).
//
// SI units (m, s, m/s). The train motion is the one offline model (offline/dynamics.hpp),
// stepped every time_step_ms. Offline module (may allocate and throw).
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "railproof/br/supervisor.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/train_type.hpp"

namespace railproof::fc {

// ---- buffers (D2 §3.1) ------------------------------------------------------------------

struct BufferParams {
  double rate = 0.001;  // r, odometry error per distance since the last balise
  double tau_s = 0.5;   // τ, radio delay
  double lc_m = 2.0;    // l_c, resolution margin
};

// r from the train type (odometry_ppm), τ and l_c from spec/parameters/fc.yaml.
// @implements REQ-FC-001
BufferParams MakeBufferParams(const offline::TrainType& train);

// The last position-correction balise at or before x (balises sorted), or the line start (0)
// when none: x_m of D2 §3.1.
double LastBalise(const std::vector<double>& balises_m, double x);

// l_f(x, v) = r (x - x_m) + v τ + l_c and l_r(x) = r (x - x_m) + l_c.
// @implements REQ-FC-001
double FrontBuffer(const BufferParams& b, double x, double v, double x_m);
// @implements REQ-FC-001
double RearBuffer(const BufferParams& b, double x, double x_m);

// The front position at which a speed limit starting at x_s takes effect for a train at speed
// v: x = (x_s - (v τ + l_c) + r x_m^i) / (1 + r), the largest over the balises i before x_s
// whose x_m^i lies at or before that x (the balise the train has last passed there); the line
// start if there is none.
// @implements REQ-FC-002
double LimitStartFront(const BufferParams& b, double x_s, double v, const std::vector<double>& balises_m);
// The front position at which a limit ending at x_e is released: the buffered rear
// x - length - l_r(x) reaches x_e, x = (x_e + length + l_c - r x_m^i) / (1 - r) with the
// balise the train has last passed there (the latest balise at or before that x).
// @implements REQ-FC-002
double LimitEndFront(const BufferParams& b, double x_e, double length_m, const std::vector<double>& balises_m);

// ---- the train and the corridor -------------------------------------------------------

// D2's three cases (D2 §4).
enum class Case { kLevelNoLimits, kSpeedLimits, kGradients };
const char* CaseName(Case c);

struct Train {
  offline::TrainPerformance perf;  // the dynamics' train: traction, resistance, decelerations
  double beta = 0.0;               // β: service maximum deceleration (speed-independent)
  BufferParams buffers;
};

// The D2 10-car EMU from its train type (length, maximum speed, accel_max, β = service
// pattern deceleration) with the D2 consist's resistance and constant-power traction
// (ASM-032, spec/parameters/fc.yaml).
// @implements REQ-FC-003
Train MakeD2Train(const offline::TrainType& type);

// The part [from_m, to_m] of one running line as a train of the given type sees it in one case,
// sampled every kGridM: the speed limit acting on the train (buffered start and release,
// REQ-FC-002; the train's maximum speed where the case has no limits), the mean gradient
// under the train (level where the case has no gradients), the braking integral
// E(x) = ∫ (β + g G / 1000) and the static ceiling (limits and the braking curves to every
// lower limit ahead).
class Corridor {
 public:
  static constexpr double kGridM = 0.25;

  Corridor(const offline::RunningLine& rl, double from_m, double to_m, const Train& train, Case c);

  [[nodiscard]] double from() const { return from_; }
  [[nodiscard]] double to() const { return to_; }
  [[nodiscard]] const std::vector<double>& balises() const { return balises_; }
  [[nodiscard]] const Train& train() const { return train_; }

  [[nodiscard]] double Gradient(double x) const;       // per mille, mean under the train
  [[nodiscard]] double Limit(double x) const;          // m/s, acting on a front at x
  [[nodiscard]] double StaticCeiling(double x) const;  // m/s
  [[nodiscard]] double BrakeIntegral(double x) const;  // E(x), m^2/s^2 / 2
  // Highest speed at x from which braking at β (on the corridor's gradients) reaches `target`
  // at no more than v_end: sqrt(v_end^2 + 2 (E(target) - E(x))); +inf beyond the target is 0.
  [[nodiscard]] double CurveTo(double x, double target, double v_end = 0.0) const;
  // Highest speed at x whose buffered front x + l_f(x, v) can still stop at the stop limit:
  // D2's v_max = sqrt(2 d β) with d measured from the buffered front (bisection).
  // @implements REQ-FC-003
  [[nodiscard]] double SafeSpeed(double x, double stop_limit) const;
  // The line speed limits' section boundaries (front positions where Limit changes) in
  // (a, b), sorted.
  [[nodiscard]] std::vector<double> LimitChanges(double a, double b) const;

 private:
  [[nodiscard]] double Sample(const std::vector<double>& v, double x) const;

  Train train_;
  double from_ = 0.0, to_ = 0.0;
  std::vector<double> balises_;
  std::vector<double> gradient_, limit_, ceiling_, brake_;
};

// ---- stepping ---------------------------------------------------------------------------

struct State {
  double t = 0.0;
  double x = 0.0;
  double v = 0.0;
};

// The ceilings one step must respect (every one a speed at a front position).
using Ceiling = std::function<bool(double x, double v)>;

// One step of dt under the net demand u (> 0 traction, < 0 braking deceleration).
State StepTrain(const Corridor& c, const State& s, double u, double dt);
// The highest demand u <= u_wanted whose next state stays within `ok` (bisection down to
// -β; full braking if none does): the safety layer of every policy.
double ChooseDemand(const Corridor& c, const State& s, double u_wanted, double dt, const Ceiling& ok);

// ---- approach point, outside stop (D2 §3.2) ----------------------------------------------

struct ApproachProblem {
  const Corridor* corridor = nullptr;
  double entry = 0.0;  // platform (fixed block) entry: the stop limit until the route clears
  double stop = 0.0;   // stop point in the platform
};

// The point on the braking curve to the entry (buffered front) where a train at speed v is.
double ApproachPosition(const ApproachProblem& p, double v);
// Fastest time from (ApproachPosition(v), v) to a stop at the stop point once the route is
// clear (full traction within the static ceiling, braking at β), integrated on 4000 nodes of
// position so that it is a smooth function of v.
double TimeFromApproach(const ApproachProblem& p, double v);

struct ApproachPoint {
  double x = 0.0, v = 0.0, time_s = 0.0;  // the optimum (Ipopt)
  double grid_v = 0.0, grid_time_s = 0.0;  // the grid's best
  std::string status;                      // Ipopt's, as text
  bool solved = false;                     // Ipopt solved it (or to the acceptable level)
  int iterations = 0;
};

// Minimises TimeFromApproach over v in (1 m/s, ceiling at the entry] with Ipopt and on a grid
// of grid_step_mps.
// @implements REQ-FC-004
ApproachPoint FindApproachPoint(const ApproachProblem& p, double grid_step_mps);

struct OutsideStop {
  double x = 0.0;           // stop position
  double time_to_approach_s = 0.0;  // full acceleration from it to the approach point
};

// The nearest stop position from which full acceleration alone reaches the approach point at
// its speed (bisection on the position).
// @implements REQ-FC-006
OutsideStop FindOutsideStop(const Corridor& c, const ApproachPoint& a);

// ---- per-section trajectories (D2 §3.3) -------------------------------------------------

// Per section (between speed-limit changes): accelerate (or brake, when faster) to the
// coast-start speed, cruise for the cruise duration, coast; braking comes from the ceilings. A section entered while coasting
// at or above its coast-start speed goes on coasting (the sections merge).
struct SectionPlan {
  double begin = 0.0;
  double coast_speed = 0.0;    // coast-start speed
  double cruise_s = 0.0;       // cruise duration
};

struct Plan {
  std::vector<SectionPlan> sections;
  double target_x = 0.0;  // the plan ends at target_x
  double target_v = 0.0;  // passed at no more than this speed
};

// Executes a plan one step at a time (keeps the section, its phase and its cruise time).
class PlanExecutor {
 public:
  PlanExecutor() = default;
  explicit PlanExecutor(Plan plan) : plan_(std::move(plan)) {}
  // The demand the plan wants in this step (before any ceiling).
  double Wanted(const Corridor& c, const State& s, double dt);
  // After the step: cruise time passes while the plan governs; a ceiling that cuts the cruise
  // (a braking curve) ends it.
  void Record(double dt, bool cut);
  [[nodiscard]] const Plan& plan() const { return plan_; }
  [[nodiscard]] double cruised(std::size_t section) const {
    return section < cruised_.size() ? cruised_[section] : 0.0;
  }
  // The plan's own ceiling: the braking curve to its target.
  [[nodiscard]] bool Within(const Corridor& c, double x, double v) const;

 private:
  enum class Phase { kAccelerate, kCruise, kCoast };
  Plan plan_;
  std::size_t section_ = 0;
  Phase phase_ = Phase::kAccelerate;
  std::vector<double> cruised_;
  bool started_ = false;
};

// Running time of a plan from a state to its target (+inf if it stops before, or after
// limit_s).
double PlanTime(const Corridor& c, const State& from, const Plan& plan, double dt, double limit_s = 600.0);

// The fastest plan from a state to (target_x, target_v): every coast-start speed the section's
// limit, every cruise as long as the braking curves allow.
Plan FastestPlan(const Corridor& c, const State& from, double target_x, double target_v, double dt);

// The slowing rule: the fastest plan slowed by lambda in [0, 2]: lambda <= 1 shortens every
// cruise to (1 - lambda) of the fastest's, then lambda - 1 lowers every coast-start speed
// towards 5 % of the section's limit.
Plan SlowedPlan(const Plan& fastest, const Corridor& c, double lambda);

struct SlowedResult {
  Plan plan;
  double lambda = 0.0;
  double time_s = 0.0;  // the plan's running time
};

// The plan from `from` reaching (target_x, target_v) after `required_s` (bisection on the
// slowing parameter); the fastest when even that is late, the slowest when even that is early.
// @implements REQ-FC-007
SlowedResult SlowToRunningTime(const Corridor& c, const State& from, double target_x, double target_v,
                               double required_s, double dt);

// ---- supervision (the on-board safety layer) -------------------------------------------------

// The command the train applies: the follower control's demand unless the on-board supervision
// commands a brake, which always wins (no traction with any brake level; 4N..7N a growing
// part of β, 7N β itself; EB the emergency brake).
// @implements REQ-FC-010
offline::Control ApplySupervision(double follower_demand, const br::Decision& decision, const Train& train);

// ---- the simulation of a leader and a follower (D2 §4) -------------------------------------

enum class Policy { kMovingBlockBaseline, kFixedBlockBaseline, kControlled };
const char* PolicyName(Policy p);

struct Scenario {
  const Corridor* corridor = nullptr;
  double origin_stop = 0.0;   // the stop both trains start from
  double station_entry = 0.0, station_end = 0.0, station_stop = 0.0;  // the studied platform
  double next_stop = 0.0;     // where the leader goes after it
  double leader_depart = 0.0;         // from the origin (s)
  double follower_depart = 0.0;       // from the origin (s)
  double leader_planned_departure = 0.0;  // from the studied station (s)
  double leader_delay = 0.0;          // leader departs the station this late
  std::vector<double> fixed_blocks;   // block boundaries of the fixed-block baseline
  double fixed_block_overlap = 0.0;
  double dt = 0.02, horizon = 300.0;
  ApproachPoint approach;
  OutsideStop outside;
};

struct Run {
  std::vector<State> leader, follower;  // every step
  double leader_departure = 0.0;        // from the studied station
  double route_clear = 0.0;             // leader's buffered rear past the platform end
  std::optional<double> follower_arrival;  // stopped at the station's stop point
  std::optional<double> approach_passed;   // follower front at the approach point (controlled)
  double approach_passed_speed = 0.0;
  bool stopped_outside = false;            // controlled: stopped at the outside stop
  // the largest excess over the ceilings the follower showed (speed limit and braking curve to
  // its stop limit), m/s; 0 when they held at every step
  double worst_excess = 0.0;
};

// The fastest run time from a stop to the next stop (standing start, full traction within the
// static ceiling, braking at β to the stop).
double FastestRunTime(const Corridor& c, double from_stop, double to_stop, double dt);

// The fixed-block boundaries between two stops: the platforms, and blocks of `length` laid back
// from each platform entry.
std::vector<double> FixedBlocks(const offline::RunningLine& rl, double from_m, double to_m, double length);

// @implements REQ-FC-005 REQ-FC-006 REQ-FC-008
Run Simulate(const Scenario& sc, Policy policy);

}  // namespace railproof::fc
