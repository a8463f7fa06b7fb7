// Line scenario simulation: telegrams between the trains and the ground through the telegram
// layer and the channel, and the ground cycle (simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <array>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "railproof/messages/codec.hpp"
#include "railproof/tg/frame.hpp"

namespace railproof::sim {

namespace {

// The payload of a message the simulation built; a message the codec refuses is a fault of
// the simulation (its trains and ground give values inside the codec's ranges).
messages::Payload EncodeOrThrow(const messages::Message& m) {
  const messages::Encoded e = messages::Encode(m);
  if (!e.Ok()) {
    throw std::logic_error(std::string("line simulation: a ") + messages::ToString(messages::TypeOf(m)) +
                           " message is not encodable: " + messages::ToString(e.error) + " " +
                           messages::ToString(e.invalid) + " " + messages::ToString(e.field));
  }
  return e.payload;
}

}  // namespace

void Simulation::Impl::DeliverFrames() {
  std::array<std::uint8_t, tg::kPayloadMax> buffer{};
  for (Frame& f : channel.Deliver(now)) {
    TrainRt* t = Find(f.train);
    if (t == nullptr || !t->OnLine()) {
      continue;
    }
    const bool uplink = f.direction == Direction::kUplink;
    const auto payload = Accept(uplink ? t->ground_ep : t->train_ep, *t, f, uplink, buffer);
    if (!payload) {
      continue;
    }
    if (uplink) {
      OnPositionReport(*t, f, *payload);
    } else {
      OnStopLimit(*t, *payload);
    }
  }
}

std::optional<std::span<const std::uint8_t>> Simulation::Impl::Accept(tg::Endpoint& ep, TrainRt& t, const Frame& f,
                                                                      bool uplink, std::span<std::uint8_t> buffer) {
  const auto r = ep.Receive(Clock32(now), f.bytes, buffer);
  if (!uplink) {
    t.link_up = r.link == tg::LinkState::kUp;
  }
  DirStats& stats = uplink ? up : down;
  if (r.reason != tg::RejectReason::kNone) {
    ++stats.rejected[VerdictName(r.reason)];
    Emit(Json{{"ev", "telegram_rejected"}, {"dir", uplink ? "up" : "down"}, {"train", t.spec.id},
              {"reason", VerdictName(r.reason)}, {"sent_ms", f.sent_ms}, {"corrupted_symbols", f.corrupted_symbols}});
    return std::nullopt;
  }
  ++stats.accepted;
  return std::span<const std::uint8_t>(buffer).first(r.header.payload_len);
}

void Simulation::Impl::OnPositionReport(TrainRt& t, const Frame& f, std::span<const std::uint8_t> payload) {
  const messages::Decoded decoded = messages::Decode(payload);
  if (std::holds_alternative<messages::NoPosition>(decoded.message)) {
    return;  // no position (tracking loss on board): nothing for the ground
  }
  const auto* rep = std::get_if<messages::PositionReport>(&decoded.message);
  if (rep == nullptr || rep->train_id != t.spec.id) {
    ++up.malformed;  // not a message, another type, or another train's
    return;
  }
  const auto st = ground->OnReport(*rep);
  ++report_status[mb::wayside::ToString(st)];
  if (st == mb::wayside::ReportStatus::kAccepted) {
    ++t.reports_accepted;
    if (Full()) {
      Emit(Json{{"ev", "report"}, {"train", t.spec.id}, {"front_mm", ToFront(*rep)}, {"correction_mm", rep->correction_mm},
                {"speed_mm_s", rep->speed_mm_s}, {"sent_ms", f.sent_ms}, {"status", "Accepted"}});
    }
  } else {
    Emit(Json{{"ev", "report"}, {"train", t.spec.id}, {"front_mm", ToFront(*rep)}, {"status", mb::wayside::ToString(st)}});
  }
}

void Simulation::Impl::OnStopLimit(TrainRt& t, std::span<const std::uint8_t> payload) {
  const messages::Decoded decoded = messages::Decode(payload);
  if (std::holds_alternative<messages::KeepAlive>(decoded.message)) {
    return;  // keep-alive: no limit for this train
  }
  const auto* tg = std::get_if<messages::StopLimitTelegram>(&decoded.message);
  if (tg == nullptr || tg->train_id != t.spec.id) {
    ++down.malformed;  // not a message, another type, or another train's
    return;
  }
  const auto before = t.auth.Limit();
  const auto v = t.auth.Receive(tg->limit_mm, tg->issue_time_ms, now);
  ++verdicts[mb::onboard::ToString(v)];
  if (v == mb::onboard::Verdict::kAccept) {
    const bool changed_kind = tg->kind != t.limit_kind;
    t.limit_kind = tg->kind;
    t.tsr.Update(std::span<const messages::SpeedRestriction>(tg->restrictions.data(), tg->restriction_count),
                 ToMm(t.est_front_m), t.length_mm);
    if (Full() || !before || *before > tg->limit_mm || changed_kind) {
      Emit(Json{{"ev", "limit"}, {"train", t.spec.id}, {"limit_mm", tg->limit_mm}, {"kind", messages::ToString(tg->kind)},
                {"issue_ms", tg->issue_time_ms}, {"age_ms", now - tg->issue_time_ms},
                {"previous_mm", before ? Json(*before) : Json(nullptr)}});
    }
  } else {
    Emit(Json{{"ev", "limit_refused"}, {"train", t.spec.id}, {"verdict", mb::onboard::ToString(v)},
              {"limit_mm", tg->limit_mm}, {"issue_ms", tg->issue_time_ms}});
  }
}

std::int64_t Simulation::Impl::ToFront(const messages::PositionReport& r) const {
  return rl->blocks_mm[std::min<std::size_t>(r.front_block, rl->blocks_mm.size() - 1)] + r.offset_mm;
}

std::pair<std::uint32_t, std::int64_t> Simulation::Impl::Locate(std::int64_t front_mm) const {
  const auto& b = rl->blocks_mm;
  if (front_mm <= 0) {
    return {0, 0};
  }
  const auto it = std::lower_bound(b.begin(), b.end(), front_mm);  // first boundary >= front
  const auto idx = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - b.begin())) - 1;
  const std::size_t block = std::min(idx, b.size() - 2);
  return {static_cast<std::uint32_t>(block), front_mm - b[block]};
}

void Simulation::Impl::GroundCycle() {
  // radio channel management: secure the handovers ahead of every tracked train
  for (TrainRt* t : TrainsOnLine()) {
    const auto ext = ground->Extended(t->spec.id);
    if (!ext) {
      continue;
    }
    for (const auto& h : gl.handovers) {
      if (h.position_mm >= ext->begin_mm && h.position_mm - ext->end_mm <= ToMm(sc.handover_secure_ahead_m) &&
          !ground->HandoverSecured(t->spec.id, h.id)) {
        ground->SecureHandover(t->spec.id, h.id);
        exercised.insert("REQ-MB-017");
        if (Full()) {
          Emit(Json{{"ev", "handover_secured"}, {"train", t->spec.id}, {"handover", h.id}});
        }
      }
    }
  }
  const std::vector<bool> before = points_reverse;
  ground->Cycle(now);
  ++ground_cycles;
  // points movement (REQ-MB-011)
  for (std::size_t p = 0; p < gl.points.size(); ++p) {
    points_reverse[p] = ground->PointsReverse(p);
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
      const auto st = ground->Possession(f.possession_id);
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
        ground->RouteSet(static_cast<std::uint32_t>(SidingRoute(f.spec)))) {
      f.active_at = now;
      Emit(Json{{"ev", "route_set"}, {"route", SidingRoute(f.spec)}});
    }
  }
  // per-train outputs and telegrams
  std::map<std::uint32_t, const messages::StopLimitTelegram*> tgs;
  for (const auto& tg : ground->Telegrams()) {
    tgs[tg.train_id] = &tg;
  }
  Json cyc = Json::array();
  for (TrainRt* t : TrainsOnLine()) {
    const auto o = ground->Train(t->spec.id);
    if (!o) {
      continue;
    }
    if (o->abnormal != t->abnormal) {
      Emit(Json{{"ev", o->abnormal ? "tracking_abnormal" : "tracking_restored"}, {"train", t->spec.id}});
      if (o->abnormal) {
        ++abnormal_events;
        exercised.insert("REQ-MB-004");
      }
      for (auto& f : faults) {
        if (f.spec.train && *f.spec.train == t->spec.id && f.started) {
          if (o->abnormal && !f.abnormal_at) {
            f.abnormal_at = now;
          }
          if (!o->abnormal && f.ended && !f.tracked_again_at) {
            f.tracked_again_at = now;
          }
        }
      }
    }
    if (o->kind != t->ground_kind && !o->abnormal) {
      Emit(Json{{"ev", "limit_kind"}, {"train", t->spec.id}, {"kind", messages::ToString(o->kind)},
                {"limit_mm", o->limit_mm ? Json(*o->limit_mm) : Json(nullptr)}});
    }
    t->abnormal = o->abnormal;
    t->ground_limit = o->limit_mm;
    t->ground_kind = o->kind;
    Json c{{"train", t->spec.id}, {"limit_mm", o->limit_mm ? Json(*o->limit_mm) : Json(nullptr)},
           {"kind", messages::ToString(o->kind)}, {"abnormal", o->abnormal}};
    cyc.push_back(c);
    messages::Payload payload;
    const auto it = tgs.find(t->spec.id);
    if (it != tgs.end()) {
      payload = EncodeOrThrow(*it->second);
      ++telegrams_issued;
      exercised.insert("REQ-MB-024");
      exercised.insert("REQ-MB-006");
    } else {
      payload = EncodeOrThrow(messages::KeepAlive{});
    }
    tg::EncodedFrame frame{};
    const auto out = t->ground_ep.Cycle(Clock32(now), payload.View(), frame);
    if (out.status == tg::SendStatus::kSent) {
      channel.Send(t->spec.id, Direction::kDownlink, now, frame.View(), t->radio_blocked);
    }
  }
  Emit(Json{{"ev", "cycle"}, {"trains", cyc}});
}

void Simulation::Impl::SendReports() {
  for (auto& t : trains) {
    if (!t->OnLine() || now < t->next_report_ms) {
      continue;
    }
    t->next_report_ms += sc.report_period_ms;
    messages::Payload payload;
    if (t->position_lost) {
      payload = EncodeOrThrow(messages::NoPosition{});
    } else {
      const std::int64_t front = std::clamp<std::int64_t>(ToMm(t->est_front_m), 0, rl->length_mm);
      const auto [block, offset] = Locate(front);
      messages::PositionReport rep{};
      rep.train_id = t->spec.id;
      rep.front_block = block;
      rep.offset_mm = offset;
      rep.length_mm = t->length_mm;
      rep.correction_mm = CorrectionMm(*t);
      rep.last_balise_mm = t->last_balise_mm;
      rep.speed_mm_s = static_cast<std::int64_t>(std::llround(t->motion.speed * 1000.0));
      rep.direction = mb::wayside::Direction::kNominal;
      payload = EncodeOrThrow(rep);
      ++t->reports_sent;
      exercised.insert("REQ-MB-001");
      exercised.insert("REQ-MB-002");
      exercised.insert("REQ-MB-003");
    }
    tg::EncodedFrame frame{};
    const auto out = t->train_ep.Cycle(Clock32(now), payload.View(), frame);
    t->link_up = out.link == tg::LinkState::kUp;
    if (out.status == tg::SendStatus::kSent) {
      channel.Send(t->spec.id, Direction::kUplink, now, frame.View(), t->radio_blocked);
    }
  }
}

}  // namespace railproof::sim
