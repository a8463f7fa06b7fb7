// Line scenario simulation: scheduled commands (possession, siding route, speed restriction)
// and the fault windows (radio loss, tracking loss) (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <string>

namespace railproof::sim {

void Simulation::Impl::ApplySchedule() {
  for (auto& f : faults) {
    const FaultSpec& s = f.spec;
    if (!f.started && now >= s.from_ms) {
      f.started = true;
      Json ev{{"ev", "fault_begin"}, {"type", ToString(s.type)}};
      switch (s.type) {
        case FaultType::kRadioLoss:
        case FaultType::kTrackingLoss: ev["train"] = *s.train; break;
        case FaultType::kPossession: {
          const auto r = wayside->RequestPossession(core::Section{s.begin_mm, s.end_mm});
          f.possession_id = r.id;
          f.status = mb::wayside::ToString(r.status);
          ev["possession"] = r.id;
          ev["range_mm"] = {s.begin_mm, s.end_mm};
          ev["status"] = f.status;
          exercised.insert("REQ-MB-014");
          break;
        }
        case FaultType::kSidingRequest: {
          const auto st = wayside->RequestRoute(static_cast<std::uint32_t>(SidingRoute(s)));
          f.status = mb::wayside::ToString(st);
          ev["route"] = SidingRoute(s);
          ev["status"] = f.status;
          exercised.insert("REQ-MB-012");
          exercised.insert("REQ-MB-013");
          break;
        }
        case FaultType::kSpeedRestriction: {
          const auto speed = static_cast<std::int64_t>(std::llround(s.speed_mps * 1000.0));
          const auto r = wayside->RequestSpeedRestriction(core::Section{s.begin_mm, s.end_mm}, speed);
          f.restriction_id = r.id;
          const auto c = wayside->ConfirmSpeedRestriction(r.id);
          f.status = std::string(mb::wayside::ToString(r.status)) + "/" + mb::wayside::ToString(c);
          ev["restriction"] = r.id;
          ev["range_mm"] = {s.begin_mm, s.end_mm};
          ev["speed_mm_s"] = speed;
          ev["status"] = f.status;
          exercised.insert("REQ-MB-015");
          break;
        }
      }
      Emit(ev);
    }
    if (f.started && !f.ended && now >= s.to_ms) {
      f.ended = true;
      Json ev{{"ev", "fault_end"}, {"type", ToString(s.type)}};
      switch (s.type) {
        case FaultType::kRadioLoss:
        case FaultType::kTrackingLoss: ev["train"] = *s.train; break;
        case FaultType::kPossession:
          ev["status"] = mb::wayside::ToString(wayside->CancelPossession(f.possession_id));
          ev["possession"] = f.possession_id;
          break;
        case FaultType::kSidingRequest: f.free_pending = true; break;
        case FaultType::kSpeedRestriction:
          ev["status"] = mb::wayside::ToString(wayside->CancelSpeedRestriction(f.restriction_id));
          break;
      }
      Emit(ev);
    }
    if (f.free_pending) {
      const auto st = wayside->FreeRoute(static_cast<std::uint32_t>(SidingRoute(s)));
      if (st == mb::wayside::CommandStatus::kAccepted) {
        f.free_pending = false;
        f.freed_at = now;
        Emit(Json{{"ev", "route_freed"}, {"route", SidingRoute(s)}});
      } else if (st != mb::wayside::CommandStatus::kRefusedInUse) {
        f.free_pending = false;
        Emit(Json{{"ev", "route_free_refused"}, {"route", SidingRoute(s)}, {"status", mb::wayside::ToString(st)}});
      }
    }
  }
  for (auto& t : trains) {
    bool blocked = false;
    bool lost = false;
    for (const auto& f : faults) {
      if (f.spec.train && *f.spec.train == t->spec.id && now >= f.spec.from_ms && now < f.spec.to_ms) {
        blocked = blocked || f.spec.type == FaultType::kRadioLoss;
        lost = lost || f.spec.type == FaultType::kTrackingLoss;
      }
    }
    t->radio_blocked = blocked;
    t->position_lost = lost;
  }
}

std::int64_t Simulation::Impl::SidingRoute(const FaultSpec& s) const {
  if (s.route != 0) {
    return s.route;
  }
  for (const auto& r : rl->routes) {
    if (r.reverse && !r.automatic) {
      return r.id;
    }
  }
  return 0;
}

}  // namespace railproof::sim
