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
      t->inbox.push_back(std::move(f.bytes));  // read by the on-board unit in its cycle at now
      continue;
    }
    const units::ReceiveResult r = wayside->Receive(now, t->spec.id, f.bytes);
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

void Simulation::Impl::GroundCycle() {
  const std::vector<bool> before = points_reverse;
  units::CycleInput in;
  in.crossings = crossing_inputs;
  const units::CycleOutput& out = wayside->Cycle(now, in);
  ++ground_cycles;
  for (const units::TrainFrame& f : out.frames) {
    const TrainRt* t = Find(static_cast<std::uint16_t>(f.train_id));
    channel.Send(static_cast<std::uint16_t>(f.train_id), Direction::kDownlink, now, f.frame.View(),
                 t != nullptr && t->radio_blocked);
  }
  CrossingEquipment(out);
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
  Json cyc = Json::array();
  for (const units::TrainStatus& s : out.trains) {
    TrainRt* t = Find(static_cast<std::uint16_t>(s.train_id));
    if (t == nullptr || !s.registered) {
      continue;
    }
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
                {"limit_mm", s.limit_mm ? Json(*s.limit_mm) : Json(nullptr)}});
    }
    t->abnormal = s.abnormal;
    t->ground_kind = s.kind;
    if (s.limit_mm) {
      ++telegrams_issued;
      exercised.insert("REQ-MB-024");
      exercised.insert("REQ-MB-006");
    }
    cyc.push_back(Json{{"train", t->spec.id}, {"limit_mm", s.limit_mm ? Json(*s.limit_mm) : Json(nullptr)},
                       {"kind", messages::ToString(s.kind)}, {"abnormal", s.abnormal}});
  }
  for (const units::InputEvent& e : out.events) {
    Emit(Json{{"ev", "wayside_event"}, {"status", units::ToString(e.status)}, {"id", e.id}});
  }
  Emit(Json{{"ev", "cycle"}, {"trains", cyc}});
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
