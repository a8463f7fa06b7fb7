// Line scenario simulation: measurements after every step (fault reactions, the gap, the
// diagram's samples), the gap result and the summary (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>

namespace railproof::sim {

void Simulation::Impl::Measure() {
  for (auto& f : faults) {
    if (!f.spec.train || !f.started) {
      continue;
    }
    const TrainRt* t = Find(*f.spec.train);
    if (t == nullptr || !t->OnLine()) {
      continue;
    }
    if (!f.ended && !f.standstill_at && t->motion.speed <= 0.0) {
      f.standstill_at = now;
    }
    if (f.ended && !f.moving_again_at && t->motion.speed > 0.0) {
      f.moving_again_at = now;
    }
  }
  for (auto& t : trains) {
    const units::OnboardOutputs* o = t->Out();
    if (!t->OnLine() || o == nullptr || !o->position_valid) {
      continue;
    }
    const double nominal = ToM(o->front_mm);
    t->max_lead_m = std::max(t->max_lead_m, nominal - t->motion.position);
    t->max_outside_m = std::max({t->max_outside_m, t->motion.position - ToM(o->front_mm + o->front_error_mm),
                                 ToM(o->front_mm - o->rear_error_mm) - t->motion.position});
  }
  if (sc.gap && now >= sc.gap->from_ms && now <= sc.gap->to_ms) {
    const TrainRt* l = Find(sc.gap->leader);
    const TrainRt* f = Find(sc.gap->follower);
    if (l != nullptr && f != nullptr && l->OnLine() && f->OnLine()) {
      const double gap = l->Rear() - f->motion.position;
      ++gap_n;
      gap_sum += gap;
      gap_sq += gap * gap;
      gap_min = std::min(gap_min, gap);
      gap_max = std::max(gap_max, gap);
      gap_vl += l->motion.speed;
      gap_vf += f->motion.speed;
      if (now % sc.sample_ms == 0) {
        // the gap in three parts: leader's rear to the follower's limit (margin, the leader's
        // reported envelope, the report's age), the limit to the follower's supervised front
        // (the pattern the follower rides), and the supervised front to the true front
        const units::OnboardOutputs& fo = *f->Out();
        const double supervised = ToM(fo.front_mm + fo.front_error_mm);
        const double limit = fo.indications.limit_mm ? ToM(*fo.indications.limit_mm) : std::nan("");
        gap_series.push_back({ToS(now), R1(gap), R1(f->motion.speed * 3.6),
                              R1(static_cast<double>(fo.indications.permitted_speed_mm_s) * 0.0036),
                              R1(limit - supervised), R1(l->Rear() - limit), R1(supervised - f->motion.position)});
      }
    }
  }
  if (now % sc.sample_ms == 0) {
    for (auto& t : trains) {
      if (!t->OnLine()) {
        continue;
      }
      const units::OnboardOutputs& o = *t->Out();
      const auto lim = o.authority_limit_mm;
      const bool usable = lim && o.authority_usable;
      t->samples.push_back(Sample{now, t->motion.position, t->Rear(), usable ? ToM(*lim) : std::nan("")});
    }
  }
}

std::optional<GapResult> Simulation::Gap() const {
  const Impl& s = *impl_;
  if (!s.sc.gap || s.gap_n == 0) {
    return std::nullopt;
  }
  GapResult g;
  g.leader = s.sc.gap->leader;
  g.follower = s.sc.gap->follower;
  g.from_s = ToS(s.sc.gap->from_ms);
  g.to_s = ToS(s.sc.gap->to_ms);
  g.samples = s.gap_n;
  const auto n = static_cast<double>(s.gap_n);
  g.mean_m = s.gap_sum / n;
  g.min_m = s.gap_min;
  g.max_m = s.gap_max;
  g.std_m = std::sqrt(std::max(0.0, s.gap_sq / n - g.mean_m * g.mean_m));
  g.leader_speed_kmh = s.gap_vl / n * 3.6;
  g.follower_speed_kmh = s.gap_vf / n * 3.6;
  return g;
}

nlohmann::ordered_json Simulation::Summary() const {
  const Impl& s = *impl_;
  Json j;
  j["schema"] = "railproof/sim-summary/1";
  j["scenario"] = s.sc.name;
  j["description"] = s.sc.description;
  j["line"] = s.line.name;
  j["line_assumption"] = s.line.assumption;
  j["running_line"] = s.rl->id;
  j["simulated_s"] = ToS(s.now);
  j["step_ms"] = s.sc.step_ms;
  j["seed"] = s.sc.seed;
  j["ground_cycle_ms"] = s.sc.ground_cycle_ms;
  j["report_period_ms"] = s.sc.report_period_ms;
  j["margin_policy"] = s.sc.margin_policy == MarginPolicy::kD2 ? "d2" : "reported";
  j["channel"] = Json{{"loss_probability", s.sc.channel.loss_probability},
                      {"min_delay_ms", s.sc.channel.min_delay_ms},
                      {"max_delay_ms", s.sc.channel.max_delay_ms},
                      {"corrupt_probability", s.sc.channel.corrupt_probability}};
  // the supervision is the on-board unit's (br::PatternCalculator with the train type's data and
  // spec/parameters/br.yaml)
  j["supervision"] = Json{{"by", "on-board unit (br patterns)"},
                          {"cycle_ms", params::br::cycle_ms},
                          {"service_offset_m", ToM(params::br::service_offset_mm)}};
  std::uint64_t nviol = 0;
  for (const auto& [id, c] : s.checks) {
    nviol += c.violations;
  }
  j["result"] = nviol == 0 ? "PASS" : "FAIL";
  j["violations"] = nviol;
  std::set<std::string> reqs = s.exercised;
  for (const auto& [id, c] : s.checks) {
    if (c.checks > 0) {
      reqs.insert(id);
    }
  }
  if (s.ground_cycles > 0) {
    reqs.insert("REQ-MB-010");
    reqs.insert("REQ-MB-018");
  }
  Json req = Json::array();
  for (const auto& r : reqs) {
    if (r.rfind("REQ-", 0) == 0) {
      req.push_back(r);
    }
  }
  j["requirements"] = req;
  Json asm_ = Json::array();
  for (const auto& r : reqs) {
    if (r.rfind("ASM-", 0) == 0) {
      asm_.push_back(r);
    }
  }
  j["assumptions_checked"] = asm_;
  Json checks = Json::object();
  for (const auto& [id, c] : s.checks) {
    checks[id] = Json{{"checks", c.checks}, {"violations", c.violations}, {"violation_steps", c.violation_steps}};
  }
  j["checks"] = checks;
  Json vl = Json::array();
  for (std::size_t i = 0; i < s.violations.size() && i < 50; ++i) {
    vl.push_back(Json{{"t_s", ToS(s.violations[i].t_ms)}, {"requirement", s.violations[i].requirement},
                      {"detail", s.violations[i].detail}});
  }
  j["violation_list"] = vl;

  Json trains = Json::array();
  std::size_t entered = 0;
  std::size_t exited = 0;
  std::int64_t last_exit = -1;
  double total_km = 0.0;
  for (const auto& t : s.trains) {
    entered += t->entered_ms >= 0 ? 1U : 0U;
    exited += t->exited_ms >= 0 ? 1U : 0U;
    last_exit = std::max(last_exit, t->exited_ms);
    const double dist = t->entered_ms >= 0 ? t->motion.position - t->start_m : 0.0;
    total_km += dist / 1000.0;
    trains.push_back(Json{{"id", t->spec.id},
                          {"phase", ToString(t->phase)},
                          {"entered_s", t->entered_ms >= 0 ? Json(ToS(t->entered_ms)) : Json(nullptr)},
                          {"exited_s", t->exited_ms >= 0 ? Json(ToS(t->exited_ms)) : Json(nullptr)},
                          {"front_m", R1(t->motion.position)},
                          {"distance_m", R1(dist)},
                          {"max_speed_kmh", R1(t->max_speed * 3.6)},
                          {"stops_made", t->stops_made},
                          {"emergency_brakes", t->emergency_brakes},
                          {"service_brakes", t->service_brakes},
                          {"nominal_front_max_lead_m", R2(t->max_lead_m)},
                          {"true_front_max_outside_envelope_m", R2(t->max_outside_m)},
                          {"train_type", t->type->name},
                          {"standstill_without_authority_s", ToS(t->standstill_no_authority_ms)},
                          {"reports_sent", t->reports_sent},
                          {"reports_accepted", t->reports_accepted}});
  }
  j["trains"] = trains;
  j["progress"] = Json{{"trains_entered", entered},
                       {"trains_left_line", exited},
                       {"last_departure_from_line_s", last_exit >= 0 ? Json(ToS(last_exit)) : Json(nullptr)},
                       {"train_km", R2(total_km)}};
  const auto dir = [&](Direction d, const DirStats& ds) {
    const ChannelStats& cs = s.channel.Stats(d);
    Json rej = Json::object();
    for (const auto& [k, v] : ds.rejected) {
      rej[k] = v;
    }
    return Json{{"sent", cs.sent},           {"lost_random", cs.lost_random}, {"lost_fault", cs.lost_fault},
                {"corrupted", cs.corrupted}, {"delivered", cs.delivered},     {"accepted", ds.accepted},
                {"rejected", rej},           {"malformed_payload", ds.malformed}};
  };
  j["radio"] = Json{{"uplink", dir(Direction::kUplink, s.up)}, {"downlink", dir(Direction::kDownlink, s.down)}};
  Json rs = Json::object();
  for (const auto& [k, v] : s.report_status) {
    rs[k] = v;
  }
  Json vs = Json::object();
  for (const auto& [k, v] : s.verdicts) {
    vs[k] = v;
  }
  j["ground"] = Json{{"cycles", s.ground_cycles},
                     {"stop_limit_telegrams", s.telegrams_issued},
                     {"reports", rs},
                     {"tracking_abnormal_events", s.abnormal_events}};
  if (s.waysides.size() > 1) {
    // the split line: its units and the trains one released to the next
    j["ground"]["wayside_units"] = s.waysides.size();
    j["ground"]["handovers"] = s.handovers;
  }
  Json br = Json::object();
  for (const auto& [k, v] : s.brake_reasons) {
    br[k] = v;
  }
  j["onboard"] = Json{{"stop_limit_verdicts", vs}, {"brake_demand_cycles", br}};
  Json xs = Json::array();
  for (const auto& x : s.crossings) {
    xs.push_back(Json{{"crossing", x.name},
                      {"warning_time_s", ToS(x.warning_time_ms)},
                      {"warnings", x.warnings},
                      {"passages", x.passages},
                      {"shortest_warning_before_passage_s",
                       x.passages > 0 ? Json(R1(x.shortest_warning_s)) : Json(nullptr)}});
  }
  j["crossings"] = xs;
  j["train_data_findings"] = s.train_data_findings;
  const auto after = [](const std::optional<std::int64_t>& at, std::int64_t ref) {
    return at ? Json(ToS(*at - ref)) : Json(nullptr);
  };
  Json faults = Json::array();
  for (const auto& f : s.faults) {
    Json fj{{"type", ToString(f.spec.type)}, {"from_s", ToS(f.spec.from_ms)}, {"to_s", ToS(f.spec.to_ms)}};
    switch (f.spec.type) {
      case FaultType::kRadioLoss:
      case FaultType::kTrackingLoss:
        fj["train"] = *f.spec.train;
        fj["abnormal_after_s"] = after(f.abnormal_at, f.spec.from_ms);
        fj["standstill_after_s"] = after(f.standstill_at, f.spec.from_ms);
        fj["tracked_again_after_end_s"] = after(f.tracked_again_at, f.spec.to_ms);
        fj["moving_again_after_end_s"] = after(f.moving_again_at, f.spec.to_ms);
        break;
      case FaultType::kPossession:
        fj["range_m"] = {ToM(f.spec.begin_mm), ToM(f.spec.end_mm)};
        fj["request_status"] = f.status;
        fj["active_after_s"] = after(f.active_at, f.spec.from_ms);
        break;
      case FaultType::kSidingRequest:
        fj["route"] = s.SidingRoute(f.spec);
        fj["request_status"] = f.status;
        fj["set_after_s"] = after(f.active_at, f.spec.from_ms);
        fj["freed_after_end_s"] = after(f.freed_at, f.spec.to_ms);
        break;
      case FaultType::kSpeedRestriction:
        fj["range_m"] = {ToM(f.spec.begin_mm), ToM(f.spec.end_mm)};
        fj["speed_kmh"] = R1(f.spec.speed_mps * 3.6);
        fj["request_status"] = f.status;
        break;
    }
    faults.push_back(fj);
  }
  j["faults"] = faults;
  if (const auto g = Gap()) {
    j["gap"] = Json{{"leader", g->leader},
                    {"follower", g->follower},
                    {"window_s", {g->from_s, g->to_s}},
                    {"samples", g->samples},
                    {"settled_gap_m", R1(g->mean_m)},
                    {"min_m", R1(g->min_m)},
                    {"max_m", R1(g->max_m)},
                    {"std_m", R1(g->std_m)},
                    {"series_columns", {"t_s", "gap_m", "follower_kmh", "permitted_kmh", "limit_to_supervised_front_m",
                                        "leader_rear_to_limit_m", "supervised_to_true_front_m"}},
                    {"series", s.gap_series},
                    {"leader_speed_kmh", R1(g->leader_speed_kmh)},
                    {"follower_speed_kmh", R1(g->follower_speed_kmh)}};
  } else {
    j["gap"] = nullptr;
  }
  j["events"] = s.events;
  return j;
}

}  // namespace railproof::sim
