// Per-section trajectories, the slowing rule, the supervision as the safety layer and the
// simulation of a leader and a follower (follower.hpp; spec/design/fc.md §5-§7).
#include <algorithm>
#include <cmath>
#include <limits>

#include "railproof/fc/follower.hpp"

namespace railproof::fc {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A train counts as stopped at a stop point this close to it.
constexpr double kStopToleranceM = 1.0;
// A section entered while coasting this much above its coast-start speed goes on coasting.
constexpr double kMergeMarginMps = 0.05;
// A plan this much earlier than required sends the follower to the outside stop instead.
constexpr double kStopEarlyS = 0.5;

// The demand that holds the speed against resistance and gradient.
double HoldDemand(const Corridor& c, double x, double v) {
  return offline::ResistanceDecel(c.train().perf.resistance, v) + offline::GradeDecel(c.Gradient(x));
}

}  // namespace

// ---- plans ---------------------------------------------------------------------------------

double PlanExecutor::Wanted(const Corridor& c, const State& s, double dt) {
  const std::vector<SectionPlan>& sec = plan_.sections;
  if (!started_) {
    started_ = true;
    cruised_.assign(sec.size(), 0.0);
    while (section_ + 1 < sec.size() && s.x >= sec[section_ + 1].begin) {
      ++section_;
    }
  }
  bool entered = false;
  while (section_ + 1 < sec.size() && s.x >= sec[section_ + 1].begin) {
    ++section_;
    entered = true;
  }
  const SectionPlan& p = sec[section_];
  if (entered && !(phase_ == Phase::kCoast && s.v >= p.coast_speed + kMergeMarginMps)) {
    phase_ = Phase::kAccelerate;
  }
  // a train above its coast-start speed brakes to it (a section entered faster, or a plan
  // slowed below the speed it runs at)
  if (phase_ == Phase::kAccelerate && std::abs(s.v - p.coast_speed) <= 1e-3) {
    phase_ = cruised_[section_] < p.cruise_s ? Phase::kCruise : Phase::kCoast;
  }
  if (phase_ == Phase::kCruise && cruised_[section_] >= p.cruise_s) {
    phase_ = Phase::kCoast;
  }
  switch (phase_) {
    case Phase::kAccelerate:
      return std::clamp((p.coast_speed - s.v) / dt + HoldDemand(c, s.x, s.v), -c.train().beta,
                        c.train().perf.accel_mps2);
    case Phase::kCruise:
      return HoldDemand(c, s.x, s.v);
    case Phase::kCoast:
      break;
  }
  return 0.0;
}

void PlanExecutor::Record(double dt, bool cut) {
  if (phase_ != Phase::kCruise) {
    return;
  }
  if (cut) {
    phase_ = Phase::kCoast;  // the braking curve ends the cruise
    return;
  }
  cruised_[section_] += dt;
}

bool PlanExecutor::Within(const Corridor& c, double x, double v) const {
  return x > plan_.target_x || v <= c.CurveTo(x, plan_.target_x, plan_.target_v) + 1e-9;
}

namespace {

// Runs a plan from a state to its target; the executor is left as it ended.
double RunPlan(const Corridor& c, const State& from, PlanExecutor& ex, double dt, double limit_s) {
  State s = from;
  auto ok = [&](double x, double v) { return v <= c.StaticCeiling(x) + 1e-9 && ex.Within(c, x, v); };
  const auto steps = static_cast<long>(limit_s / dt);
  for (long k = 0; k < steps && s.x < ex.plan().target_x; ++k) {
    const double wanted = ex.Wanted(c, s, dt);
    const double u = ChooseDemand(c, s, wanted, dt, ok);
    ex.Record(dt, u < wanted - 1e-9);
    const State n = StepTrain(c, s, u, dt);
    if (n.v <= 0.0 && n.x <= s.x) {
      return kInf;  // stopped before the target
    }
    s = n;
  }
  return s.x >= ex.plan().target_x ? s.t - from.t : kInf;
}

}  // namespace

double PlanTime(const Corridor& c, const State& from, const Plan& plan, double dt, double limit_s) {
  PlanExecutor ex(plan);
  return RunPlan(c, from, ex, dt, limit_s);
}

Plan FastestPlan(const Corridor& c, const State& from, double target_x, double target_v, double dt) {
  Plan p;
  p.target_x = target_x;
  p.target_v = target_v;
  std::vector<double> begins{from.x};
  for (const double b : c.LimitChanges(from.x, target_x)) {
    begins.push_back(b);
  }
  for (const double b : begins) {
    p.sections.push_back({b, c.Limit(b), kInf});
  }
  // the fastest's cruise durations: as long as the run cruises before a braking curve ends it
  PlanExecutor ex(p);
  RunPlan(c, from, ex, dt, 600.0);
  for (std::size_t i = 0; i < p.sections.size(); ++i) {
    p.sections[i].cruise_s = ex.cruised(i);
  }
  return p;
}

Plan SlowedPlan(const Plan& fastest, const Corridor& c, double lambda) {
  Plan p = fastest;
  const double shorten = std::clamp(lambda, 0.0, 1.0);
  const double lower = std::clamp(lambda - 1.0, 0.0, 1.0);
  for (SectionPlan& s : p.sections) {
    s.cruise_s *= 1.0 - shorten;
    s.coast_speed = c.Limit(s.begin) * (1.0 - 0.95 * lower);
  }
  return p;
}

SlowedResult SlowToRunningTime(const Corridor& c, const State& from, double target_x, double target_v,
                               double required_s, double dt) {
  const Plan fastest = FastestPlan(c, from, target_x, target_v, dt);
  SlowedResult best{fastest, 0.0, PlanTime(c, from, fastest, dt)};
  if (best.time_s >= required_s) {
    return best;
  }
  const Plan slowest = SlowedPlan(fastest, c, 2.0);
  const double t_slowest = PlanTime(c, from, slowest, dt);
  if (t_slowest <= required_s) {
    return {slowest, 2.0, t_slowest};
  }
  double lo = 0.0;
  double hi = 2.0;
  for (int i = 0; i < 24; ++i) {
    const double mid = 0.5 * (lo + hi);
    const Plan plan = SlowedPlan(fastest, c, mid);
    const double t = PlanTime(c, from, plan, dt);
    if (std::abs(t - required_s) < std::abs(best.time_s - required_s)) {
      best = {plan, mid, t};
    }
    (t < required_s ? lo : hi) = mid;
  }
  return best;
}

// ---- supervision -------------------------------------------------------------------------------

offline::Control ApplySupervision(double follower_demand, const br::Decision& decision, const Train& train) {
  offline::Control out;
  if (decision.level == br::BrakeLevel::kEmergency) {
    out.emergency = true;
    return out;
  }
  const double brake = train.beta * br::ServiceNotchSevenths(decision.level) / 7.0;
  if (brake > 0.0) {
    // any supervision brake removes the traction; the follower may brake harder, never less
    out.brake_mps2 = std::max(brake, -follower_demand);
    return out;
  }
  if (follower_demand >= 0.0) {
    out.traction_mps2 = follower_demand;
  } else {
    out.brake_mps2 = -follower_demand;
  }
  return out;
}

// ---- the simulation -------------------------------------------------------------------------------

const char* PolicyName(Policy p) {
  switch (p) {
    case Policy::kMovingBlockBaseline:
      return "moving_block_baseline";
    case Policy::kFixedBlockBaseline:
      return "fixed_block_baseline";
    case Policy::kControlled:
      return "controlled";
  }
  return "?";
}

std::vector<double> FixedBlocks(const offline::RunningLine& rl, double from_m, double to_m, double length) {
  std::vector<double> b;
  double prev_end = -kInf;
  for (const offline::Station& s : rl.stations) {
    const double begin = static_cast<double>(s.platform.begin_mm) / 1000.0;
    const double end = static_cast<double>(s.platform.end_mm) / 1000.0;
    if (end < from_m || begin > to_m) {
      continue;
    }
    // blocks of `length` laid back from the platform entry; a remainder shorter than half a
    // block joins its neighbour
    for (double x = begin - length; prev_end > -kInf && x > prev_end + 0.5 * length; x -= length) {
      b.push_back(x);
    }
    b.push_back(begin);
    b.push_back(end);
    prev_end = end;
  }
  std::sort(b.begin(), b.end());
  return b;
}

namespace {

// The leader: from its origin stop to the station, its dwell, then to the next stop, at full
// traction within the static ceiling.
struct LeaderRun {
  std::vector<State> states;
  double departure = 0.0, route_clear = kInf;
};

bool Stopped(const State& s, double stop) { return s.v <= 0.0 && s.x >= stop - kStopToleranceM; }

}  // namespace

double FastestRunTime(const Corridor& c, double from_stop, double to_stop, double dt) {
  State s{0.0, from_stop, 0.0};
  auto ok = [&](double x, double v) { return v <= c.StaticCeiling(x) + 1e-9 && v <= c.CurveTo(x, to_stop) + 1e-9; };
  for (int k = 0; k < 100000 && !Stopped(s, to_stop); ++k) {
    s = StepTrain(c, s, ChooseDemand(c, s, c.train().perf.accel_mps2, dt, ok), dt);
  }
  return s.t;
}

namespace {

LeaderRun RunLeader(const Scenario& sc) {
  const Corridor& c = *sc.corridor;
  const BufferParams& b = c.train().buffers;
  const double length = c.train().perf.length_m;
  LeaderRun r;
  State s{0.0, sc.origin_stop, 0.0};
  double arrived = kInf;
  r.departure = kInf;
  const auto steps = static_cast<long>(sc.horizon / sc.dt);
  r.states.reserve(static_cast<std::size_t>(steps) + 1);
  r.states.push_back(s);
  for (long k = 0; k < steps; ++k) {
    double target = sc.station_stop;
    double wanted = c.train().perf.accel_mps2;
    if (s.t < sc.leader_depart - 1e-9) {
      wanted = -c.train().beta;
    } else if (arrived < kInf) {
      if (r.departure == kInf && s.t >= std::max(sc.leader_planned_departure + sc.leader_delay, arrived) - 1e-9) {
        r.departure = s.t;
      }
      if (r.departure == kInf) {
        wanted = -c.train().beta;
      }
      target = sc.next_stop;
    }
    auto ok = [&](double x, double v) { return v <= c.StaticCeiling(x) + 1e-9 && v <= c.CurveTo(x, target) + 1e-9; };
    s = StepTrain(c, s, ChooseDemand(c, s, wanted, sc.dt, ok), sc.dt);
    if (arrived == kInf && Stopped(s, sc.station_stop)) {
      arrived = s.t;
    }
    const double rear = s.x - length - RearBuffer(b, s.x, LastBalise(c.balises(), s.x));
    if (r.departure < kInf && r.route_clear == kInf && rear >= sc.station_end) {
      r.route_clear = s.t;
    }
    r.states.push_back(s);
  }
  return r;
}

}  // namespace

Run Simulate(const Scenario& sc, Policy policy) {
  const Corridor& c = *sc.corridor;
  const Train& tr = c.train();
  const double length = tr.perf.length_m;
  const LeaderRun leader = RunLeader(sc);
  Run run;
  run.leader = leader.states;
  run.leader_departure = leader.departure;
  run.route_clear = leader.route_clear;
  // the leader's clearing run, as the follower predicts it from a departure
  const double clear_run = leader.route_clear - leader.departure;
  const double x_a = sc.approach.x;

  State s{0.0, sc.origin_stop, 0.0};
  PlanExecutor ex;
  bool planned = false, replanned_on_departure = false, stop_outside = false;
  double start_at = kInf;
  run.follower.push_back(s);
  for (std::size_t k = 0; k + 1 < leader.states.size(); ++k) {
    const State& l = leader.states[k];
    const bool departed = s.t >= leader.departure - 1e-9;
    const bool clear = s.t >= leader.route_clear - 1e-9;
    // the stop limit the ground gives the follower
    double authority = kInf;
    if (l.x > s.x) {
      const double rear = l.x - length - RearBuffer(tr.buffers, l.x, LastBalise(c.balises(), l.x));
      if (policy == Policy::kFixedBlockBaseline) {
        const std::vector<double>& fb = sc.fixed_blocks;
        for (std::size_t j = 0; j + 1 < fb.size(); ++j) {
          const bool occupied = l.x - length < fb[j + 1] + sc.fixed_block_overlap && l.x > fb[j];
          if (occupied && fb[j] >= s.x - 1e-9) {
            authority = fb[j];
            break;
          }
        }
      } else {
        authority = rear;
        if (!clear && s.x < sc.station_entry) {
          authority = std::min(authority, sc.station_entry);
        }
      }
    }
    double wanted = tr.perf.accel_mps2;
    bool outside_curve = false;
    bool plan_curve = false;
    if (s.t < sc.follower_depart - 1e-9) {
      wanted = -tr.beta;
    } else if (policy == Policy::kControlled && !clear && s.x < x_a) {
      const double target_time = (departed ? leader.departure : sc.leader_planned_departure) + clear_run;
      if (departed && !replanned_on_departure) {
        replanned_on_departure = true;
        planned = false;
      }
      if (departed && s.v <= 0.0 && start_at == kInf) {
        // standing (at the outside stop): full acceleration, started so that it passes the
        // approach point at the route-clear time
        start_at = target_time - PlanTime(c, s, FastestPlan(c, s, x_a, sc.approach.v, sc.dt), sc.dt);
        planned = false;
        stop_outside = false;
      }
      if (s.v <= 0.0 && s.t > sc.follower_depart && (!departed || s.t < start_at - 1e-9)) {
        wanted = -tr.beta;
        run.stopped_outside = run.stopped_outside || std::abs(s.x - sc.outside.x) < kStopToleranceM;
      } else {
        if (!planned) {
          const double required = target_time - s.t;
          const SlowedResult slowed = SlowToRunningTime(c, s, x_a, sc.approach.v, required, sc.dt);
          ex = PlanExecutor(slowed.plan);
          planned = true;
          // a follower that can still stop at the outside stop and reach the approach point at
          // its speed by full acceleration in time waits there (the slowed plan would pass it
          // slower); braking evenly to it takes 2 d / v
          const bool can_stop = s.v > 0.0 && s.x < sc.outside.x &&
                                2.0 * (sc.outside.x - s.x) / s.v + sc.outside.time_to_approach_s <= required;
          stop_outside = departed && (can_stop || (slowed.time_s < required - kStopEarlyS && s.x < sc.outside.x));
        }
        wanted = ex.Wanted(c, s, sc.dt);
        plan_curve = true;
        // keep to the timetable while the leader stands; brake at β to the outside stop when
        // going on would pass it
        outside_curve = (!departed || stop_outside) && s.x <= sc.outside.x;
      }
    }
    auto safe = [&](double x, double v) {
      return v <= c.StaticCeiling(x) + 1e-9 && (authority == kInf || v <= c.SafeSpeed(x, authority) + 1e-9);
    };
    auto ok = [&](double x, double v) {
      return safe(x, v) && v <= c.CurveTo(x, sc.station_stop) + 1e-9 && (!plan_curve || ex.Within(c, x, v)) &&
             (!outside_curve || v <= c.CurveTo(x, sc.outside.x) + 1e-9);
    };
    const double u = ChooseDemand(c, s, wanted, sc.dt, ok);
    if (plan_curve) {
      ex.Record(sc.dt, u < wanted - 1e-9);
    }
    const State n = StepTrain(c, s, u, sc.dt);
    double excess = n.v - c.StaticCeiling(n.x);
    if (authority < kInf) {
      excess = std::max(excess, n.v - c.SafeSpeed(n.x, authority));
    }
    run.worst_excess = std::max(run.worst_excess, excess);
    if (!run.approach_passed && s.x < x_a && n.x >= x_a) {
      run.approach_passed = n.t;
      run.approach_passed_speed = n.v;
    }
    s = n;
    run.follower.push_back(s);
    if (Stopped(s, sc.station_stop)) {
      run.follower_arrival = s.t;
      break;
    }
  }
  return run;
}

}  // namespace railproof::fc
