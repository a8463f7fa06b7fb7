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
  // REQ-MB-008 separation (true ranges; neighbours in front order suffice)
  ++checks["REQ-MB-008"].checks;
  for (std::size_t i = 1; i < on.size(); ++i) {
    const TrainRt& f = *on[i - 1];
    const TrainRt& l = *on[i];
    if (core::Overlaps(f.RearMm(), f.FrontMm(), l.RearMm(), l.FrontMm())) {
      const std::string a = std::to_string(f.spec.id);
      const std::string b = std::to_string(l.spec.id);
      Violate("REQ-MB-008", a + "/" + b,
              "true ranges of trains " + a + " [" + std::to_string(f.RearMm()) + ", " + std::to_string(f.FrontMm()) +
                  ") and " + b + " [" + std::to_string(l.RearMm()) + ", " + std::to_string(l.FrontMm()) +
                  ") mm overlap");
    }
  }
  for (std::size_t i = 0; i < on.size(); ++i) {
    const TrainRt& t = *on[i];
    const auto lim = t.auth.Limit();
    // ASM-013: the true front never passes the last accepted stop limit
    ++checks["ASM-013"].checks;
    const double bound = lim ? ToM(*lim) : ToM(t.spec.initial_front_mm);
    if (t.motion.position > bound + kLimitToleranceM) {
      Violate("ASM-013", std::to_string(t.spec.id),
              "train " + std::to_string(t.spec.id) + " front " + Fmt(t.motion.position) +
                  " m beyond its on-board stop limit " + Fmt(bound) + " m");
    }
    if (!lim || !t.auth.Usable(now)) {
      continue;
    }
    // REQ-MB-009: the usable on-board authority lies within what the ground protects
    ++checks["REQ-MB-009"].checks;
    const auto prot = ground->ProtectedAuthority(t.spec.id);
    if (!prot || *lim > *prot) {
      const std::string id = std::to_string(t.spec.id);
      Violate("REQ-MB-009", id,
              "train " + id + " usable limit " + std::to_string(*lim) + " mm beyond the ground's protected authority " +
                  (prot ? std::to_string(*prot) + " mm" : std::string("(none)")));
    }
    // REQ-MB-007: never beyond the true rear of the next train ahead minus its margin
    if (i + 1 < on.size()) {
      ++checks["REQ-MB-007"].checks;
      const TrainRt& ahead = *on[i + 1];
      if (*lim > ahead.RearMm() - mbp::margin_preceding_train_mm) {
        const std::string id = std::to_string(t.spec.id);
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
    if (ground->Possession(f.possession_id) != mb::wayside::PossessionState::kActive) {
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
}

}  // namespace railproof::sim
