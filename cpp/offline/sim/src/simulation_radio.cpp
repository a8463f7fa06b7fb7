// Line scenario simulation: the units' telegram frames through the channel, the wayside
// unit's ground cycle and the level crossings' equipment it drives (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <span>
#include <string>
#include <vector>

namespace railproof::sim {

void Simulation::Impl::DeliverFrames() {
  for (Frame& f : channel.Deliver(now)) {
    TrainRt* t = Find(f.train);
    if (t == nullptr || !t->OnLine()) {
      continue;
    }
    if (f.direction == Direction::kDownlink) {
      // read by the on-board unit in its cycle at now, on the link of the unit that sent it
      // (none: a link the train has dropped)
      const units::OnboardOutputs* o = t->Out();
      if (o == nullptr || f.wayside == o->radio_area) {
        t->inbox.push_back(std::move(f.bytes));
      } else if (o->handover_area == f.wayside) {
        t->handover_inbox.push_back(std::move(f.bytes));
      }
      continue;
    }
    const units::ReceiveResult r = waysides[f.wayside].unit->Receive(now, t->spec.id, f.bytes);
    if (r.status == units::FrameStatus::kFrameRejected) {
      ++up.rejected[tg::ToString(r.tg_reason)];
      Emit(Json{{"ev", "telegram_rejected"}, {"dir", "up"}, {"train", t->spec.id}, {"reason", tg::ToString(r.tg_reason)},
                {"sent_ms", f.sent_ms}, {"corrupted_symbols", f.corrupted_symbols}});
      continue;
    }
    if (r.status != units::FrameStatus::kAccepted) {
      ++up.malformed;
      continue;
    }
    ++up.accepted;
    for (const units::MessageResult& m : r.Messages()) {
      if (m.type != messages::MessageType::kPositionReport) {
        continue;
      }
      ++report_status[mb::wayside::ToString(m.report)];
      if (m.status == units::MessageStatus::kAccepted) {
        ++t->reports_accepted;
        exercised.insert("REQ-MB-002");
        exercised.insert("REQ-MB-003");
      } else {
        Emit(Json{{"ev", "report"}, {"train", t->spec.id}, {"status", mb::wayside::ToString(m.report)}});
      }
    }
  }
}

// Every wayside unit's cycle, in line order: a unit takes the requests its previous unit made in
// this cycle and the answers its next unit gave in the last (as two ground computers
// exchanging messages once per cycle).
void Simulation::Impl::GroundCycle() {
  const std::vector<bool> before = points_reverse;
  ++ground_cycles;
  Json cyc = Json::array();
  for (std::size_t k = 0; k < waysides.size(); ++k) {
    WaysideRt& w = waysides[k];
    std::vector<units::CrossingSensors> sensors;
    for (const std::size_t i : w.crossing_index) {
      sensors.push_back(crossing_inputs[i]);
    }
    units::CycleInput in;
    in.crossings = sensors;
    if (k > 0) {
      in.from_previous = waysides[k - 1].requests;
    }
    if (k + 1 < waysides.size()) {
      in.from_next = waysides[k + 1].responses;
    }
    const units::CycleOutput& out = w.unit->Cycle(now, in);
    w.requests.assign(out.handover_requests.begin(), out.handover_requests.end());
    w.responses.assign(out.handover_responses.begin(), out.handover_responses.end());
    for (const std::uint32_t id : out.released) {
      ++handovers;
      Emit(Json{{"ev", "handed_over"}, {"train", id}, {"from_unit", k}});
    }
    WaysideOutput(k, out, before, cyc);
  }
  Emit(Json{{"ev", "cycle"}, {"trains", cyc}});
}

// One unit's frames, crossing commands, train statuses (of the trains whose first link is
// this unit's; limits in line chainage) and events; after the first unit's crossings, the
// points and fault windows of its ground.
void Simulation::Impl::WaysideOutput(std::size_t k, const units::CycleOutput& out, const std::vector<bool>& before,
                                     Json& cyc) {
  const std::int64_t origin = waysides[k].origin_mm;
  for (const units::TrainFrame& f : out.frames) {
    const TrainRt* t = Find(static_cast<std::uint16_t>(f.train_id));
    channel.Send(static_cast<std::uint16_t>(f.train_id), Direction::kDownlink, now, f.frame.View(),
                 t != nullptr && t->radio_blocked, k);
  }
  CrossingEquipment(out);
  if (k == 0) {
    GroundState(before);
  }
  for (const units::TrainStatus& s : out.trains) {
    TrainRt* t = Find(static_cast<std::uint16_t>(s.train_id));
    if (t == nullptr || !s.registered || (t->Out() != nullptr && t->Out()->radio_area != k)) {
      continue;
    }
    const auto limit = s.limit_mm ? std::optional<std::int64_t>(*s.limit_mm + origin) : std::nullopt;
    if (s.abnormal != t->abnormal) {
      Emit(Json{{"ev", s.abnormal ? "tracking_abnormal" : "tracking_restored"}, {"train", t->spec.id}});
      if (s.abnormal) {
        ++abnormal_events;
        exercised.insert("REQ-MB-004");
      }
      for (auto& f : faults) {
        if (f.spec.train && *f.spec.train == t->spec.id && f.started) {
          if (s.abnormal && !f.abnormal_at) {
            f.abnormal_at = now;
          }
          if (!s.abnormal && f.ended && !f.tracked_again_at) {
            f.tracked_again_at = now;
          }
        }
      }
    }
    if (s.kind != t->ground_kind && !s.abnormal) {
      Emit(Json{{"ev", "limit_kind"}, {"train", t->spec.id}, {"kind", messages::ToString(s.kind)},
                {"limit_mm", limit ? Json(*limit) : Json(nullptr)}});
    }
    t->abnormal = s.abnormal;
    t->ground_kind = s.kind;
    if (s.limit_mm) {
      ++telegrams_issued;
      exercised.insert("REQ-MB-024");
      exercised.insert("REQ-MB-006");
    }
    cyc.push_back(Json{{"train", t->spec.id}, {"limit_mm", limit ? Json(*limit) : Json(nullptr)},
                       {"kind", messages::ToString(s.kind)}, {"abnormal", s.abnormal}});
  }
  for (const units::InputEvent& e : out.events) {
    Emit(Json{{"ev", "wayside_event"}, {"status", units::ToString(e.status)}, {"id", e.id}});
  }
}

// The points and the possessions and routes of the fault windows (the first unit's ground).
void Simulation::Impl::GroundState(const std::vector<bool>& before) {
  // points movement (REQ-MB-011)
  for (std::size_t p = 0; p < gl.points.size(); ++p) {
    points_reverse[p] = Ground().PointsReverse(p);
    if (points_reverse[p] != before[p]) {
      ++checks["REQ-MB-011"].checks;
      Emit(Json{{"ev", "points"}, {"points", rl->points[p].id}, {"reverse", points_reverse[p]}});
      for (const auto& t : trains) {
        if (t->OnLine() && core::Overlaps(t->RearMm(), t->FrontMm(), gl.points[p].section.begin_mm,
                                             gl.points[p].section.end_mm)) {
          Violate("REQ-MB-011", "move@" + std::to_string(now) + "/" + rl->points[p].id + "/" + std::to_string(t->spec.id),
                  "points " + rl->points[p].id + " moved under train " + std::to_string(t->spec.id));
        }
      }
    }
  }
  for (auto& f : faults) {
    if (f.spec.type == FaultType::kPossession && f.possession_id != 0) {
      const auto st = Ground().Possession(f.possession_id);
      auto& prev = possession_state[f.possession_id];
      if (st != prev) {
        Emit(Json{{"ev", "possession"}, {"possession", f.possession_id}, {"state", mb::wayside::ToString(st)}});
        if (st == mb::wayside::PossessionState::kActive && !f.active_at) {
          f.active_at = now;
        }
        prev = st;
      }
    }
    if (f.spec.type == FaultType::kSidingRequest && f.started && !f.active_at &&
        Ground().RouteSet(static_cast<std::uint32_t>(SidingRoute(f.spec)))) {
      f.active_at = now;
      Emit(Json{{"ev", "route_set"}, {"route", SidingRoute(f.spec)}});
    }
  }
}

// The lights follow the controller's command at once; the barriers are detected down
// kBarrierTravelMs after they were commanded down and up as soon as the command is withdrawn.
void Simulation::Impl::CrossingEquipment(const units::CycleOutput& out) {
  for (const units::CrossingOutput& o : out.crossings) {
    for (std::size_t i = 0; i < crossings.size(); ++i) {
      CrossingRt& x = crossings[i];
      if (x.id != o.crossing_id) {
        continue;
      }
      if (o.lights_on && !x.lights_since) {
        x.lights_since = now;
        ++x.warnings;
        exercised.insert("REQ-LC-006");
        if (Full()) {
          Emit(Json{{"ev", "crossing_warning"}, {"crossing", x.name}});
        }
      } else if (!o.lights_on && x.lights_since) {
        x.lights_since.reset();
        exercised.insert("REQ-LC-007");
      }
      if (o.barriers_down_commanded && !x.command_since) {
        x.command_since = now;
      } else if (!o.barriers_down_commanded) {
        x.command_since.reset();
      }
      x.down = x.command_since && now - *x.command_since >= kBarrierTravelMs;
      crossing_inputs[i].barrier_down = x.down;
      crossing_inputs[i].barrier_up = !x.command_since.has_value();
      if (o.alarm) {
        Emit(Json{{"ev", "crossing_alarm"}, {"crossing", x.name}});
      }
    }
  }
}

}  // namespace railproof::sim
