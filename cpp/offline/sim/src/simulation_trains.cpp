// Line scenario simulation: the trains: entry and exit, the on-board unit's cycle, the driver
// and the brake equipment, the true motion (dynamics.hpp, or the wheel-rail vehicle where the
// scenario has low adhesion: wheel_rail_train.hpp) and the sensors (sensors.hpp)
// (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "railproof/generated/ra_params.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"

namespace railproof::sim {

double Simulation::Impl::MeanGradient(double rear_m, double front_m) const {
  return rl->MeanGradientPermille(rear_m * 1000.0, front_m * 1000.0);
}

double Simulation::Impl::MotionGradient(double rear_m, double front_m) const {
  return MeanGradient(rear_m, front_m) + rl->MeanCurveResistancePermille(rear_m * 1000.0, front_m * 1000.0);
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
      const auto prot = ProtectedAuthority(u->spec.id);
      if (prot && *prot > rear - m) {
        return false;
      }
      const auto lim = u->Out() != nullptr ? u->Out()->authority_limit_mm : std::nullopt;
      if (lim && *lim > rear - m) {
        return false;
      }
    }
  }
  return true;
}

// The on-board unit of a train starting (or restarting) with its front at `front_mm` (the
// entry balise's fix): the train type's braking data, the odometry on the line's sections, the
// track database, the crossing protection and the radio link to the wayside unit.
void Simulation::Impl::CreateUnit(TrainRt& t, std::int64_t front_mm) {
  units::OnboardConfig c;
  c.train_id = t.spec.id;
  c.train = ToTrainData(*t.type);
  c.odometry.length_correction_ppm = mbp::length_correction_ppm;
  // Ta never below its floor on the line's sections (the sensor model puts gravity into a_x)
  c.odometry.detect_threshold_mm_s2 =
      std::max(c.odometry.detect_threshold_mm_s2,
               ra::DetectThresholdFloorMmS2(obl.sections.data(), static_cast<int>(obl.sections.size())));
  c.initial_front_mm = front_mm;
  c.line = units::LineData{obl.blocks_mm, obl.gradients, t.limits, obl.balises, obl.crossings, obl.sections};
  c.crossing = lc::onboard::DefaultProtectionConfig(t.spec.id, t.length_mm, c.train.accel_max_mm_s2);
  c.radio = tg::DeploymentConfig(tg::Role::kTrain, t.spec.id, kGroundId);
  c.radio_areas = radio_areas;
  c.link_key.emplace(t.key);
  c.radio_period_ms = sc.report_period_ms;
  // spread the trains' telegrams over the period
  c.radio_offset_ms = (static_cast<std::int64_t>(t.spec.id) * sc.step_ms) % sc.report_period_ms;
  auto created = units::OnboardUnit::Create(c);
  if (created.check.error != units::OnboardConfigError::kNone) {
    throw InputError(sc.file + ": " + t.spec.entry + ": the on-board unit refuses its configuration: " +
                     units::ToString(created.check.error) + " (entry " + std::to_string(created.check.entry) + ")");
  }
  t.unit = std::make_unique<units::OnboardUnit>(std::move(*created.unit));
  SensorConfig s;
  s.length_correction_ppm = mbp::length_correction_ppm;
  s.nominal_wheel_diameter_um = c.odometry.wheel_diameter_um;
  s.seed = sc.seed ^ (0x5E5E5E5E00000000ULL + t.spec.id * 0x9E3779B97F4A7C15ULL);
  t.sensors = std::make_unique<SensorModel>(s);
  t.inbox.clear();
  t.handover_inbox.clear();
  t.driver = {};
  t.next_balise.reset();
  t.next_balise_index = 0;
  while (t.next_balise_index < rl->balises.size() && rl->balises[t.next_balise_index].position_mm <= front_mm) {
    ++t.next_balise_index;
  }
  Sense(t, now, t.motion, 0.0);
}

void Simulation::Impl::Enter(TrainRt& t) {
  const WaysideRt& w = waysides[WaysideAt(t.spec.initial_front_mm)];
  const auto admitted = w.unit->Admit(t.spec.id, t.spec.id);
  const mb::wayside::TrainRegistration reg{t.spec.id, t.length_mm, t.spec.initial_front_mm - w.origin_mm, 0,
                                           mb::wayside::InitialPosition::kEntryBalise};
  const auto st = admitted == units::AdmitStatus::kAdmitted ? w.unit->Register(reg) : units::RegisterResult{};
  if (admitted != units::AdmitStatus::kAdmitted || st.status != units::RegisterStatus::kRegistered) {
    throw InputError(sc.file + ": " + t.spec.entry + ": the wayside unit refuses the train (" +
                     units::ToString(admitted) + ", " + units::ToString(st.status) + ", ground " +
                     std::to_string(static_cast<int>(st.ground)) + ")");
  }
  t.phase = Phase::kStanding;
  t.entered_ms = now;
  t.motion = Motion{ToM(t.spec.initial_front_mm), 0.0};
  t.start_m = t.motion.position;
  if (sc.OnWheelRail(t.spec.id)) {
    t.wheel_rail = MakeWheelRailTrain(sc, t.spec, *rl, t.motion.position);
  }
  CreateUnit(t, t.spec.initial_front_mm);
  Emit(Json{{"ev", "enter"}, {"train", t.spec.id}, {"front_mm", t.spec.initial_front_mm}, {"length_mm", t.length_mm},
            {"train_type", t.type->name}});
}

void Simulation::Impl::Exit(TrainRt& t, const std::string& why) {
  for (const WaysideRt& w : waysides) {
    (void)w.unit->Remove(t.spec.id);
  }
  channel.Purge(t.spec.id);
  t.phase = Phase::kExited;
  t.exited_ms = now;
  t.motion.speed = 0.0;
  Emit(Json{{"ev", "exit"}, {"train", t.spec.id}, {"front_mm", t.FrontMm()}, {"reason", why}});
}

void Simulation::Impl::Sense(TrainRt& t, std::int64_t end_ms, const Motion& start, double accel,
                             const std::optional<AxleMotion>& axle) {
  TrueCycle c;
  c.time_ms = end_ms;
  c.start = start;
  c.accel_mps2 = accel;
  // the IMU rides on the car whose motion it is: the wheel-rail vehicle's, or the train's
  const double length = t.wheel_rail ? t.wheel_rail->CarLengthM() : t.spec.performance.length_m;
  c.gradient_permille = MeanGradient(start.position - length, start.position);
  c.axle = axle;
  t.next_sensors = t.sensors->Cycle(c);
}

double Simulation::Impl::Move(TrainRt& t, double a, double dt, std::optional<AxleMotion>& axle) {
  if (!t.wheel_rail) {
    t.motion = offline::Advance(t.motion, a, dt);
    return a;
  }
  const WheelRailStep w = t.wheel_rail->Step(t.applied_mps2, ToS(now), dt);
  t.motion = w.end;
  axle = w.axle;
  if (w.state != t.axle_state) {
    t.axle_state = w.state;
    Emit(Json{{"ev", "axle"}, {"train", t.spec.id}, {"state", ToString(w.state)}, {"creep", R2(w.creep)},
              {"speed_mps", R2(w.end.speed)}, {"axle_speed_mps", R2(w.axle.speed_mps + w.axle.accel_mps2 * dt)},
              {"front_mm", t.FrontMm()}});
  }
  return w.accel_mps2;
}

// One cycle of the train's on-board unit with what reached it since the last one; its
// telegram goes to the channel.
void Simulation::Impl::OnboardCycle(TrainRt& t) {
  std::vector<std::span<const std::uint8_t>> frames(t.inbox.begin(), t.inbox.end());
  std::vector<std::span<const std::uint8_t>> handover_frames(t.handover_inbox.begin(), t.handover_inbox.end());
  units::OnboardInputs in;
  in.now_ms = now;
  in.sensors = t.next_sensors;
  if (t.position_lost) {
    in.sensors.imu_count = 0;  // the injected sensor failure: the odometry stops (REQ-RA-013)
  }
  in.balise_id = std::exchange(t.next_balise, std::nullopt);
  in.frames = frames;
  in.handover_frames = handover_frames;
  in.driver = t.driver;
  if (t.phase == Phase::kDwelling) {
    in.dwell_departure_ms = t.dwell_until_ms;
  }
  const auto before_limit = t.Out() != nullptr ? t.Out()->authority_limit_mm : std::nullopt;
  const auto before_kind = t.Out() != nullptr ? t.Out()->indications.obstruction : messages::Obstruction::kNone;
  const auto before_governs = t.Out() != nullptr ? t.Out()->indications.limit_kind : units::LimitKind::kNone;
  const auto last_reason = t.Out() != nullptr ? t.Out()->reason : units::BrakeReason::kNone;
  const auto last_mode = t.unit->Odometry().mode;
  const units::OnboardOutputs& o = t.unit->Cycle(in);
  t.inbox.clear();
  t.handover_inbox.clear();
  for (const units::RxEvent& e : o.Events()) {
    switch (e.status) {
      case units::RxStatus::kFrameRejected:
        ++down.rejected[tg::ToString(e.reject)];
        Emit(Json{{"ev", "telegram_rejected"}, {"dir", "down"}, {"train", t.spec.id}, {"reason", tg::ToString(e.reject)}});
        break;
      case units::RxStatus::kUndecodable:
      case units::RxStatus::kOtherTrain:
      case units::RxStatus::kUnexpectedType: ++down.malformed; break;
      case units::RxStatus::kAccepted:
      case units::RxStatus::kStopLimitRefused:
        down.accepted += e.entry == 0 ? 1U : 0U;
        if (e.type == messages::MessageType::kStopLimit) {
          ++verdicts[mb::onboard::ToString(e.verdict)];
        }
        break;
      case units::RxStatus::kMessageDropped:
      case units::RxStatus::kFramesDropped: ++down.malformed; break;
    }
  }
  if (o.sent) {
    ++t.reports_sent;
    exercised.insert("REQ-MB-001");
    channel.Send(t.spec.id, Direction::kUplink, now, o.frame.View(), t.radio_blocked, o.radio_area);
  }
  if (o.handover_sent) {
    channel.Send(t.spec.id, Direction::kUplink, now, o.handover_frame.View(), t.radio_blocked, *o.handover_area);
  }
  const auto lim = o.authority_limit_mm;
  if (lim && (!before_limit || *lim < *before_limit || o.indications.obstruction != before_kind || Full())) {
    Emit(Json{{"ev", "limit"}, {"train", t.spec.id}, {"limit_mm", *lim},
              {"kind", messages::ToString(o.indications.obstruction)},
              {"previous_mm", before_limit ? Json(*before_limit) : Json(nullptr)}});
  }
  if (o.brake != units::BrakeDemand::kNone) {
    ++brake_reasons[units::ToString(o.reason)];
  }
  if (const ra::OdometryOutput& od = t.unit->Odometry(); od.mode != last_mode) {
    Emit(Json{{"ev", "odometry"}, {"train", t.spec.id}, {"mode", ra::ToString(od.mode)},
              {"stop_reason", ra::ToString(od.stop_reason)}, {"speed_mps", R2(t.motion.speed)},
              {"front_error_m", R2(ToM(od.front_error_mm))}, {"rear_error_m", R2(ToM(od.rear_error_mm))},
              {"nominal_lead_m", R2(ToM(od.front_mm) - t.motion.position)}, {"brake", static_cast<int>(t.brake)},
              {"ax_avg", R2(od.ax_avg)}, {"ap_avg", R2(od.ap_avg)}});
  }
  if (o.reason != last_reason && o.reason != units::BrakeReason::kServicePattern &&
      (o.reason != units::BrakeReason::kNone || last_reason != units::BrakeReason::kServicePattern)) {
    const ra::OdometryOutput& od = t.unit->Odometry();
    Emit(Json{{"ev", "brake_demand"}, {"train", t.spec.id}, {"demand", units::ToString(o.brake)},
              {"reason", units::ToString(o.reason)}, {"odometry", ra::ToString(od.mode)},
              {"odometry_stop", ra::ToString(od.stop_reason)}, {"speed_mps", R2(t.motion.speed)}});
  }
  if (o.indications.limit_kind != before_governs) {
    Emit(Json{{"ev", "governing_limit"}, {"train", t.spec.id}, {"kind", units::ToString(o.indications.limit_kind)},
              {"limit_mm", o.indications.limit_mm ? Json(*o.indications.limit_mm) : Json(nullptr)},
              {"crossing", o.indications.crossing_id}, {"speed_mps", R2(t.motion.speed)}});
  }
  if (o.indications.limit_kind == units::LimitKind::kCrossingProtection) {
    exercised.insert("REQ-LC-003");
  }
}

// The driver and the brake equipment. The unit's demand overrides the driver: SERVICE is the
// service brake at the unit's notch (7N: full), EMERGENCY the emergency brake held until
// standstill. Otherwise the driver
// aims at the indicated permitted speed less a driving margin (no traction while "pattern
// approaching" is shown), the scenario's speed cap and the station stop, and resets the
// supervision's latched emergency brake at standstill once the authority is usable again.
Control Simulation::Impl::Drive(TrainRt& t, const units::OnboardOutputs& o, double dt) {
  const TrainPerformance& p = t.spec.performance;
  const double v = t.motion.speed;
  const Brake prev = t.brake;
  Control c;
  t.driver = {};
  if (o.brake == units::BrakeDemand::kEmergency) {
    if (!t.eb_hold && v > 0.0) {
      ++t.emergency_brakes;
      Emit(Json{{"ev", "emergency_brake"}, {"train", t.spec.id}, {"speed_mps", R2(v)},
                {"reason", units::ToString(o.reason)},
                {"distance_to_limit_m", R2(ToM(o.indications.target_distance_mm))}});
    }
    t.eb_hold = v > 0.0;
  }
  if (t.eb_hold && v <= 0.0) {
    t.eb_hold = false;
  }
  if (t.eb_hold || o.brake == units::BrakeDemand::kEmergency) {
    t.brake = Brake::kEmergency;
    c.emergency = true;
  } else if (o.brake == units::BrakeDemand::kService) {
    t.brake = Brake::kService;
    c.brake_mps2 = p.service_decel_mps2 * br::ServiceNotchSevenths(o.level) / 7.0;  // graded as the unit asks
    if (prev != Brake::kService) {
      ++t.service_brakes;
    }
  } else {
    t.brake = Brake::kNone;
  }
  if (v <= 0.0 && o.level == br::BrakeLevel::kEmergency && o.authority_usable && o.link == tg::LinkState::kUp) {
    t.driver.handle_emergency = true;
    t.driver.reset = true;
  }
  if (t.brake != Brake::kNone) {
    return c;
  }
  if (t.phase != Phase::kRunning || !o.position_valid) {
    c.brake_mps2 = p.service_decel_mps2;  // standing, dwelling: the driver holds the train
    return c;
  }
  const double look = v * (dt + kDriverResponseS);  // the driver anticipates his response
  const double permitted = static_cast<double>(o.indications.permitted_speed_mm_s) / 1000.0;
  double target = std::min({p.max_speed_mps, t.spec.speed_cap_mps.value_or(p.max_speed_mps),
                            permitted - kDrivingMarginMps});
  if (t.next_stop < t.spec.stops.size()) {
    const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
    const double ds = ToM(st->stop_mm - o.front_mm);
    const double vs = ds > 0.5 ? std::max(kCreepMps, CurveSpeed(ds - 0.3 - look, kStationDecelShare * p.service_decel_mps2, 0.0))
                               : 0.0;
    target = std::min(target, vs);
  }
  target = std::max(0.0, target);
  if (target < 0.5 * kCreepMps && v < kCreepMps) {  // nothing worth moving for: stop and hold
    c.brake_mps2 = p.service_decel_mps2;  // stopping or standing: full service brake holds the train
    t.brake = Brake::kDriver;
    return c;
  }
  const double other =
      NetAcceleration(p, Control{}, v, MotionGradient(t.motion.position - p.length_m, t.motion.position));
  const double need = (target - v) / kDriverResponseS - other;  // applied acceleration needed
  if (need > 0.0) {
    c.traction_mps2 = std::min(need, p.accel_mps2);
  } else {
    c.brake_mps2 = std::min(-need, p.service_decel_mps2);
    t.brake = c.brake_mps2 > 0.0 ? Brake::kDriver : Brake::kNone;
  }
  return c;
}

// The traction and brake equipment: the applied acceleration (traction minus brake) follows the
// command at no more than kApplyRateMps3 (traction control and brake build-up); a standing
// train's holding brake is applied at once. Between the full service and the emergency brake
// the net acceleration is interpolated between the two (the same resistance and gravity).
double Simulation::Impl::Apply(TrainRt& t, const Control& c, double gradient, double dt) const {
  const TrainPerformance& p = t.spec.performance;
  const double wanted = c.emergency ? -p.emergency_decel_mps2
                                    : std::min(c.traction_mps2, p.accel_mps2) - std::min(c.brake_mps2, p.service_decel_mps2);
  const double step = kApplyRateMps3 * dt;
  const bool holding = t.motion.speed <= 0.0 && wanted <= 0.0;
  t.applied_mps2 = holding ? wanted : std::clamp(wanted, t.applied_mps2 - step, t.applied_mps2 + step);
  const double v = t.motion.speed;
  if (t.applied_mps2 >= -p.service_decel_mps2) {
    return NetAcceleration(p, Control{std::max(t.applied_mps2, 0.0), std::max(-t.applied_mps2, 0.0), false}, v,
                           gradient);
  }
  const double service = NetAcceleration(p, Control{0.0, p.service_decel_mps2, false}, v, gradient);
  const double emergency = NetAcceleration(p, Control{0.0, 0.0, true}, v, gradient);
  const double share = (-t.applied_mps2 - p.service_decel_mps2) / (p.emergency_decel_mps2 - p.service_decel_mps2);
  return service + share * (emergency - service);
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
    // The re-fix after a tracking loss, or after the odometry stopped (it waits for a balise
    // the standing train cannot reach): the unit restarts at the train's position and the
    // train registers again (as at an entry balise, REQ-MB-016). A stand-in for the operating
    // procedure (spec/design/sim.md).
    const bool refix_due = t.odometry_stopped_ms >= kRefixAfterMs;
    if ((t.was_position_lost && !t.position_lost && t.motion.speed <= 0.0) || refix_due) {
      t.odometry_stopped_ms = 0;
      for (const WaysideRt& w : waysides) {
        (void)w.unit->Remove(t.spec.id);
      }
      channel.Purge(t.spec.id);
      const WaysideRt& w = waysides[WaysideAt(t.FrontMm())];
      (void)w.unit->Admit(t.spec.id, t.spec.id);
      const auto st = w.unit->Register(mb::wayside::TrainRegistration{
          t.spec.id, t.length_mm, t.FrontMm() - w.origin_mm, 0, mb::wayside::InitialPosition::kEntryBalise});
      CreateUnit(t, t.FrontMm());
      Emit(Json{{"ev", "refix"}, {"train", t.spec.id}, {"front_mm", t.FrontMm()},
                {"status", units::ToString(st.status)}});
    }
    t.was_position_lost = t.position_lost;
    OnboardCycle(t);
    const units::OnboardOutputs& o = *t.Out();
    const bool stopped = t.unit->Odometry().mode == ra::Mode::kStopped &&
                         t.unit->Odometry().stop_reason != ra::StopReason::kStartUp;
    t.odometry_stopped_ms = stopped && !t.position_lost && t.motion.speed <= 0.0 ? t.odometry_stopped_ms + sc.step_ms : 0;
    const Control c = Drive(t, o, dt);
    const double grad = MotionGradient(t.Rear(), t.motion.position);
    const double a = Apply(t, c, grad, dt);
    const Motion before = t.motion;
    t.previous_front_m = before.position;
    std::optional<AxleMotion> axle;
    const double achieved = Move(t, a, dt, axle);
    // a balise the true front passed is read in the next cycle
    while (t.next_balise_index < rl->balises.size() &&
           t.FrontMm() >= rl->balises[t.next_balise_index].position_mm) {
      t.next_balise = static_cast<std::uint32_t>(t.next_balise_index + 1);
      if (Full()) {
        Emit(Json{{"ev", "balise"}, {"train", t.spec.id}, {"balise", rl->balises[t.next_balise_index].id}});
      }
      ++t.next_balise_index;
    }
    Sense(t, now + sc.step_ms, before, achieved, axle);
    t.max_speed = std::max(t.max_speed, t.motion.speed);
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && !o.authority_usable) {
      t.standstill_no_authority_ms += sc.step_ms;
    }
    // station arrival (the driver sees the unit's position)
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop < t.spec.stops.size()) {
      const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
      const double ds = ToM(st->stop_mm - o.front_mm);
      if (ds <= kStopWindowM) {
        t.phase = Phase::kDwelling;
        t.dwell_until_ms = now + sc.step_ms + t.spec.stops[t.next_stop].dwell_ms;
        ++t.stops_made;
        Emit(Json{{"ev", "arrive"}, {"train", t.spec.id}, {"station", st->name},
                  {"stop_error_m", R2(t.motion.position - ToM(st->stop_mm))}});
      }
    }
    // end of the line: standing before the end of track (or a boundary no neighbour
    // accepts) with no stop left, it leaves the area (removed from the wayside unit)
    const auto kind = o.indications.obstruction;
    const bool last_unit = o.radio_area + 1 == waysides.size();  // a split's boundary is no line end
    const bool at_end = kind == messages::Obstruction::kEndOfTrack ||
                        (kind == messages::Obstruction::kSystemBoundary && last_unit);
    if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop >= t.spec.stops.size() && at_end &&
        o.indications.limit_mm && ToM(o.indications.target_distance_mm) <= kExitWindowM) {
      t.standing_at_end_ms += sc.step_ms;
      if (t.standing_at_end_ms >= 5000) {
        Exit(t, kind == messages::Obstruction::kEndOfTrack ? "end of line" : "at the system boundary");
      }
    } else {
      t.standing_at_end_ms = 0;
    }
  }
}

}  // namespace railproof::sim
