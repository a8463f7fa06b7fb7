// The D2 headway study (headway.hpp; spec/design/fc.md §8).
#include "railproof/fc/headway.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "railproof/generated/fc_params.hpp"
#include "railproof/offline/svg.hpp"

namespace railproof::fc {

namespace {

namespace fcp = railproof::params::fc;
using offline::InputError;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Case kCases[] = {Case::kLevelNoLimits, Case::kSpeedLimits, Case::kGradients};
constexpr Policy kPolicies[] = {Policy::kMovingBlockBaseline, Policy::kFixedBlockBaseline, Policy::kControlled};

double Seconds(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }
double Metres(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }

struct Stations {
  const offline::Station* origin = nullptr;
  const offline::Station* station = nullptr;
  const offline::Station* next = nullptr;
};

// The leader and follower services and the three stations, or InputError naming the entry.
Stations CheckServices(const lc::analysis::Timetable& tt, const offline::RunningLine& rl) {
  auto fail = [&](std::size_t i, const std::string& reason) {
    throw InputError(tt.file + ": services[" + std::to_string(i) + "] (" + tt.services[i].id + "): " + reason);
  };
  if (tt.services.size() < 2) {
    throw InputError(tt.file + ": services: the study needs a leader and a follower (two services), got " +
                     std::to_string(tt.services.size()));
  }
  const lc::analysis::Service& l = tt.services[0];
  const lc::analysis::Service& f = tt.services[1];
  if (f.running_line != l.running_line || f.train != l.train || f.from != l.from || f.to != l.to) {
    fail(1, "the follower must run the leader's route with the leader's train type");
  }
  if (f.depart_ms <= l.depart_ms) {
    fail(1, "the follower must depart after the leader");
  }
  if (l.stops.empty() || f.stops.empty() || f.stops[0].station != l.stops[0].station) {
    fail(l.stops.empty() ? 0 : 1, "leader and follower must call at the same first stop (the studied station)");
  }
  auto find = [&](const std::string& name, std::size_t i, const char* what) {
    const offline::Station* s = rl.FindStation(name);
    if (s == nullptr) {
      fail(i, std::string("unknown ") + what + " station '" + name + "' on running line " + rl.id);
    }
    return s;
  };
  Stations s;
  s.origin = find(l.from.empty() ? rl.stations.front().name : l.from, 0, "origin");
  s.station = find(l.stops[0].station, 0, "stop");
  s.next = find(l.stops.size() > 1 ? l.stops[1].station : (l.to.empty() ? rl.stations.back().name : l.to), 0, "next");
  return s;
}

double PlannedRunTime(const lc::analysis::Timetable& tt, double fastest_s) {
  const double step = Seconds(tt.planned_time_step_ms);
  const double t = fastest_s * (1.0 + static_cast<double>(tt.running_time_allowance_percent) / 100.0);
  return std::ceil(t / step - 1e-9) * step;
}

}  // namespace

StudyResult RunStudy(const StudyInput& in) {
  const lc::analysis::Timetable& tt = *in.timetable;
  lc::analysis::CheckTimetable(tt, *in.line, *in.trains);
  const lc::analysis::Service& leader = tt.services.empty() ? lc::analysis::Service{} : tt.services[0];
  const offline::RunningLine& rl = in.line->Running(tt.services.empty() ? "up" : leader.running_line);
  const Stations st = CheckServices(tt, rl);
  const Train train = MakeD2Train(in.trains->at(leader.train));
  const double dt = static_cast<double>(fcp::time_step_ms) / 1000.0;
  const double horizon = static_cast<double>(fcp::horizon_ms) / 1000.0;
  const double origin_stop = Metres(st.origin->stop_mm);
  const double stop = Metres(st.station->stop_mm);
  const double next_stop = Metres(st.next->stop_mm);

  StudyResult r;
  r.origin = st.origin->name;
  r.station = st.station->name;
  r.next = st.next->name;
  for (const Case which : kCases) {
    const Corridor c(rl, origin_stop - 1.0, next_stop + 1.0, train, which);
    CaseResult cr;
    cr.which = which;
    const ApproachProblem p{&c, Metres(st.station->platform.begin_mm), stop};
    cr.approach = FindApproachPoint(p, static_cast<double>(fcp::approach_grid_step_mm_s) / 1000.0);
    cr.outside = FindOutsideStop(c, cr.approach);
    const double run_time = PlannedRunTime(tt, FastestRunTime(c, origin_stop, stop, dt));
    cr.planned_arrival_s = run_time;
    cr.planned_departure_s = run_time + Seconds(leader.stops[0].dwell_ms);
    const double follower_depart = Seconds(tt.services[1].depart_ms - leader.depart_ms);
    r.interval_planned_s = follower_depart + run_time - cr.planned_departure_s;
    for (const double delay : in.delays_s) {
      Scenario sc;
      sc.corridor = &c;
      sc.origin_stop = origin_stop;
      sc.station_entry = p.entry;
      sc.station_end = Metres(st.station->platform.end_mm);
      sc.station_stop = stop;
      sc.next_stop = next_stop;
      sc.follower_depart = follower_depart;
      sc.leader_planned_departure = cr.planned_departure_s;
      sc.leader_delay = delay;
      sc.fixed_blocks = FixedBlocks(rl, origin_stop, next_stop, Metres(fcp::fixed_block_length_mm));
      sc.fixed_block_overlap = Metres(fcp::fixed_block_overlap_mm);
      sc.dt = dt;
      sc.horizon = horizon;
      sc.approach = cr.approach;
      sc.outside = cr.outside;
      DelayRuns d;
      d.delay_s = delay;
      for (const Policy policy : kPolicies) {
        PolicyRun pr;
        pr.policy = policy;
        pr.run = Simulate(sc, policy);
        pr.interval_s = pr.run.follower_arrival ? *pr.run.follower_arrival - pr.run.leader_departure : kInf;
        d.runs.push_back(std::move(pr));
      }
      cr.delays.push_back(std::move(d));
    }
    r.cases.push_back(std::move(cr));
  }
  return r;
}

namespace {

nlohmann::ordered_json Num(double v, double scale = 1000.0) {
  if (!std::isfinite(v)) {
    return nullptr;
  }
  return std::round(v * scale) / scale;
}

}  // namespace

nlohmann::ordered_json StudyJson(const StudyResult& r, bool* pass) {
  using J = nlohmann::ordered_json;
  const double tolerance_s = static_cast<double>(fcp::approach_tolerance_ms) / 1000.0;
  J j;
  j["schema"] = "railproof/fc-headway/1";
  j["requirements"] = {"REQ-FC-003", "REQ-FC-004", "REQ-FC-005", "REQ-FC-006", "REQ-FC-008", "REQ-FC-009"};
  j["route"] = r.origin + " - " + r.station + " - " + r.next;
  j["studied_station"] = r.station;
  j["planned_interval_s"] = Num(r.interval_planned_s);
  J cases = J::array();
  J runs = J::array();
  bool ok = true;
  for (const CaseResult& c : r.cases) {
    double min_i[3] = {kInf, kInf, kInf};
    double best_reduction = -kInf;
    double excess = 0.0;
    bool arrived = true;
    for (const DelayRuns& d : c.delays) {
      for (std::size_t k = 0; k < d.runs.size(); ++k) {
        const PolicyRun& p = d.runs[k];
        min_i[k] = std::min(min_i[k], p.interval_s);
        excess = std::max(excess, p.run.worst_excess);
        arrived = arrived && p.run.follower_arrival.has_value();
        runs.push_back(J{{"case", CaseName(c.which)},
                         {"delay_s", Num(d.delay_s)},
                         {"policy", PolicyName(p.policy)},
                         {"interval_s", Num(p.interval_s)},
                         {"leader_departure_s", Num(p.run.leader_departure)},
                         {"route_clear_s", Num(p.run.route_clear)},
                         {"follower_arrival_s", Num(p.run.follower_arrival.value_or(kInf))},
                         {"approach_passed_s", Num(p.run.approach_passed.value_or(kInf))},
                         {"approach_passed_kmh", Num(p.run.approach_passed_speed * 3.6, 10.0)},
                         {"stopped_outside", p.run.stopped_outside},
                         {"worst_excess_mps", Num(p.run.worst_excess, 1e6)}});
      }
      best_reduction = std::max(best_reduction, d.runs[0].interval_s - d.runs[2].interval_s);
    }
    const double diff_s = c.approach.time_s - c.approach.grid_time_s;
    const bool cross = c.approach.solved && std::abs(diff_s) <= tolerance_s;
    const bool meets = cross && excess <= 1e-6 && arrived;
    ok = ok && meets;
    cases.push_back(J{{"case", CaseName(c.which)},
                      {"approach_speed_kmh", Num(c.approach.v * 3.6, 100.0)},
                      {"approach_position_m", Num(c.approach.x, 100.0)},
                      {"approach_time_s", Num(c.approach.time_s)},
                      {"grid_approach_speed_kmh", Num(c.approach.grid_v * 3.6, 100.0)},
                      {"grid_approach_time_s", Num(c.approach.grid_time_s)},
                      {"ipopt_status", c.approach.status},
                      {"ipopt_minus_grid_ms", Num(diff_s * 1000.0, 10.0)},
                      {"outside_stop_m", Num(c.outside.x, 100.0)},
                      {"leader_planned_departure_s", Num(c.planned_departure_s)},
                      {"min_interval_baseline_s", Num(min_i[0])},
                      {"min_interval_fixed_block_s", Num(min_i[1])},
                      {"min_interval_controlled_s", Num(min_i[2])},
                      {"reduction_s", Num(min_i[0] - min_i[2])},
                      {"reduction_vs_fixed_block_s", Num(min_i[1] - min_i[2])},
                      {"best_reduction_s", Num(best_reduction)},
                      {"worst_excess_mps", Num(excess, 1e6)},
                      {"meets_target", meets}});
  }
  j["cases"] = cases;
  j["runs"] = runs;
  if (pass != nullptr) {
    *pass = ok;
  }
  return j;
}

std::string TimeDistanceSvg(const StudyResult& r, const CaseResult& c, const DelayRuns& d) {
  const Run& first = d.runs.front().run;
  double t_max = 0.0;
  double x_min = kInf;
  double x_max = -kInf;
  for (const PolicyRun& p : d.runs) {
    t_max = std::max(t_max, p.run.follower.back().t);
  }
  for (const State& s : first.leader) {
    if (s.t <= t_max) {
      x_min = std::min(x_min, s.x);
      x_max = std::max(x_max, s.x);
    }
  }
  offline::SvgPlot plot(0.0, t_max, x_min - 50.0, x_max + 50.0);
  char title[200];
  std::snprintf(title, sizeof title, "Time-distance, case %s, leader %.0f s late at %s", CaseName(c.which),
                d.delay_s, r.station.c_str());
  plot.SetTitle(title);
  plot.SetXLabel("time from the leader's departure (s)");
  plot.SetYLabel("front position (m)");
  auto series = [&](const std::vector<State>& states) {
    offline::SvgPoints pts;
    for (std::size_t i = 0; i < states.size(); i += 25) {
      pts.emplace_back(states[i].t, states[i].x);
    }
    pts.emplace_back(states.back().t, states.back().x);
    return pts;
  };
  plot.AddSeries(series(first.leader), {"#000000", 2.0, "", 1.0}, "leader");
  const char* colours[] = {"#1f77b4", "#7f7f7f", "#d62728"};
  const char* dashes[] = {"6 4", "2 3", ""};
  for (std::size_t k = 0; k < d.runs.size(); ++k) {
    plot.AddSeries(series(d.runs[k].run.follower), {colours[k], 2.0, dashes[k], 1.0},
                   std::string("follower, ") + PolicyName(d.runs[k].policy));
  }
  plot.AddHLine(c.approach.x, "approach point", {"#d62728", 1.0, "4 4", 0.6});
  plot.AddHLine(c.outside.x, "outside stop", {"#ff7f0e", 1.0, "4 4", 0.6});
  plot.AddVLine(first.leader_departure, "leader departs", {"#000000", 1.0, "3 3", 0.6});
  plot.AddVLine(first.route_clear, "route clear", {"#2ca02c", 1.0, "3 3", 0.6});
  return plot.Render();
}

}  // namespace railproof::fc
