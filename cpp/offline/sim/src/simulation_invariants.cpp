// Line scenario simulation: the safety invariants, checked on the true state after every
// step (simulation.hpp lists them; simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <string>
#include <vector>

namespace railproof::sim {

void Simulation::Impl::CheckInvariants() {
  active_prev.swap(active_now);
  active_now.clear();
  std::vector<const TrainRt*> on;
  for (const auto& t : trains) {
    if (t->OnLine()) {
      on.push_back(t.get());
    }
  }
  std::sort(on.begin(), on.end(),
            [](const TrainRt* a, const TrainRt* b) { return a->motion.position < b->motion.position; });
  // REQ-MB-008 separation of the true trains, at least the preceding-train margin (neighbours
  // in front order suffice)
  ++checks["REQ-MB-008"].checks;
  for (std::size_t i = 1; i < on.size(); ++i) {
    const TrainRt& f = *on[i - 1];
    const TrainRt& l = *on[i];
    if (l.RearMm() - f.FrontMm() < mbp::margin_preceding_train_mm) {
      const std::string a = std::to_string(f.spec.id);
      const std::string b = std::to_string(l.spec.id);
      Violate("REQ-MB-008", a + "/" + b,
              "train " + a + " front " + std::to_string(f.FrontMm()) + " mm is " +
                  std::to_string(l.RearMm() - f.FrontMm()) + " mm behind the rear of train " + b +
                  ", less than the preceding-train margin " + std::to_string(mbp::margin_preceding_train_mm) + " mm");
    }
  }
  for (std::size_t i = 0; i < on.size(); ++i) {
    const TrainRt& t = *on[i];
    const units::OnboardOutputs& o = *t.Out();
    const std::string id = std::to_string(t.spec.id);
    // ASM-013: the true front never passes the limit the unit supervises (the movement
    // authority or the crossing protection limit; none: the unit demands standstill; the
    // patterns include the cycle and reaction times, so no allowance). A limit that appears
    // behind a standing train (a unit before its first valid position supervises
    // the first crossing of the line) is not passed: the train has to move beyond it.
    ++checks["ASM-013"].checks;
    if (o.indications.limit_mm && t.motion.position > ToM(*o.indications.limit_mm) &&
        t.motion.position > t.previous_front_m) {
      Violate("ASM-013", id,
              "train " + id + " front " + Fmt(t.motion.position) + " m beyond its supervised limit " +
                  Fmt(ToM(*o.indications.limit_mm)) + " m (" + units::ToString(o.indications.limit_kind) + ")");
    }
    // REQ-RA-012 / REQ-RA-008: the true front lies inside the unit's position envelope
    ++checks["REQ-RA-012"].checks;
    if (o.position_valid) {
      const double lo = ToM(o.front_mm - o.rear_error_mm);
      const double hi = ToM(o.front_mm + o.front_error_mm);
      if (t.motion.position < lo || t.motion.position > hi) {
        Violate("REQ-RA-012", id,
                "train " + id + " true front " + Fmt(t.motion.position) + " m outside its position envelope [" +
                    Fmt(lo) + ", " + Fmt(hi) + "] m (odometry " + ra::ToString(t.unit->Odometry().mode) + ")");
      }
    }
    // REQ-BR-004 / REQ-BR-001: no true speed above a ceiling of the unit's profile under the
    // train plus the emergency overspeed allowance
    ++checks["REQ-BR-004"].checks;
    const auto overspeed = ToTrainData(*t.type).overspeed_mm_s;
    for (const core::RestrictionSegment& r : t.unit->Profile()) {
      if (r.begin_mm <= t.FrontMm() && t.RearMm() < r.end_mm &&
          t.motion.speed * 1000.0 > static_cast<double>(r.limit_mm_s + overspeed)) {
        Violate("REQ-BR-004", id + "/" + std::to_string(r.begin_mm),
                "train " + id + " at " + Fmt(t.motion.speed * 3.6) + " km/h over the ceiling " +
                    Fmt(static_cast<double>(r.limit_mm_s) * 0.0036) + " km/h plus the overspeed allowance");
        break;
      }
    }
    const auto lim = o.authority_limit_mm;
    if (!lim || !o.authority_usable) {
      continue;
    }
    // REQ-MB-009: the usable on-board authority lies within what the ground protects
    ++checks["REQ-MB-009"].checks;
    const auto prot = ProtectedAuthority(t.spec.id);
    if (!prot || *lim > *prot) {
      Violate("REQ-MB-009", id,
              "train " + id + " usable limit " + std::to_string(*lim) + " mm beyond the ground's protected authority " +
                  (prot ? std::to_string(*prot) + " mm" : std::string("(none)")));
    }
    // REQ-MB-007: never beyond the true rear of the next train ahead minus its margin
    if (i + 1 < on.size()) {
      ++checks["REQ-MB-007"].checks;
      const TrainRt& ahead = *on[i + 1];
      if (*lim > ahead.RearMm() - mbp::margin_preceding_train_mm) {
        Violate("REQ-MB-007", id,
                "train " + id + " usable limit " + std::to_string(*lim) + " mm beyond the true rear of train " +
                    std::to_string(ahead.spec.id) + " (" + std::to_string(ahead.RearMm()) + " mm) minus the margin");
      }
    }
  }
  // REQ-MB-014: no train inside an active possession
  for (const auto& f : faults) {
    if (f.spec.type != FaultType::kPossession || f.possession_id == 0) {
      continue;
    }
    if (Ground().Possession(f.possession_id) != mb::wayside::PossessionState::kActive) {
      continue;
    }
    ++checks["REQ-MB-014"].checks;
    for (const TrainRt* t : on) {
      if (core::Overlaps(t->RearMm(), t->FrontMm(), f.spec.begin_mm, f.spec.end_mm)) {
        const std::string id = std::to_string(t->spec.id);
        const std::string pid = std::to_string(f.possession_id);
        Violate("REQ-MB-014", id + "/" + pid, "train " + id + " inside active possession " + pid);
      }
    }
  }
  // REQ-MB-013: trains on points only in the running line's route position
  for (std::size_t p = 0; p < gl.points.size(); ++p) {
    ++checks["REQ-MB-013"].checks;
    if (points_reverse[p] == points_running_reverse[p]) {
      continue;
    }
    for (const TrainRt* t : on) {
      if (core::Overlaps(t->RearMm(), t->FrontMm(), gl.points[p].section.begin_mm, gl.points[p].section.end_mm)) {
        const std::string id = std::to_string(t->spec.id);
        Violate("REQ-MB-013", id + "/" + rl->points[p].id,
                "train " + id + " on points " + rl->points[p].id + " lying against its route");
      }
    }
  }
  CheckCrossings(on);
}

// REQ-LC-003 / REQ-LC-002: a true train on a level crossing only while its barriers are down
// and after its lights have warned for the crossing's design warning time.
void Simulation::Impl::CheckCrossings(const std::vector<const TrainRt*>& on) {
  for (CrossingRt& x : crossings) {
    ++checks["REQ-LC-003"].checks;
    ++checks["REQ-LC-002"].checks;
    for (const TrainRt* t : on) {
      const std::string key = std::to_string(t->spec.id) + "/" + x.name;
      if (!core::Overlaps(t->RearMm(), t->FrontMm(), x.near_mm, x.far_mm)) {
        x.occupying.erase(t->spec.id);
        continue;
      }
      const double warned_s = x.lights_since ? ToS(now - *x.lights_since) : 0.0;
      if (x.occupying.insert(t->spec.id).second) {
        ++x.passages;
        x.shortest_warning_s = std::min(x.shortest_warning_s, warned_s);
      }
      if (!x.down) {
        Violate("REQ-LC-003", key, "train " + std::to_string(t->spec.id) + " on crossing " + x.name +
                                       " whose barriers are not down");
      }
      if (!x.lights_since || now - *x.lights_since < x.warning_time_ms) {
        Violate("REQ-LC-002", key, "train " + std::to_string(t->spec.id) + " on crossing " + x.name + " warned " +
                                       Fmt(warned_s) + " s, less than its design warning time " +
                                       Fmt(ToS(x.warning_time_ms)) + " s");
      }
    }
  }
}

}  // namespace railproof::sim
