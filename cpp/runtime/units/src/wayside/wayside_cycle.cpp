// The wayside unit's ground cycle (include/railproof/units/wayside_unit.hpp), in this order:
//   1. radio channels: base-station channels released behind and secured ahead of every train
//   2. the previous unit's handover requests answered (a new train admitted and registered
//      before the ground cycle, so that it has a limit to answer with), the next unit's
//      answers taken, the boundary accepted or not
//   3. the moving-block ground cycle
//   4. the centre schedulers (with the controllers' acknowledgements and reports of the last
//      cycle, or those received over an external link), then the crossing controllers (with
//      this cycle's start times and stops, or those received over an external link, the
//      requests and withdrawals received since the last cycle and the equipment state)
//   5. trains handed over and past the boundary released, requests for those in the overlap
//   6. one telegram per train: its stop limit (or a keep-alive), then the crossing messages
//      waiting for it that fit
#include <algorithm>
#include <variant>

#include "railproof/core/seeded_fault.hpp"
#include "railproof/units/wayside_unit.hpp"
#include "wayside_internal.hpp"

namespace railproof::units {
namespace {

// The part of a received centre-link list that is used (Cycle reports a longer one).
template <typename T>
std::span<const T> Bounded(std::span<const T> list) noexcept {
  return list.first(std::min(list.size(), kMaxLinkMessages));
}

// Appends as many of `from` as fit (the centre's inbox holds what it takes in one cycle).
template <typename T>
void Append(core::FixedVector<T>& to, const core::FixedVector<T>& from) noexcept {
  for (const T& x : from) {
    (void)to.PushBack(x);
  }
}

}  // namespace

void WaysideUnit::Event(InputStatus status, std::uint32_t id, HandoverVerdict verdict) noexcept {
  (void)out_.events.PushBack(InputEvent{status, id, verdict});
}

const CycleOutput& WaysideUnit::Cycle(std::int64_t now_ms, const CycleInput& input) noexcept {
  out_.frames.Clear();
  out_.trains.Clear();
  out_.departures.Clear();
  out_.handover_requests.Clear();
  out_.handover_responses.Clear();
  out_.released.Clear();
  out_.start_times.Clear();
  out_.warning_stops.Clear();
  out_.start_acks.Clear();
  out_.stop_acks.Clear();
  out_.crossing_reports.Clear();
  out_.events.Clear();
  if (now_ms < last_cycle_ms_) {
    // nothing done, nothing sent (safe side); the crossing equipment keeps its last commands
    out_.status = CycleStatus::kClockWentBack;
    return out_;
  }
  out_.status = CycleStatus::kDone;
  last_cycle_ms_ = now_ms;
  ChannelStep();
  AnswerPrevious(input.from_previous);
  TakeAnswers(input.from_next);
  BoundaryAcceptance();
  (void)ground_->Cycle(now_ms);
  const ToCrossings& tx = input.to_crossings;
  const ToCentre& rx = input.to_centre;
  const std::size_t longest = std::max({tx.start_times.size(), tx.warning_stops.size(), rx.start_acks.size(),
                                        rx.stop_acks.size(), rx.reports.size()});
  if (link_ == CentreLink::kInternal && longest > 0) {
    Event(InputStatus::kLinkNotExternal, 0);
  } else if (longest > kMaxLinkMessages) {
    Event(InputStatus::kTooManyMessages, 0);
  }
  if (link_ == CentreLink::kExternal) {
    ReceiveAtCentre(rx);
  }
  CentreStep(now_ms);
  DeliverToCrossings(link_ == CentreLink::kExternal ? ToCrossings{Bounded(tx.start_times), Bounded(tx.warning_stops)}
                                                    : out_.ToCrossingsSent());
  CrossingStep(now_ms, input.crossings);
  ReleaseAndRequest();
  SendStep(now_ms);
  return out_;
}

// Radio channel management (D5 §5.1.4 obstruction 4, REQ-MB-017): a train holds a channel of
// every base station under its extended range; the handover point ahead is secured when the
// next base station has room, else the point stays an obstruction for the train.
// @implements REQ-MB-017
void WaysideUnit::ChannelStep() noexcept {
  for (Slot& s : slots_) {
    const auto ext = s.registered ? ground_->Extended(s.train_id) : std::nullopt;
    if (!ext) {
      continue;
    }
    while (s.first_cell < s.last_cell && handover_mm_[s.first_cell] <= ext->begin_mm) {
      --cell_load_[s.first_cell];
      ++s.first_cell;
    }
    while (secure_ahead_mm_ && s.last_cell < handover_mm_.Size() &&
           handover_mm_[s.last_cell] - ext->end_mm <= *secure_ahead_mm_) {
      if (cell_load_[s.last_cell + 1] >= per_station_) {
        Event(InputStatus::kBaseStationFull, s.train_id);
        break;
      }
      (void)ground_->SecureHandover(s.train_id, handover_ids_[s.last_cell]);
      ++s.last_cell;
      ++cell_load_[s.last_cell];
    }
  }
}

// Accepting side of a handover: every request is answered; a train not known yet is admitted
// and registered at the handed-over position, or refused.
void WaysideUnit::AnswerPrevious(std::span<const HandoverRequest> requests) noexcept {
  if (requests.size() > kMaxNeighbourMessages) {
    Event(InputStatus::kTooManyMessages, 0);
    requests = requests.first(kMaxNeighbourMessages);
  }
  for (const HandoverRequest& q : requests) {
    Slot* s = Find(q.train_id);
    if (s != nullptr && s->registered) {
      s->answer_previous = true;
      continue;
    }
    HandoverVerdict verdict = HandoverVerdict::kAccepted;
    if (s == nullptr && Admit(q.train_id, q.radio_id) != AdmitStatus::kAdmitted) {
      verdict = HandoverVerdict::kNoRoom;
    } else {
      const RegisterResult r = Register(mb::wayside::TrainRegistration{
          q.train_id, q.length_mm, q.front_mm - origin_mm_, q.correction_mm, mb::wayside::InitialPosition::kEntryBalise});
      if (r.status != RegisterStatus::kRegistered) {
        verdict = r.status == RegisterStatus::kGroundRefused ? HandoverVerdict::kTrackNotClear : HandoverVerdict::kNoRoom;
        (void)Remove(q.train_id);
      }
    }
    if (verdict == HandoverVerdict::kAccepted) {
      Find(q.train_id)->answer_previous = true;
    } else {
      (void)out_.handover_responses.PushBack(HandoverResponse{q.train_id, verdict, std::nullopt,
                                                              messages::Obstruction::kNone, 0});
    }
  }
}

// Releasing side: the next unit's answers.
void WaysideUnit::TakeAnswers(std::span<const HandoverResponse> answers) noexcept {
  if (answers.size() > kMaxNeighbourMessages) {
    Event(InputStatus::kTooManyMessages, 0);
    answers = answers.first(kMaxNeighbourMessages);
  }
  for (const HandoverResponse& a : answers) {
    Slot* s = Find(a.train_id);
    if (s == nullptr || s->handover == Handover::kNone) {
      Event(InputStatus::kUnknownTrain, a.train_id);
      continue;
    }
    if (a.verdict != HandoverVerdict::kAccepted) {
      s->handover = Handover::kRefused;
      s->next_limit_mm.reset();
      Event(InputStatus::kHandoverRefused, a.train_id, a.verdict);
      continue;
    }
    s->handover = Handover::kAccepted;
    s->next_limit_mm = a.limit_mm ? std::optional<std::int64_t>(*a.limit_mm - origin_mm_) : std::nullopt;
    s->next_kind = a.kind;
    s->next_issue_ms = a.issue_time_ms;
  }
}

// The system boundary is an obstruction (REQ-MB-023) unless the foremost train before it is
// accepted by the next unit with a limit known: only that train can have the boundary as its
// nearest obstruction (every other one is behind its rear).
// @implements REQ-MB-023
void WaysideUnit::BoundaryAcceptance() noexcept {
  if (!zone_begin_mm_) {
    return;  // no next unit: the boundary is accepted by command (AcceptAtBoundary)
  }
  const Slot* foremost = nullptr;
  for (const Slot& s : slots_) {
    if (s.registered && s.front_mm <= *boundary_mm_ && (foremost == nullptr || s.front_mm > foremost->front_mm)) {
      foremost = &s;
    }
  }
  (void)ground_->AcceptAtBoundary(foremost != nullptr && foremost->handover == Handover::kAccepted &&
                                  foremost->next_limit_mm.has_value());
}

// The centre link's messages to the centre (kExternal): those naming a crossing the unit does
// not hold, or acknowledging a departure none of its schedulers holds, are not used.
void WaysideUnit::ReceiveAtCentre(const ToCentre& in) noexcept {
  const auto known = [this](std::uint32_t crossing_id, std::uint32_t departure_id) {
    if (FindCrossing(crossing_id) == nullptr) {
      Event(InputStatus::kUnknownCrossing, crossing_id);
      return false;
    }
    if (!HoldsDeparture(departure_id)) {
      Event(InputStatus::kUnknownDeparture, departure_id);
      return false;
    }
    return true;
  };
  for (const lc::wayside::StartTimeAck& a : Bounded(in.start_acks)) {
    if (known(a.crossing_id, a.departure_id)) {
      (void)start_acks_.PushBack(a);
    }
  }
  for (const lc::wayside::WarningStopAck& a : Bounded(in.stop_acks)) {
    if (known(a.crossing_id, a.departure_id)) {
      (void)stop_acks_.PushBack(a);
    }
  }
  for (const messages::CrossingReport& r : Bounded(in.reports)) {
    if (FindCrossing(r.crossing_id) == nullptr) {
      Event(InputStatus::kUnknownCrossing, r.crossing_id);
    } else {
      (void)last_reports_.PushBack(r);
    }
  }
}

// The centre schedulers of the GNSS-time variant (lc design §5): the acknowledgements and
// reports received, the train's centre position report; their start times and stops are sent
// in this cycle.
// Connects the centre schedulers (REQ-LC-008, REQ-LC-010, implemented in lc) to the controllers.
void WaysideUnit::CentreStep(std::int64_t now_ms) noexcept {
  for (DepartureSlot& d : departures_) {
    const auto& dep = d.scheduler->CurrentDeparture();
    if (!dep) {
      continue;
    }
    lc::wayside::SchedulerInput in;
    in.now_ms = now_ms;
    in.start_acks = start_acks_.Span();
    in.stop_acks = stop_acks_.Span();
    in.reports = last_reports_.Span();
    in.position = d.position;
    in.restrictions = profile_.Span();
    d.position.reset();
    if (d.scheduler->Cycle(in) != lc::wayside::SchedulerError::kNone) {
      Event(InputStatus::kSchedulerRefused, dep->train_id);
    }
    const lc::wayside::SchedulerOutput& o = d.scheduler->Output();
    for (const lc::wayside::StartTimeMessage& m : o.StartTimes()) {
      (void)out_.start_times.PushBack(m);
    }
    for (const lc::wayside::WarningStopMessage& m : o.WarningStops()) {
      (void)out_.warning_stops.PushBack(m);
    }
    (void)out_.departures.PushBack(DepartureOutput{dep->train_id, dep->departure_id, o.departure_cleared, o.block});
  }
  start_acks_.Clear();
  stop_acks_.Clear();
  last_reports_.Clear();
}

// The start times and stops for the controllers of this cycle: the centre's of this cycle
// (kInternal) or those received (kExternal); a message for a crossing the unit does not hold,
// or beyond what its controller takes in one cycle, is not used.
void WaysideUnit::DeliverToCrossings(const ToCrossings& in) noexcept {
  for (CrossingSlot& c : crossings_) {
    c.start_time_count = 0;
    c.stop_count = 0;
  }
  const auto deliver = [this](const auto& messages, auto list, auto count) {
    for (const auto& m : messages) {
      CrossingSlot* c = FindCrossing(m.crossing_id);
      if (c == nullptr) {
        Event(InputStatus::kUnknownCrossing, m.crossing_id);
      } else if (c->*count >= (c->*list).size()) {
        Event(InputStatus::kTooManyMessages, m.crossing_id);
      } else {
        (c->*list)[(c->*count)++] = m;
      }
    }
  };
  deliver(in.start_times, &CrossingSlot::start_times, &CrossingSlot::start_time_count);
  deliver(in.warning_stops, &CrossingSlot::stops, &CrossingSlot::stop_count);
}

// Keeps a crossing message for the train's next telegrams: a newer report of a crossing
// replaces the one still waiting (only the latest state matters), an acknowledgement waiting
// already is not repeated; so at most one of each per crossing waits.
void WaysideUnit::Enqueue(Slot& s, const messages::Message& m) noexcept {
  messages::Message* box = outbox_.begin() + SlotIndex(s) * outbox_per_slot_;  // none without crossings (null + 0)
  const auto* report = std::get_if<messages::CrossingReport>(&m);
  const auto* ack = std::get_if<messages::WithdrawalAck>(&m);
  for (std::size_t i = 0; i < s.outbox_count; ++i) {
    const auto* r = std::get_if<messages::CrossingReport>(&box[i]);
    const auto* a = std::get_if<messages::WithdrawalAck>(&box[i]);
    if (report != nullptr && r != nullptr && r->crossing_id == report->crossing_id) {
      box[i] = m;
      return;
    }
    if (ack != nullptr && a != nullptr && a->crossing_id == ack->crossing_id && a->train_id == ack->train_id) {
      return;
    }
  }
  if (s.outbox_count < outbox_per_slot_) {
    box[s.outbox_count++] = m;
  }
}

// Connects the crossing controllers (REQ-LC-003, REQ-LC-006, REQ-LC-007, implemented in lc) to
// the trains' telegrams, the crossing equipment and the centre link.
void WaysideUnit::CrossingStep(std::int64_t now_ms, std::span<const CrossingSensors> sensors) noexcept {
  for (const CrossingSensors& x : sensors) {
    if (FindCrossing(x.crossing_id) == nullptr) {
      Event(InputStatus::kUnknownCrossing, x.crossing_id);
    }
  }
  out_.crossings.Clear();
  for (CrossingSlot& c : crossings_) {
    lc::wayside::ControllerInput in;
    in.now_ms = now_ms;
    in.requests = std::span<const std::uint32_t>(c.requests.data(), c.request_count);
    in.withdrawals = std::span<const std::uint32_t>(c.withdrawals.data(), c.withdrawal_count);
    in.barrier_down = false;
    in.barrier_up = false;
    for (const CrossingSensors& x : sensors) {
      if (x.crossing_id == c.data.id) {
        in.barrier_down = x.barrier_down;
        in.barrier_up = x.barrier_up;
        in.clock = x.clock;
      }
    }
    in.start_times = std::span<const lc::wayside::StartTimeMessage>(c.start_times.data(), c.start_time_count);
    in.warning_stops = std::span<const lc::wayside::WarningStopMessage>(c.stops.data(), c.stop_count);
    if (c.controller->Cycle(in) != lc::wayside::ControllerError::kNone) {
      Event(InputStatus::kControllerRefused, c.data.id);
    }
    c.request_count = 0;
    c.withdrawal_count = 0;
    const lc::wayside::ControllerOutput& o = c.controller->Output();
    (void)out_.crossings.PushBack(CrossingOutput{c.data.id, o.lights_on, o.barriers_down_commanded, o.alarm, o.report});
    (void)out_.crossing_reports.PushBack(o.report);
    // the report goes to every train among its requesters (lc design §3 item 3), the
    // acknowledgement to the train that withdrew
    for (std::size_t i = 0; i < o.report.requester_count && i < o.report.requesters.size(); ++i) {
      if (Slot* s = Find(o.report.requesters[i])) {
        Enqueue(*s, o.report);
      }
    }
    for (const std::uint32_t t : o.WithdrawalAcks()) {
      if (Slot* s = Find(t)) {
        Enqueue(*s, messages::WithdrawalAck{c.data.id, t});
      }
    }
    for (lc::wayside::StartTimeAck a : o.StartAcks()) {
      if (RAILPROOF_FAULT(FAULT_UNIT_START_ACK_WRONG_CROSSING)) {
        a.crossing_id = crossings_[(static_cast<std::size_t>(&c - crossings_.begin()) + 1) % crossings_.Size()].data.id;
      }
      (void)out_.start_acks.PushBack(a);
    }
    for (const lc::wayside::WarningStopAck& a : o.StopAcks()) {
      (void)out_.stop_acks.PushBack(a);
    }
  }
  if (link_ == CentreLink::kInternal) {
    // the centre takes them in its next step
    Append(start_acks_, out_.start_acks);
    Append(stop_acks_, out_.stop_acks);
    Append(last_reports_, out_.crossing_reports);
  }
}

// Releasing side: a train accepted by the next unit is removed once its extended rear has
// passed the boundary; until then every train whose extended front end reaches the overlap is
// asked for every cycle (the request is also the answer's trigger).
void WaysideUnit::ReleaseAndRequest() noexcept {
  for (Slot& s : slots_) {
    if (!s.registered) {
      continue;
    }
    if (s.answer_previous) {
      s.answer_previous = false;
      const auto o = ground_->Train(s.train_id);
      const StopLimitTelegramView t = FindTelegram(s.train_id);
      (void)out_.handover_responses.PushBack(HandoverResponse{
          s.train_id, HandoverVerdict::kAccepted,
          o && o->limit_mm && !o->abnormal ? std::optional<std::int64_t>(*o->limit_mm + origin_mm_) : std::nullopt,
          o ? o->kind : messages::Obstruction::kNone, t != nullptr ? t->issue_time_ms : 0});
    }
    const auto ext = ground_->Extended(s.train_id);
    if (!zone_begin_mm_ || !boundary_mm_ || !ext) {
      continue;
    }
    const std::int64_t rear = RAILPROOF_FAULT(FAULT_UNIT_HANDOVER_EARLY_RELEASE) ? ext->end_mm : ext->begin_mm;
    if (s.handover == Handover::kAccepted && rear >= *boundary_mm_) {
      (void)out_.released.PushBack(s.train_id);
      FreeSlot(s);
      continue;
    }
    if (ext->end_mm >= *zone_begin_mm_) {
      (void)out_.handover_requests.PushBack(
          HandoverRequest{s.train_id, s.radio_id, s.front_mm + origin_mm_, s.length_mm, s.correction_mm});
      if (s.handover == Handover::kNone) {
        s.handover = Handover::kRequested;
      }
    }
  }
}

WaysideUnit::StopLimitTelegramView WaysideUnit::FindTelegram(std::uint32_t train_id) const noexcept {
  for (const messages::StopLimitTelegram& t : ground_->Telegrams()) {
    if (t.train_id == train_id) {
      return &t;
    }
  }
  return nullptr;
}

// Past the boundary the next unit's limit governs: a limit beyond it is capped by the next
// unit's (with that limit's issue time, so that it lives no longer than the next unit protects
// it); without one the train stops at the boundary.
void WaysideUnit::CapAtBoundary(const Slot& s, messages::StopLimitTelegram& t) const noexcept {
  if (!boundary_mm_ || s.handover != Handover::kAccepted || t.limit_mm <= *boundary_mm_) {
    return;
  }
  if (!s.next_limit_mm) {
    t.limit_mm = *boundary_mm_ - margin_boundary_mm_;
    t.kind = messages::Obstruction::kSystemBoundary;
    return;
  }
  if (*s.next_limit_mm < t.limit_mm) {
    t.limit_mm = *s.next_limit_mm;
    t.kind = s.next_kind;
    t.issue_time_ms = std::min(t.issue_time_ms, s.next_issue_ms);
  }
}

// One telegram per train and cycle through its endpoint (REQ-TG-008, implemented in tg).
// @implements REQ-MB-024
void WaysideUnit::SendStep(std::int64_t now_ms) noexcept {
  for (Slot& s : slots_) {
    if (!s.used) {
      continue;
    }
    // the fault sends the telegram of the next slot in use
    std::uint32_t addressee = s.train_id;
    if (RAILPROOF_FAULT(FAULT_UNIT_STOP_LIMIT_WRONG_SLOT)) {
      for (std::size_t j = SlotIndex(s) + 1; j < slots_.Size(); ++j) {
        if (slots_[j].used) {
          addressee = slots_[j].train_id;
          break;
        }
      }
    }
    TrainStatus status{s.train_id, tg::LinkState::kNone, s.registered, false, std::nullopt,
                       messages::Obstruction::kNone};
    messages::Bundle bundle;
    const StopLimitTelegramView found = s.registered ? FindTelegram(addressee) : nullptr;
    if (found != nullptr) {
      messages::StopLimitTelegram t = *found;
      CapAtBoundary(s, t);
      status.limit_mm = t.limit_mm;
      status.kind = t.kind;
      (void)bundle.Add(t);
    } else {
      (void)bundle.Add(messages::KeepAlive{});
    }
    if (s.registered) {
      const auto o = ground_->Train(s.train_id);
      status.abnormal = o && o->abnormal;
    }
    if (!messages::EncodeBundle(bundle.View()).Ok()) {
      // a limit the wire cannot hold: no authority rather than a wrong one
      bundle = messages::Bundle{};
      (void)bundle.Add(messages::KeepAlive{});
      status.limit_mm.reset();
      status.kind = messages::Obstruction::kNone;
    }
    // then the crossing messages waiting, in order, as many as fit
    messages::Message* box = outbox_.begin() + SlotIndex(s) * outbox_per_slot_;  // none without crossings (null + 0)
    std::size_t taken = 0;
    while (taken < s.outbox_count && messages::AddIfFits(bundle, box[taken])) {
      ++taken;
    }
    for (std::size_t i = taken; i < s.outbox_count; ++i) {
      box[i - taken] = box[i];
    }
    s.outbox_count -= taken;
    const messages::Encoded payload = messages::EncodeBundle(bundle.View());
    TrainFrame f;
    f.train_id = s.train_id;
    const tg::Endpoint::CycleOutput sent = s.endpoint.Cycle(detail::Clock32(now_ms), payload.payload.View(), f.frame);
    status.link = sent.link;
    if (sent.status == tg::SendStatus::kSent) {
      (void)out_.frames.PushBack(f);
    }
    (void)out_.trains.PushBack(status);
  }
}

}  // namespace railproof::units
