// OMPL falsifier with the runtime supervision in the loop (falsifier.hpp).
#include "railproof/br/analysis/falsifier.hpp"

#include <ompl/base/goals/GoalRegion.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/control/PathControl.h>
#include <ompl/control/SimpleSetup.h>
#include <ompl/control/planners/kpiece/KPIECE1.h>
#include <ompl/control/spaces/RealVectorControlSpace.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <utility>

#include "railproof/br/supervisor.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::br::analysis {

namespace {

namespace ob = ompl::base;
namespace oc = ompl::control;

constexpr double kStaleMaxMm = 100000.0;
constexpr int kControlDims = 7;

// What one cycle needs: the runtime patterns, the physics profile, the envelope.
struct Env {
  const MarginModel* m = nullptr;
  std::int64_t e_mm = 0;     // position error bound E of this train on this line
  std::int64_t l_mm = 0;     // stop limit
  bool standstill = true;    // the standstill input may be set (FalsifierOptions)
};

struct SimState {
  double x_mm = 0.0;
  double v_mm_s = 0.0;
  double eb_s = -1.0;  // time since the emergency command, -1: not commanded
};

AdversaryStep Clamp(const Env& env, AdversaryStep c) {
  const TrainType& t = env.m->train();
  const double ge = static_cast<double>(env.m->params().gradient_error_x10);
  const double e = static_cast<double>(env.e_mm);
  c.traction = std::clamp(c.traction, 0.0, 1.0);
  c.speed_error = std::clamp(c.speed_error, -1.0, 1.0);
  c.beta_mm_s2 = std::clamp(c.beta_mm_s2, static_cast<double>(t.emergency_deceleration_mm_s2.min),
                            static_cast<double>(t.emergency_deceleration_mm_s2.max));
  c.free_running_ms = std::clamp(c.free_running_ms, static_cast<double>(t.emergency_free_running_ms.min),
                                 static_cast<double>(t.emergency_free_running_ms.max));
  c.gradient_error_x10 = std::clamp(c.gradient_error_x10, -ge, ge);
  c.position_error_mm = std::clamp(c.position_error_mm, -e, e);
  c.stale_mm = std::clamp(c.stale_mm, 0.0, kStaleMaxMm);
  return c;
}

// One supervision cycle: the check at its start (runtime Evaluate + Supervisor::Step), then
// cycle_ms of physics (traction until reaction + free running after the command, then the
// real emergency deceleration), integrated in 10 ms steps split at the brake onset.
// @implements REQ-BR-001 REQ-BR-014
void Cycle(const Env& env, SimState& s, const AdversaryStep& c) {
  const MarginModel& m = *env.m;
  const auto& pr = m.params();
  if (s.eb_s < 0.0) {
    const double dv = static_cast<double>(m.speed_error().Bound(static_cast<std::int64_t>(std::ceil(s.v_mm_s))));
    const auto vm = static_cast<std::int64_t>(std::max(0.0, std::floor(s.v_mm_s - c.speed_error * dv)));
    br::PositionEstimate pe;
    pe.front_mm = static_cast<std::int64_t>(std::floor(s.x_mm - c.position_error_mm));
    pe.front_error_mm = env.e_mm;
    pe.rear_error_mm = env.e_mm;
    pe.speed_mm_s = vm;
    pe.standstill = env.standstill && vm == 0;
    const auto limit = env.l_mm - static_cast<std::int64_t>(std::floor(c.stale_mm));
    const br::Evaluation ev = m.patterns().Evaluate(pe, limit);
    br::Supervisor sup;  // not latched before the first command (the state that matters)
    const br::Decision d = sup.Step(ev.speeds, br::DriverInputs{});
    if (d.level == br::BrakeLevel::kEmergency) {
      s.eb_s = 0.0;
    }
  }
  const double onset = (static_cast<double>(pr.reaction_ms) + c.free_running_ms) / 1000.0;
  const double amax = static_cast<double>(m.train().accel_max_mm_s2) * c.traction;
  double left = static_cast<double>(pr.cycle_ms) / 1000.0;
  while (left > 1e-12) {
    double dt = std::min(0.01, left);
    const bool braking_now = s.eb_s >= 0.0 && s.eb_s >= onset - 1e-12;
    if (s.eb_s >= 0.0 && !braking_now) {
      dt = std::min(dt, onset - s.eb_s);
    }
    const double grade = GradeDecel((m.GradientUnderTrain(s.x_mm) + c.gradient_error_x10) / 10.0, m.Gravity());
    const double a = braking_now ? -(c.beta_mm_s2 + grade) : amax - grade;
    // the offline train-motion model: a train that stops stands (the brake holds; traction
    // cannot hold it on a rise: no roll-back)
    const Motion next = Advance({s.x_mm, s.v_mm_s}, a, dt);
    s.x_mm = next.position;
    s.v_mm_s = next.speed;
    if (s.eb_s >= 0.0) {
      s.eb_s += dt;
    }
    left -= dt;
  }
}

class BeyondLimit : public ob::GoalRegion {
 public:
  explicit BeyondLimit(const ob::SpaceInformationPtr& si) : ob::GoalRegion(si) { setThreshold(0.0); }
  double distanceGoal(const ob::State* st) const override {
    const double x = st->as<ob::RealVectorStateSpace::StateType>()->values[0];
    return x > 0.0 ? 0.0 : -x + 1e-9;
  }
};

// Control sampler biased to the adversarial end of the envelope: each component takes its
// worst-case bound with probability 3/4 (full traction, speed read low, weakest brake,
// longest free running, most falling gradient error, front ahead of the estimate, fresh
// limit) and a uniform value otherwise, so runs that combine several worst cases over many
// cycles are sampled often enough to be found within a short budget.
class AdversarialControlSampler : public oc::ControlSampler {
 public:
  AdversarialControlSampler(const oc::ControlSpace* space, std::vector<double> worst)
      : oc::ControlSampler(space), worst_(std::move(worst)) {}
  void sample(oc::Control* control) override {
    const auto* cs = space_->as<oc::RealVectorControlSpace>();
    const auto& b = cs->getBounds();
    double* u = control->as<oc::RealVectorControlSpace::ControlType>()->values;
    for (std::size_t i = 0; i < worst_.size(); ++i) {
      u[i] = rng_.uniform01() < 0.75 ? worst_[i] : rng_.uniformReal(b.low[i], b.high[i]);
    }
  }

 private:
  std::vector<double> worst_;
};

// The adversary's controls, in the order of the control vector: the key of each in a
// regression case and its member of AdversaryStep.
constexpr std::array<std::pair<const char*, double AdversaryStep::*>, kControlDims> kControls{{
    {"traction", &AdversaryStep::traction},
    {"speed_error", &AdversaryStep::speed_error},
    {"beta_mm_s2", &AdversaryStep::beta_mm_s2},
    {"free_running_ms", &AdversaryStep::free_running_ms},
    {"gradient_error_x10", &AdversaryStep::gradient_error_x10},
    {"position_error_mm", &AdversaryStep::position_error_mm},
    {"stale_mm", &AdversaryStep::stale_mm},
}};

AdversaryStep FromControl(const oc::Control* ctl) {
  const double* u = ctl->as<oc::RealVectorControlSpace::ControlType>()->values;
  AdversaryStep c;
  for (std::size_t i = 0; i < kControls.size(); ++i) {
    c.*kControls[i].second = u[i];
  }
  return c;
}

nlohmann::ordered_json StepJson(const AdversaryStep& c) {
  nlohmann::ordered_json j{{"cycles", c.cycles}};
  for (const auto& [key, member] : kControls) {
    j[key] = c.*member;
  }
  return j;
}

// The step of a regression case (the inverse of StepJson).
AdversaryStep StepFromJson(const offline::JsonNode& st) {
  AdversaryStep c;
  c.cycles = static_cast<int>(st.Key("cycles").Int());
  for (const auto& [key, member] : kControls) {
    c.*member = st.Key(key).Number();
  }
  return c;
}

std::mutex& OmplMutex() {
  static std::mutex mu;
  return mu;
}

}  // namespace

// @implements REQ-BR-009 REQ-BR-014
FalsifierResult Falsify(const MarginModel& m, const Location& loc, const std::string& line_name,
                        const FalsifierOptions& opt) {
  std::lock_guard<std::mutex> lock(OmplMutex());  // the global seed makes runs deterministic only serially
  const auto t0 = std::chrono::steady_clock::now();
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  ompl::RNG::setSeed(opt.seed);
  Env env{&m, m.position_error_mm(), loc.stop_limit_mm, opt.admit_standstill_restart};
  const TrainType& t = m.train();
  const double d_m = static_cast<double>(m.approach_mm()) / 1000.0;

  auto space = std::make_shared<ob::RealVectorStateSpace>(3);
  ob::RealVectorBounds sb(3);
  sb.setLow(0, -d_m - 300.0);
  sb.setHigh(0, 300.0);
  sb.setLow(1, 0.0);
  sb.setHigh(1, 100.0);
  sb.setLow(2, -1.0);
  sb.setHigh(2, 1000.0);
  space->setBounds(sb);
  auto cspace = std::make_shared<oc::RealVectorControlSpace>(space, kControlDims);
  ob::RealVectorBounds cb(kControlDims);
  const double ge = static_cast<double>(m.params().gradient_error_x10);
  const double e = static_cast<double>(env.e_mm);
  const double lo[kControlDims] = {0.0, -1.0, static_cast<double>(t.emergency_deceleration_mm_s2.min),
                                   static_cast<double>(t.emergency_free_running_ms.min), -ge, -e, 0.0};
  const double hi[kControlDims] = {1.0, 1.0, static_cast<double>(t.emergency_deceleration_mm_s2.max),
                                   static_cast<double>(t.emergency_free_running_ms.max), ge, e, kStaleMaxMm};
  for (int i = 0; i < kControlDims; ++i) {
    cb.setLow(static_cast<unsigned>(i), lo[i]);
    cb.setHigh(static_cast<unsigned>(i), hi[i]);
  }
  cspace->setBounds(cb);
  const std::vector<double> worst = {1.0, 1.0, lo[2], hi[3], -ge, e, 0.0};
  cspace->setControlSamplerAllocator([worst](const oc::ControlSpace* sp) -> oc::ControlSamplerPtr {
    return std::make_shared<AdversarialControlSampler>(sp, worst);
  });
  oc::SimpleSetup ss(cspace);
  auto si = ss.getSpaceInformation();
  const double cycle_s = static_cast<double>(m.params().cycle_ms) / 1000.0;
  si->setPropagationStepSize(cycle_s);
  si->setMinMaxControlDuration(1, 25);
  FalsifierResult res;
  res.max_overrun_mm = -std::numeric_limits<double>::infinity();
  const double l = static_cast<double>(loc.stop_limit_mm);
  ss.setStateValidityChecker([space](const ob::State* st) { return space->satisfiesBounds(st); });
  ss.setStatePropagator([&](const ob::State* from, const oc::Control* ctl, double duration, ob::State* to) {
    const double* f = from->as<ob::RealVectorStateSpace::StateType>()->values;
    SimState s{l + f[0] * 1000.0, f[1] * 1000.0, f[2] < 0.0 ? -1.0 : f[2]};
    const AdversaryStep c = FromControl(ctl);
    const int cycles = std::max(1, static_cast<int>(std::lround(duration / cycle_s)));
    for (int k = 0; k < cycles; ++k) {
      Cycle(env, s, c);
    }
    ++res.propagations;
    res.max_overrun_mm = std::max(res.max_overrun_mm, s.x_mm - l);
    double* o = to->as<ob::RealVectorStateSpace::StateType>()->values;
    o[0] = (s.x_mm - l) / 1000.0;
    o[1] = s.v_mm_s / 1000.0;
    o[2] = s.eb_s;
  });
  // Start states: the far end of the approach and the grid's worst check, each at the
  // largest speed the runtime admits there (measured speed exact, worst true front).
  auto add_start = [&](std::int64_t xs) {
    const std::int64_t ve = m.patterns().EmergencyPatternSpeed(xs, loc.stop_limit_mm, env.e_mm, env.e_mm);
    const auto vm = m.MaxMeasuredSpeed(ve);
    ob::ScopedState<ob::RealVectorStateSpace> st(space);
    st[0] = (static_cast<double>(xs) - l) / 1000.0;
    st[1] = vm ? m.TrueSpeedMax(*vm) / 1000.0 : 0.0;
    st[2] = -1.0;
    ss.addStartState(st);
  };
  add_start(loc.stop_limit_mm - m.approach_mm());
  const GridResult g = GridWorstCase(m, loc, 1000);
  add_start(static_cast<std::int64_t>(g.worst_moving.check_front_mm));
  if (opt.admit_standstill_restart && g.worst.standstill_start) {
    add_start(static_cast<std::int64_t>(g.worst.check_front_mm));  // standing where V_e = 0
  }
  ss.setGoal(std::make_shared<BeyondLimit>(si));
  auto planner = std::make_shared<oc::KPIECE1>(si);
  planner->setGoalBias(0.2);
  ss.setPlanner(planner);
  ss.setup();
  const ob::PlannerStatus status = ss.solve(ob::timedPlannerTerminationCondition(opt.budget_s));
  (void)status;  // KPIECE1 may label a goal-reaching path "approximate"; the path decides
  res.violation = false;
  if (ss.haveSolutionPath()) {
    const oc::PathControl& path = ss.getSolutionPath();
    for (std::size_t i = 0; i < path.getStateCount(); ++i) {
      res.violation = res.violation || path.getState(static_cast<unsigned>(i))->as<ob::RealVectorStateSpace::StateType>()->values[0] > 0.0;
    }
  }
  if (res.violation) {
    const oc::PathControl& path = ss.getSolutionPath();
    const double* s0 = path.getState(0)->as<ob::RealVectorStateSpace::StateType>()->values;
    nlohmann::ordered_json steps = nlohmann::ordered_json::array();
    for (unsigned i = 0; i < static_cast<unsigned>(path.getControlCount()); ++i) {
      AdversaryStep c = FromControl(path.getControl(i));
      c.cycles = std::max(1, static_cast<int>(std::lround(path.getControlDuration(i) / cycle_s)));
      steps.push_back(StepJson(c));
    }
    const auto& rl = m.running_line();
    nlohmann::ordered_json grads = nlohmann::ordered_json::array();
    for (const auto& gr : rl.gradients) {
      grads.push_back({{"begin_mm", gr.section.begin_mm}, {"end_mm", gr.section.end_mm}, {"permille_x10", gr.permille_x10}});
    }
    nlohmann::ordered_json lims = nlohmann::ordered_json::array();
    for (const auto& sl : rl.speed_limits) {
      lims.push_back({{"begin_mm", sl.section.begin_mm}, {"end_mm", sl.section.end_mm}, {"kmh", sl.kmh}});
    }
    nlohmann::ordered_json c;
    c["schema"] = "railproof/margin-case/1";
    c["found_by"] = "falsifier (ompl::control::KPIECE1, seed " + std::to_string(opt.seed) + ")";
    c["requirements"] = {"REQ-BR-009", "REQ-BR-014"};
    c["train"] = t.name;
    c["line"] = line_name;
    c["running_line"] = rl.id;
    c["length_mm"] = rl.length_mm;
    c["balise_spacing_mm"] = m.longest_balise_spacing_mm();
    c["admit_standstill_restart"] = opt.admit_standstill_restart;
    c["location"] = {{"class", ToString(loc.cls)}, {"id", loc.id}, {"stop_limit_mm", loc.stop_limit_mm}};
    c["gradients"] = grads;
    c["speed_limits"] = lims;
    c["start"] = {{"front_mm", l + s0[0] * 1000.0}, {"speed_mm_s", s0[1] * 1000.0}};
    c["steps"] = steps;
    res.regression_case = c;
  }
  res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

// @implements REQ-BR-009 REQ-BR-014
ReplayResult ReplayCase(const nlohmann::json& doc, const TrainType& train, const std::string& file,
                        bool admit_standstill_restart) {
  const offline::JsonNode root(doc, "", file);
  if (root.Key("schema").String() != "railproof/margin-case/1") {
    root.Key("schema").Fail("unsupported schema");
  }
  offline::RunningLine rl;
  rl.id = root.Key("running_line").String();
  rl.length_mm = root.Key("length_mm").Int();
  for (const auto& g : root.Key("gradients").Array()) {
    rl.gradients.push_back({{g.Key("begin_mm").Int(), g.Key("end_mm").Int()}, g.Key("permille_x10").Int()});
  }
  for (const auto& s : root.Key("speed_limits").Array()) {
    rl.speed_limits.push_back({{s.Key("begin_mm").Int(), s.Key("end_mm").Int()}, s.Key("kmh").Int()});
  }
  const std::int64_t spacing = root.Key("balise_spacing_mm").Int();
  rl.balises.push_back({"replay", std::min(rl.length_mm, spacing)});  // E of the replay: env below
  const MarginModel m(rl, train, ReferenceSpeedErrorModel());
  Env env{&m, (train.odometry_ppm * spacing + 999'999) / 1'000'000 + train.readhesion_margin_mm,
          root.Key("location").Key("stop_limit_mm").Int(), admit_standstill_restart};
  SimState s{root.Key("start").Key("front_mm").Number(), root.Key("start").Key("speed_mm_s").Number(), -1.0};
  // the start must be admissible for THIS train: at most the largest true speed its runtime
  // admits at the start (front error +E: x_s = true front)
  {
    const auto xs = static_cast<std::int64_t>(std::floor(s.x_mm));
    const auto vm = m.MaxMeasuredSpeed(m.patterns().EmergencyPatternSpeed(xs, env.l_mm, env.e_mm, env.e_mm));
    s.v_mm_s = std::min(s.v_mm_s, vm ? m.TrueSpeedMax(*vm) : 0.0);
  }
  ReplayResult r;
  r.max_overrun_mm = s.x_mm - static_cast<double>(env.l_mm);
  const auto cycle = [&](const AdversaryStep& c) {
    Cycle(env, s, c);
    ++r.cycles;
    r.max_overrun_mm = std::max(r.max_overrun_mm, s.x_mm - static_cast<double>(env.l_mm));
  };
  const auto steps = root.Key("steps").Array();
  for (const auto& st : steps) {
    const AdversaryStep c = Clamp(env, StepFromJson(st));
    for (int k = 0; k < c.cycles; ++k) {
      cycle(c);
    }
  }
  // after the recorded controls: keep the last control until standstill (bounded)
  if (!steps.empty()) {
    const AdversaryStep c = Clamp(env, StepFromJson(steps.back()));
    for (int k = 0; k < 3000 && (s.v_mm_s > 0.0 || s.eb_s < 0.0); ++k) {
      cycle(c);
      if (s.v_mm_s <= 0.0 && s.eb_s >= 0.0) {
        break;
      }
    }
  }
  r.emergency_commanded = s.eb_s >= 0.0;
  return r;
}

}  // namespace railproof::br::analysis
