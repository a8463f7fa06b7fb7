// Line scenario simulation: the trains: entry and exit, driving (line speed, supervision
// stand-in, station stops), the train-motion model (dynamics.hpp) and odometry
// (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace railproof::sim {

double Simulation::Impl::MeanGradient(double rear_m, double front_m) const {
  const std::int64_t a = std::max<std::int64_t>(0, ToMm(rear_m));
  const std::int64_t b = std::min(rl->length_mm, std::max(a + 1, ToMm(front_m)));
  double sum = 0.0;
  for (const auto& g : rl->gradients) {
    const std::int64_t lo = std::max(a, g.section.begin_mm);
    const std::int64_t hi = std::min(b, g.section.end_mm);
    if (hi > lo) {
      sum += static_cast<double>(hi - lo) * static_cast<double>(g.permille_x10) / 10.0;
    }
  }
  return b > a ? sum / static_cast<double>(b - a) : static_cast<double>(rl->GradientAt(a)) / 10.0;
}

double Simulation::Impl::SteepestFall(double a_m, double b_m) const {
  const std::int64_t a = ToMm(a_m);
  const std::int64_t b = std::max(a + 1, ToMm(b_m));
  double fall = 0.0;
  for (const auto& g : rl->gradients) {
    if (g.section.begin_mm < b && a < g.section.end_mm) {
      fall = std::max(fall, -static_cast<double>(g.permille_x10) / 10.0);
    }
  }
  return fall;
}

std::int64_t Simulation::Impl::CorrectionMm(const TrainRt& t) const {
  const double odo_m = std::max(0.0, t.est_front_m - t.balise_est_m);
  return static_cast<std::int64_t>(std::ceil(odo_m * 1000.0 * static_cast<double>(mbp::length_correction_ppm) / 1e6));
}

bool Simulation::Impl::EntryClear(const TrainRt& n) const {
  const std::int64_t front = n.spec.initial_front_mm;
  const std::int64_t rear = front - n.length_mm;
  const std::int64_t m = mbp::margin_preceding_train_mm;
  for (const auto& u : trains) {
    if (u.get() == &n || !u->OnLine()) {
      continue;
    }
    if (core::Overlaps(rear - m, front + m, u->RearMm(), u->FrontMm())) {
      return false;
    }
    if (u->FrontMm() <= front) {
      const auto prot = ground->ProtectedAuthority(u->spec.id);
      if (prot && *prot > rear - m) {
        return false;
      }
      const auto lim = u->auth.Limit();
      if (lim && *lim > rear - m) {
        return false;
      }
    }
  }
  return true;
}

void Simulation::Impl::Enter(TrainRt& t) {
  const mb::wayside::TrainRegistration reg{t.spec.id, t.length_mm, t.spec.initial_front_mm, 0,
                                       mb::wayside::InitialPosition::kEntryBalise};
  const auto st = ground->RegisterTrain(reg);
  if (st != mb::wayside::RegisterStatus::kRegistered) {
    throw InputError(sc.file + ": " + t.spec.entry + ": the ground refuses the train registration (status " +
                     std::to_string(static_cast<int>(st)) + ")");
  }
  auto tc = tg::DeploymentConfig(tg::Role::kTrain, t.spec.id, kGroundId);
  auto gc = tg::DeploymentConfig(tg::Role::kGround, kGroundId, t.spec.id);
  if (t.train_ep.Init(tc, *t.key) != tg::ConfigError::kNone || t.ground_ep.Init(gc, *t.key) != tg::ConfigError::kNone) {
    throw std::runtime_error("radio endpoint initialisation failed (crypto unavailable?)");
  }
  t.phase = Phase::kStanding;
  t.entered_ms = now;
  t.motion = Motion{ToM(t.spec.initial_front_mm), 0.0};
  t.est_front_m = t.motion.position;
  t.balise_est_m = t.est_front_m;
  t.balise_true_m = t.motion.position;
  t.last_balise_mm = t.spec.initial_front_mm;
  t.odo_error = -kOdometryErrorShare * static_cast<double>(mbp::length_correction_ppm) / 1e6 * odo_prng.Uniform();
  t.next_balise = 0;
  while (t.next_balise < rl->balises.size() && rl->balises[t.next_balise].position_mm <= t.spec.initial_front_mm) {
    ++t.next_balise;
  }
  t.start_m = t.motion.position;
  // spread the report instants of the trains over the period
  t.next_report_ms = now + (static_cast<std::int64_t>(t.spec.id) * sc.step_ms) % sc.report_period_ms;
  Emit(Json{{"ev", "enter"}, {"train", t.spec.id}, {"front_mm", t.spec.initial_front_mm}, {"length_mm", t.length_mm}});
}

void Simulation::Impl::Exit(TrainRt& t, const std::string& why) {
  ground->RemoveTrain(t.spec.id);
  channel.Purge(t.spec.id);
  t.phase = Phase::kExited;
  t.exited_ms = now;
  t.motion.speed = 0.0;
  Emit(Json{{"ev", "exit"}, {"train", t.spec.id}, {"front_mm", t.FrontMm()}, {"reason", why}});
}

double Simulation::Impl::LineSpeed(const TrainRt& t, double safe_front, double rear, double b, double look) const {
  double v = std::numeric_limits<double>::infinity();
  const double front = safe_front + look;
  const auto limit_mps = [](const SpeedLimit& s) { return static_cast<double>(s.kmh) / 3.6; };
  rl->ForEachLimitActing(rear, front, [&](std::size_t i) { v = std::min(v, limit_mps(rl->speed_limits[i])); }, 1000.0);
  for (const auto& s : rl->speed_limits) {
    const double begin = ToM(s.section.begin_mm);
    if (begin > front) {  // ahead: the speed from which braking with b reaches the limit at its begin
      v = std::min(v, SpeedAfter(limit_mps(s), b, begin - front));
    }
  }
  const auto front_mm = ToMm(t.est_front_m);
  if (const auto tsr = t.tsr.ApplicableSpeed(front_mm, t.length_mm)) {
    v = std::min(v, static_cast<double>(*tsr) / 1000.0);
  }
  for (const auto& r : t.tsr.Held()) {
    const double begin = ToM(r.begin_mm);
    const double lim = static_cast<double>(r.speed_mm_s) / 1000.0;
    if (begin >= front) {
      v = std::min(v, SpeedAfter(lim, b, begin - front));
    } else if (rear < ToM(r.end_mm)) {
      v = std::min(v, lim);
    }
  }
  return v;
}

Control Simulation::Impl::Drive(TrainRt& t, double dt) {
  const TrainPerformance& p = t.spec.performance;
  const double v = t.motion.speed;
  const double corr = ToM(CorrectionMm(t));
  const double safe_front = t.est_front_m + corr;
  const double rear = t.est_front_m - p.length_m - corr;
  t.link_up = t.train_ep.Link() == tg::LinkState::kUp;
  const bool usable = t.auth.Usable(now) && t.link_up;
  Control c;
  const auto limit_mm = t.auth.Limit();
  if (!usable || !limit_mm) {
    // no usable authority (none yet, expired, or radio link down): standstill demanded
    if (!t.eb && v > 0.0) {
      ++t.emergency_brakes;
      Emit(Json{{"ev", "emergency_brake"}, {"train", t.spec.id}, {"speed_mps", R2(v)},
                {"reason", !t.link_up ? "radio link not up" : "no usable authority"}});
      exercised.insert("REQ-MB-009");
    }
    t.eb = true;
    c.emergency = true;
    return c;
  }
  const double limit = ToM(*limit_mm);
  const double d = limit - safe_front;
  const double fall = SteepestFall(safe_front, std::max(safe_front, limit) + 1.0);
  const double bs = std::max(0.05, p.service_decel_mps2 - GradeDecel(fall));
  const double be = std::max(0.05, p.emergency_decel_mps2 - GradeDecel(fall));
  const double v_e = CurveSpeed(d, be, sc.supervision.emergency_free_running_s);
  if (v > v_e + 1e-9 && !t.eb) {
    ++t.emergency_brakes;
    t.eb = true;
    Emit(Json{{"ev", "emergency_brake"}, {"train", t.spec.id}, {"speed_mps", R2(v)}, {"reason", "emergency curve exceeded"},
              {"distance_to_limit_m", R2(d)}});
  }
  if (t.eb) {
    if (v > 0.0) {
      c.emergency = true;
      return c;
    }
    t.eb = false;  // standstill with a usable authority: released
  }
  if (t.position_lost || t.phase == Phase::kStanding || t.phase == Phase::kDwelling) {
    c.brake_mps2 = p.service_decel_mps2;  // hold / brake to a stop
    return c;
  }
  // running: target speed for the end of this step
  const double look = v * dt;
  double target = std::min(p.max_speed_mps, t.spec.speed_cap_mps.value_or(p.max_speed_mps));
  target = std::min(target, LineSpeed(t, safe_front, rear, bs, look));
  target = std::min(target, CurveSpeed(d - sc.supervision.margin_m - look, bs, sc.supervision.free_running_s));
  if (t.next_stop < t.spec.stops.size()) {
    const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
    const double ds = ToM(st->stop_mm) - t.est_front_m;
    const double vs = ds > 0.5 ? std::max(kCreepMps, CurveSpeed(ds - 0.3 - look, kStationDecelShare * bs, 0.0)) : 0.0;
    target = std::min(target, vs);
  }
  target = std::max(0.0, target);
  if (target < 0.01 && v < 0.5) {
    c.brake_mps2 = p.service_decel_mps2;  // stopping or standing: full service brake holds the train
    return c;
  }
  const double other = NetAcceleration(p, Control{}, v, MeanGradient(t.motion.position - p.length_m, t.motion.position));
  const double need = (target - v) / dt - other;  // applied acceleration needed
  if (need > 0.0) {
    c.traction_mps2 = std::min(need, p.accel_mps2);
  } else {
    c.brake_mps2 = std::min(-need, p.service_decel_mps2);
  }
  return c;
}

void Simulation::Impl::EnterTrains() {
  for (auto& tp : trains) {
    TrainRt& t = *tp;
    if (t.phase == Phase::kPending && now >= t.spec.enter_ms) {
      if (EntryClear(t)) {
        Enter(t);
      } else if (!t.deferral_logged) {
        t.deferral_logged = true;
        Emit(Json{{"ev", "entry_deferred"}, {"train", t.spec.id}});
      }
    }
  }
}

void Simulation::Impl::MoveTrains() {
  const double dt = ToS(sc.step_ms);
  for (auto& tp : trains) {
    TrainRt& t = *tp;
    if (!t.OnLine()) {
      continue;
    }
    // phase transitions at t
    if (t.phase == Phase::kStanding && now >= t.spec.depart_ms) {
      t.phase = Phase::kRunning;
      Emit(Json{{"ev", "depart"}, {"train", t.spec.id}});
    }
    if (t.phase == Phase::kDwelling && now >= t.dwell_until_ms) {
      ++t.next_stop;
      t.phase = Phase::kRunning;
      Emit(Json{{"ev", "depart"}, {"train", t.spec.id}});
      if (t.next_stop >= t.spec.stops.size()) {
        Exit(t, "terminus (last stop)");
        continue;
      }
    }
    const Control c = Drive(t, dt);
    const double grad = MeanGradient(t.motion.position - t.spec.performance.length_m, t.motion.position);
    const double a = NetAcceleration(t.spec.performance, c, t.motion.speed, grad);
    const Motion before = t.motion;
    t.motion = offline::Advance(before, a, dt);
    const double moved = t.motion.position - before.position;
    // odometry: under-reads by odo_error; a balise passed resets it
    t.est_front_m += moved * (1.0 + t.odo_error);
    while (t.next_balise < rl->balises.size() && ToMm(t.motion.position) >= rl->balises[t.next_balise].position_mm) {
      const auto& b = rl->balises[t.next_balise];
      const double beyond = t.motion.position - ToM(b.position_mm);
      t.odo_error = -kOdometryErrorShare * static_cast<double>(mbp::length_correction_ppm) / 1e6 * odo_prng.Uniform();
      t.balise_est_m = ToM(b.position_mm);
      t.balise_true_m = ToM(b.position_mm);
      t.est_front_m = std::max(t.est_front_m, t.balise_est_m + beyond * (1.0 + t.odo_error));
      t.last_balise_mm = b.position_mm;
      ++t.next_balise;
      if (Full()) {
        Emit(Json{{"ev", "balise"}, {"train", t.spec.id}, {"balise", b.id}});
      }
    }
    t.max_speed = std::max(t.max_speed, t.motion.speed);
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && (t.eb || !t.auth.Usable(now))) {
      t.standstill_no_authority_ms += sc.step_ms;
    }
    // station arrival
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop < t.spec.stops.size()) {
      const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
      const double ds = ToM(st->stop_mm) - t.est_front_m;
      if (ds <= kStopWindowM) {
        t.phase = Phase::kDwelling;
        t.dwell_until_ms = now + sc.step_ms + t.spec.stops[t.next_stop].dwell_ms;
        ++t.stops_made;
        Emit(Json{{"ev", "arrive"}, {"train", t.spec.id}, {"station", st->name}, {"stop_error_m", R2(-ds)}});
      }
    }
    // beyond an accepted system boundary: handed over to the neighbour once its rear has
    // passed the boundary (until then it obstructs like any train)
    if (rl->system_boundary_mm && sc.boundary_accepted && t.RearMm() >= *rl->system_boundary_mm) {
      Exit(t, "crossed the system boundary");
      continue;
    }
    // end of the line: leaves the area (removed from the ground)
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop >= t.spec.stops.size() &&
        t.limit_kind == messages::Obstruction::kEndOfTrack && t.auth.Limit()) {
      const double d = ToM(*t.auth.Limit()) - t.est_front_m - ToM(CorrectionMm(t));
      if (d <= sc.supervision.margin_m + kExitWindowM) {
        Exit(t, "end of line");
      }
    }
  }
}

}  // namespace railproof::sim
