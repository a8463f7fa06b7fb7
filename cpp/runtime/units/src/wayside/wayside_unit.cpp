// The wayside unit: configuration, trains (admission, registration, removal) and the frames
// received from them (include/railproof/units/wayside_unit.hpp; the cycle: wayside_cycle.cpp).
#include "railproof/units/wayside_unit.hpp"

#include <algorithm>
#include <new>
#include <variant>

#include "railproof/core/seeded_fault.hpp"
#include "wayside_internal.hpp"

namespace railproof::units {

using mb::wayside::CommandStatus;

WaysideUnit::~WaysideUnit() = default;

WaysideUnit::CreateResult WaysideUnit::Create(const WaysideConfig& config) noexcept {
  CreateResult result;
  std::unique_ptr<WaysideUnit> unit(new (std::nothrow) WaysideUnit());
  if (!unit) {
    result.error = ConfigError::kOutOfMemory;  // GCOVR_EXCL_LINE defensive: out of memory at initialisation
    return result;                              // GCOVR_EXCL_LINE
  }
  result.error = unit->Init(config, result);
  if (result.error == ConfigError::kNone) {
    result.unit = std::move(unit);
  }
  return result;
}

ConfigError WaysideUnit::Init(const WaysideConfig& config, CreateResult& result) noexcept {
  if (config.keys == nullptr) {
    return ConfigError::kNoKeyProvider;
  }
  tg::EndpointConfig radio = config.radio;
  radio.role = tg::Role::kGround;
  radio.own_id = config.radio_id;
  // validated with some peer other than itself: the trains' ids come at Admit
  radio.peer_id = static_cast<std::uint16_t>(config.radio_id == 0xFFFFU ? 0U : config.radio_id + 1U);
  result.radio_error = tg::Validate(radio);
  if (result.radio_error != tg::ConfigError::kNone) {
    return ConfigError::kRadioInvalid;
  }
  if (config.trains_per_base_station == 0) {
    return ConfigError::kBaseStationCapacityInvalid;
  }
  // The trains of the unit are those its base stations serve: one base station per cell
  // between the line's radio handover points (D5 §1, 12 trains each).
  const std::size_t cells = config.line.handovers.size() + 1;
  mb::wayside::Capacity capacity = config.capacity;
  capacity.trains = cells * config.trains_per_base_station;
  auto created = mb::wayside::Ground::Create(config.line, capacity, config.start_ms);
  if (created.error != mb::wayside::ConfigError::kNone) {
    result.line_error = created.error;
    result.entry = created.entry;
    return ConfigError::kLineInvalid;
  }
  ground_ = std::move(created.ground);
  if (config.secure_ahead_mm && (*config.secure_ahead_mm < 0 || *config.secure_ahead_mm > mb::wayside::kMaxLineMm)) {
    return ConfigError::kSecureAheadInvalid;
  }
  if (config.centre_link != CentreLink::kInternal && config.centre_link != CentreLink::kExternal) {
    return ConfigError::kCentreLinkInvalid;
  }
  if (config.crossings.size() > lc::kMaxCrossings) {
    return ConfigError::kTooManyCrossings;
  }
  if (config.departures > 0 && !lc::wayside::CentreScheduler::Create(config.scheduler).scheduler) {
    return ConfigError::kSchedulerInvalid;
  }
  if (config.handover_zone_begin_mm &&
      (!config.line.system_boundary_mm || *config.handover_zone_begin_mm < 0 ||
       *config.handover_zone_begin_mm >= *config.line.system_boundary_mm)) {
    return ConfigError::kHandoverZoneInvalid;
  }
  const std::size_t trains = capacity.trains;
  outbox_per_slot_ = 2 * config.crossings.size();  // one report and one acknowledgement per crossing
  // each departure sends at most one start time and one stop per crossing and cycle
  const std::size_t centre_sent = config.departures * config.crossings.size();
  // the centre link: one event per message not used (five lists), per list too long, and
  // per start time or stop beyond a controller's input
  const std::size_t link_events = 5 * kMaxLinkMessages + 6 + 2 * centre_sent;
  const std::size_t events =
      2 * trains + config.crossings.size() + 2 * kMaxNeighbourMessages + config.departures + link_events;
  if (!slots_.Allocate(trains) || !slots_.Resize(trains) || !handover_mm_.Allocate(cells) ||
      !handover_ids_.Allocate(cells) || !cell_load_.Allocate(cells) || !cell_load_.Resize(cells) ||
      !blocks_mm_.AssignFrom(config.line.blocks_mm, config.line.blocks_mm.size()) ||
      !outbox_.Allocate(trains * outbox_per_slot_) ||
      !outbox_.Resize(trains * outbox_per_slot_) || !crossings_.Allocate(config.crossings.size()) ||
      !departures_.Allocate(config.departures) || !departures_.Resize(config.departures) ||
      !departure_crossings_.Allocate(config.crossings.size()) || !profile_.AssignFrom(config.profile, config.profile.size()) ||
      !start_acks_.Allocate(kMaxLinkMessages) || !stop_acks_.Allocate(kMaxLinkMessages) ||
      !last_reports_.Allocate(std::max(kMaxLinkMessages, config.crossings.size())) ||
      !out_.start_times.Allocate(centre_sent) || !out_.warning_stops.Allocate(centre_sent) ||
      !out_.start_acks.Allocate(kMaxLinkMessages) || !out_.stop_acks.Allocate(kMaxLinkMessages) ||
      !out_.crossing_reports.Allocate(config.crossings.size()) || !out_.frames.Allocate(trains) ||
      !out_.trains.Allocate(trains) || !out_.crossings.Allocate(config.crossings.size()) ||
      !out_.departures.Allocate(config.departures) || !out_.handover_requests.Allocate(trains) ||
      !out_.handover_responses.Allocate(kMaxNeighbourMessages) || !out_.released.Allocate(trains) ||
      !out_.events.Allocate(events)) {
    return ConfigError::kOutOfMemory;  // GCOVR_EXCL_LINE defensive: out of memory at initialisation
  }
  for (const mb::wayside::HandoverConfig& h : config.line.handovers) {
    (void)handover_mm_.PushBack(h.position_mm);
    (void)handover_ids_.PushBack(h.id);
  }
  for (std::size_t i = 0; i < config.crossings.size(); ++i) {
    const lc::CrossingData& data = config.crossings[i];
    lc::wayside::ControllerConfig cc = config.controller;
    cc.crossing_id = data.id;
    auto controller = lc::wayside::CrossingController::Create(cc);
    if (FindCrossing(data.id) != nullptr || !controller.controller) {
      result.entry = i;
      return ConfigError::kCrossingInvalid;
    }
    CrossingSlot slot;
    slot.data = data;
    slot.controller = *controller.controller;
    (void)crossings_.PushBack(slot);
  }
  for (DepartureSlot& d : departures_) {
    d.scheduler = *lc::wayside::CentreScheduler::Create(config.scheduler).scheduler;
  }
  radio_ = radio;
  radio_id_ = config.radio_id;
  keys_ = config.keys;
  key_context_ = config.key_context;
  per_station_ = config.trains_per_base_station;
  secure_ahead_mm_ = config.secure_ahead_mm;
  origin_mm_ = config.origin_mm;
  zone_begin_mm_ = config.handover_zone_begin_mm;
  boundary_mm_ = config.line.system_boundary_mm;
  margin_boundary_mm_ = config.line.margins.system_boundary_mm;
  last_cycle_ms_ = config.start_ms;
  link_ = config.centre_link;
  return ConfigError::kNone;
}

// ---- trains ------------------------------------------------------------------------------------

WaysideUnit::Slot* WaysideUnit::Find(std::uint32_t train_id) noexcept {
  for (Slot& s : slots_) {
    if (s.used && s.train_id == train_id) {
      return &s;
    }
  }
  return nullptr;
}

std::size_t WaysideUnit::SlotIndex(const Slot& s) const noexcept {
  return static_cast<std::size_t>(&s - slots_.begin());
}

WaysideUnit::CrossingSlot* WaysideUnit::FindCrossing(std::uint32_t crossing_id) noexcept {
  for (CrossingSlot& c : crossings_) {
    if (c.data.id == crossing_id) {
      return &c;
    }
  }
  return nullptr;
}

const lc::wayside::CrossingController* WaysideUnit::Controller(std::uint32_t crossing_id) const noexcept {
  for (const CrossingSlot& c : crossings_) {
    if (c.data.id == crossing_id) {
      return &*c.controller;
    }
  }
  return nullptr;
}

const lc::wayside::CentreScheduler* WaysideUnit::Scheduler(std::uint32_t train_id) const noexcept {
  for (const DepartureSlot& d : departures_) {
    const auto& dep = d.scheduler->CurrentDeparture();
    if (dep && dep->train_id == train_id) {
      return &*d.scheduler;
    }
  }
  return nullptr;
}

bool WaysideUnit::HoldsDeparture(std::uint32_t departure_id) const noexcept {
  for (const DepartureSlot& d : departures_) {
    const auto& dep = d.scheduler->CurrentDeparture();
    if (dep && dep->departure_id == departure_id) {
      return true;
    }
  }
  return false;
}

// Base station (cell) i covers [handover i-1, handover i).
std::size_t WaysideUnit::CellOf(std::int64_t position_mm) const noexcept {
  std::size_t cell = 0;
  while (cell < handover_mm_.Size() && handover_mm_[cell] <= position_mm) {
    ++cell;
  }
  return cell;
}

AdmitStatus WaysideUnit::Admit(std::uint32_t train_id, std::uint16_t radio_id) noexcept {
  if (Find(train_id) != nullptr) {
    return AdmitStatus::kDuplicateTrain;
  }
  if (radio_id == radio_id_) {
    return AdmitStatus::kRadioIdInvalid;
  }
  Slot* free = nullptr;
  for (Slot& s : slots_) {
    if (!s.used) {
      free = &s;
      break;
    }
  }
  if (free == nullptr) {
    return AdmitStatus::kCapacityFull;
  }
  std::array<std::uint8_t, tg::kKeyBytes> bytes{};
  if (!keys_(key_context_, train_id, bytes)) {
    return AdmitStatus::kNoKey;
  }
  tg::EndpointConfig c = radio_;
  c.peer_id = radio_id;
  const tg::LinkKey key(bytes);
  bytes.fill(0);
  if (free->endpoint.Init(c, key) != tg::ConfigError::kNone) {
    return AdmitStatus::kRadioIdInvalid;  // GCOVR_EXCL_LINE defensive: the configuration was validated at Create
  }
  free->used = true;
  free->train_id = train_id;
  free->radio_id = radio_id;
  return AdmitStatus::kAdmitted;
}

RegisterResult WaysideUnit::Register(const mb::wayside::TrainRegistration& registration) noexcept {
  Slot* s = Find(registration.id);
  if (s == nullptr) {
    return {RegisterStatus::kNotAdmitted, mb::wayside::RegisterStatus::kRegistered};
  }
  if (s->registered) {
    return {RegisterStatus::kAlreadyRegistered, mb::wayside::RegisterStatus::kRegistered};
  }
  // the base stations under the extended range each need a free channel
  const std::int64_t begin = registration.front_mm - registration.length_mm - registration.correction_mm;
  const std::int64_t end = registration.front_mm + registration.correction_mm;
  const std::size_t first = CellOf(begin);
  const std::size_t last = end > begin ? CellOf(end - 1) : first;
  for (std::size_t c = first; c <= last && c < cell_load_.Size(); ++c) {
    if (cell_load_[c] >= per_station_) {
      return {RegisterStatus::kBaseStationFull, mb::wayside::RegisterStatus::kRegistered};
    }
  }
  const mb::wayside::RegisterStatus st = ground_->RegisterTrain(registration);
  if (st != mb::wayside::RegisterStatus::kRegistered) {
    return {RegisterStatus::kGroundRefused, st};
  }
  s->registered = true;
  s->first_cell = first;
  s->last_cell = last;
  s->front_mm = registration.front_mm;
  s->length_mm = registration.length_mm;
  s->correction_mm = registration.correction_mm;
  for (std::size_t c = first; c <= last && c < cell_load_.Size(); ++c) {
    ++cell_load_[c];
    if (c > first) {
      (void)ground_->SecureHandover(registration.id, handover_ids_[c - 1]);
    }
  }
  return {RegisterStatus::kRegistered, st};
}

void WaysideUnit::FreeSlot(Slot& s) noexcept {
  if (s.registered) {
    for (std::size_t c = s.first_cell; c <= s.last_cell && c < cell_load_.Size(); ++c) {
      --cell_load_[c];
    }
    (void)ground_->RemoveTrain(s.train_id);
  }
  s = Slot{};
}

CommandStatus WaysideUnit::Remove(std::uint32_t train_id) noexcept {
  Slot* s = Find(train_id);
  if (s == nullptr) {
    return CommandStatus::kUnknownTrain;
  }
  FreeSlot(*s);
  return CommandStatus::kAccepted;
}

// ---- received frames ---------------------------------------------------------------------------

ReceiveResult WaysideUnit::Receive(std::int64_t now_ms, std::uint32_t train_id,
                                   std::span<const std::uint8_t> frame) noexcept {
  ReceiveResult r;
  Slot* s = Find(train_id);
  if (s == nullptr) {
    r.status = FrameStatus::kUnknownTrain;
    return r;
  }
  std::array<std::uint8_t, tg::kPayloadMax> payload{};
  const tg::Endpoint::RxResult rx = s->endpoint.Receive(detail::Clock32(now_ms), frame, payload);
  r.gap = rx.gap;
  r.link = rx.link;
  if (rx.reason != tg::RejectReason::kNone) {
    r.status = FrameStatus::kFrameRejected;
    r.tg_reason = rx.reason;
    return r;
  }
  const messages::DecodedBundle d =
      messages::DecodeBundle(std::span<const std::uint8_t>(payload).first(rx.header.payload_len));
  if (!d.Ok()) {
    r.status = FrameStatus::kPayloadInvalid;
    r.decode_error = d.error;
    r.field = d.field;
    r.entry = d.entry;
    return r;
  }
  for (const messages::Message& m : d.bundle.View()) {
    r.messages[r.message_count] = Dispatch(*s, m);
    ++r.message_count;
  }
  return r;
}

namespace {

// The train a train -> ground message names (0 for those that name none).
struct NamedTrain {
  std::uint32_t operator()(const messages::PositionReport& m) const noexcept { return m.train_id; }
  std::uint32_t operator()(const messages::CrossingRequest& m) const noexcept { return m.train_id; }
  std::uint32_t operator()(const messages::CrossingWithdrawal& m) const noexcept { return m.request.train_id; }
  std::uint32_t operator()(const messages::CentrePositionReport& m) const noexcept { return m.train_id; }
  template <typename T>
  std::uint32_t operator()(const T& /*m*/) const noexcept {
    return 0;
  }
};

}  // namespace

// Routes one received message to the module that owns it (reports: REQ-MB-001 in mb; crossing
// requests and withdrawals: REQ-LC-002, REQ-LC-004, sent by the on-board unit, taken by lc).
MessageResult WaysideUnit::Dispatch(Slot& s, const messages::Message& m) noexcept {
  MessageResult r;
  r.type = messages::TypeOf(m);
  const bool names_train = std::holds_alternative<messages::PositionReport>(m) ||
                           std::holds_alternative<messages::CrossingRequest>(m) ||
                           std::holds_alternative<messages::CrossingWithdrawal>(m) ||
                           std::holds_alternative<messages::CentrePositionReport>(m);
  if (!names_train) {
    // a train has no position (nothing for the ground); the ground's own messages never come
    // from a train
    r.status = std::holds_alternative<messages::NoPosition>(m) ? MessageStatus::kAccepted : MessageStatus::kUnexpectedType;
    return r;
  }
  // a link speaks for its own train only
  if (std::visit(NamedTrain{}, m) != s.train_id) {
    r.status = MessageStatus::kWrongTrain;
    return r;
  }
  if (const auto* rep = std::get_if<messages::PositionReport>(&m)) {
    r.report = ground_->OnReport(*rep);
    if (r.report != mb::wayside::ReportStatus::kAccepted) {
      r.status = MessageStatus::kReportRejected;
      return r;
    }
    s.front_mm = blocks_mm_[rep->front_block] + rep->offset_mm;  // accepted: the block is on the line
    s.length_mm = rep->length_mm;
    s.correction_mm = rep->correction_mm;
    return r;
  }
  if (const auto* cpr = std::get_if<messages::CentrePositionReport>(&m)) {
    for (DepartureSlot& d : departures_) {
      const auto& dep = d.scheduler->CurrentDeparture();
      if (dep && dep->train_id == s.train_id) {
        messages::CentrePositionReport p = *cpr;
        if (RAILPROOF_FAULT(FAULT_UNIT_ENVELOPE_REAR_AS_FRONT)) {
          p.front_mm = cpr->rear_mm;
        }
        d.position = p;
        return r;
      }
    }
    r.status = MessageStatus::kNoDeparture;
    return r;
  }
  const bool request = std::holds_alternative<messages::CrossingRequest>(m);
  const messages::CrossingRequest& q =
      request ? std::get<messages::CrossingRequest>(m) : std::get<messages::CrossingWithdrawal>(m).request;
  CrossingSlot* c = FindCrossing(q.crossing_id);
  if (c == nullptr) {
    r.status = MessageStatus::kUnknownCrossing;
    return r;
  }
  std::size_t& count = request ? c->request_count : c->withdrawal_count;
  auto& list = request ? c->requests : c->withdrawals;
  if (count >= list.size()) {
    r.status = MessageStatus::kQueueFull;
    return r;
  }
  if (!(request && RAILPROOF_FAULT(FAULT_UNIT_CROSSING_REQUEST_DROPPED))) {
    list[count] = s.train_id;
    ++count;
  }
  return r;
}

lc::wayside::SchedulerError WaysideUnit::StartDeparture(const lc::wayside::Departure& departure,
                                                        std::span<const std::uint32_t> crossing_ids,
                                                        std::int64_t now_ms) noexcept {
  departure_crossings_.Clear();
  for (const std::uint32_t id : crossing_ids) {
    const CrossingSlot* c = FindCrossing(id);
    if (c == nullptr || !departure_crossings_.PushBack(c->data)) {
      return lc::wayside::SchedulerError::kCrossingDataInvalid;
    }
  }
  // the train's previous departure is replaced; else the first scheduler without one
  DepartureSlot* slot = nullptr;
  for (DepartureSlot& d : departures_) {
    const auto& dep = d.scheduler->CurrentDeparture();
    if (dep && dep->train_id == departure.train_id) {
      slot = &d;
      break;
    }
    if (!dep && slot == nullptr) {
      slot = &d;
    }
  }
  if (slot == nullptr) {
    return lc::wayside::SchedulerError::kTooManyMessages;
  }
  slot->position.reset();
  return slot->scheduler->StartDeparture(departure, departure_crossings_.Span(), profile_.Span(), now_ms);
}

}  // namespace railproof::units
