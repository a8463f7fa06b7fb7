// The wayside unit: the ground-side modules composed into one ground computer that runs on the
// ground cycle (spec/design/units.md, the wayside section):
//   radio     one telegram endpoint (tg::Endpoint, ground role) per admitted train; the trains
//             of each base station up to its capacity (D5 §1: one base station serves 12
//             trains); the base stations are the cells between the radio handover points of
//             the line, and the unit secures a handover only when the next cell has room
//   tracking  the moving-block ground (mb::wayside::Ground): registration, position reports,
//             interlocking, possessions, restrictions, stop limits, the system boundary
//   crossings one lc::wayside::CrossingController per crossing of the line, and the centre
//             schedulers of the GNSS-time pre-armed departures (lc::wayside::CentreScheduler)
//   boundary  handover of a train to the neighbouring unit at the system boundary (below)
//   centre    the link between the centre schedulers and the crossing controllers (below)
// Train and ground meet only in railproof_messages (the payload codec) and the telegram layer.
//
// Usage (the line simulator, or a ground computer's main loop):
//   auto created = WaysideUnit::Create(config);        // validates, allocates everything once
//   WaysideUnit& unit = *created.unit;
//   unit.Admit(train_id, radio_id);                     // the train entered the radio area
//   unit.Register({train_id, length, front, correction, InitialPosition::kEntryBalise});
//   between cycles: unit.Receive(now, train_id, frame bytes) for every received frame;
//                   commands (RequestPossession, ..., StartDeparture)
//   every ground cycle (params::tg::ground_cycle_ms):
//     const CycleOutput& out = unit.Cycle(now, inputs);  // crossing sensors, neighbour messages
//     send out.frames[i].frame to train out.frames[i].train_id; drive out.crossings; hand
//     out.handover_requests / out.handover_responses to the neighbouring units; with an
//     external centre link, carry out.ToCrossingsSent() / out.ToCentreSent() (below).
//
// Handover at the system boundary (D5 §5.1.4 obstruction 5; mb's system boundary, REQ-MB-023).
// The releasing unit's line ends past its system boundary (the overlap with the next unit,
// which is at least the longest train plus its margins); the next unit's line starts before
// it. Positions between units are global chainage (each unit's origin_mm + its own chainage).
//   1. While a train's extended front end lies in the overlap (>= handover_zone_begin_mm) and it
//      has not been released, the releasing unit sends a HandoverRequest every cycle.
//   2. The accepting unit answers every request: a train it does not know yet is admitted and
//      registered at the handed-over position (room in its entry base station, no overlap with
//      another train); once known, the answer carries the limit it issued to the train.
//   3. The releasing unit accepts at its boundary (Ground::AcceptAtBoundary) only while the
//      foremost train before the boundary is accepted with a limit known; a limit it sends past
//      the boundary is capped by the accepting unit's limit (with that limit's issue time): the
//      accepting unit's stop limit governs past the boundary. A refused train stops at the
//      boundary minus its margin.
//   4. The releasing unit removes the train once its extended rear has passed the boundary.
//
// The centre link (GNSS-time variant, lc design §5, D4 §4.8.2). The centre schedulers send
// start times and warning stops to the crossing controllers; the controllers answer with
// acknowledgements and their reports. Each cycle runs the schedulers before the controllers,
// and CycleOutput lists what each side sent in it.
//   kInternal  the centre and the crossings in one place: the unit delivers the start times and
//              stops to the controllers in the same cycle, the acknowledgements and reports to
//              the schedulers in the next one (the link input is refused, kLinkNotExternal).
//   kExternal  the crossings elsewhere, behind a ground network that may lose, delay or repeat
//              messages (lc design §5 tolerates each): the integrator carries them, from
//              out.ToCrossingsSent() of the unit holding the departures to
//              CycleInput::to_crossings of the unit holding the crossings, and from
//              out.ToCentreSent() back to
//              CycleInput::to_centre; one unit may hold both ends. A received message naming a
//              crossing the unit does not hold, or an acknowledgement naming a departure none of
//              its schedulers holds, is not used (kUnknownCrossing, kUnknownDeparture).
//
// Runtime module: no heap after Create, no exceptions, no recursion, bounded loops, typed
// results, deterministic. Units: mm, mm/s, ms (int64); the telegram layer's clock is now_ms
// modulo 2^32.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/core/fixed_vector.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"
#include "railproof/mb/wayside/ground.hpp"
#include "railproof/messages/codec.hpp"
#include "railproof/tg/aead.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"

namespace railproof::units {

// D5 §1 (digest §1): one base station serves 12 trains (spec/parameters/tg.yaml
// trains_per_base_station).
inline constexpr auto kTrainsPerBaseStation = static_cast<std::size_t>(params::tg::trains_per_base_station);
// The ground cycle (spec/parameters/tg.yaml ground_cycle_ms, D5 §1).
inline constexpr std::int64_t kGroundCycleMs = params::tg::ground_cycle_ms;
// Most neighbour messages (requests or responses) per cycle and direction.
inline constexpr std::size_t kMaxNeighbourMessages = 16;
// Most messages per list of the centre link per cycle and direction (the schedulers' limit).
inline constexpr std::size_t kMaxLinkMessages = lc::wayside::kMaxSchedulerMessages;

// Who carries the messages between the centre schedulers and the crossing controllers (above).
enum class CentreLink : std::uint8_t { kInternal, kExternal };

constexpr const char* ToString(CentreLink l) noexcept {
  return core::EnumName(l, std::array<const char*, 2>{"INTERNAL", "EXTERNAL"});
}

// The link key of a train (the key management of the line, outside the unit): true and `key`
// filled, or false if the train has none.
using KeyProvider = bool (*)(const void* context, std::uint32_t train_id, std::array<std::uint8_t, tg::kKeyBytes>& key);

struct WaysideConfig {
  std::uint16_t radio_id = static_cast<std::uint16_t>(params::tg::ground_id);
  // the telegram layer's parameters (role and ids are set per train); DeploymentConfig by default
  tg::EndpointConfig radio = tg::DeploymentConfig(tg::Role::kGround, static_cast<std::uint16_t>(params::tg::ground_id),
                                                 static_cast<std::uint16_t>(params::tg::ground_id + 1));
  KeyProvider keys = nullptr;
  const void* key_context = nullptr;
  // the running line and the ground's capacities; capacity.trains is the base stations'
  // capacity (ignored here: (handovers + 1) x trains_per_base_station)
  mb::wayside::LineConfig line{};
  mb::wayside::Capacity capacity{};
  std::size_t trains_per_base_station = kTrainsPerBaseStation;
  // a handover point is secured for a train when its extended front end is this close (mm);
  // none: only by command (SecureHandover)
  std::optional<std::int64_t> secure_ahead_mm;
  // crossings of the line (ids unique), each with one controller of these parameters
  std::span<const lc::CrossingData> crossings;
  lc::wayside::ControllerConfig controller = lc::wayside::DefaultControllerConfig(0);
  // GNSS-time variant: departures scheduled at once (0: not used), their scheduler parameters
  // and the permitted-speed profile of the line
  std::size_t departures = 0;
  lc::wayside::SchedulerConfig scheduler{};
  std::span<const core::RestrictionSegment> profile;
  CentreLink centre_link = CentreLink::kInternal;
  // global chainage of the line's 0, and where the next unit's area begins (local, < the
  // system boundary; requires one)
  std::int64_t origin_mm = 0;
  std::optional<std::int64_t> handover_zone_begin_mm;
  std::int64_t start_ms = 0;
};

enum class ConfigError : std::uint8_t {
  kNone,
  kNoKeyProvider,
  kRadioInvalid,          // see radio_error
  kLineInvalid,           // see line_error and entry
  kBaseStationCapacityInvalid,  // 0
  kSecureAheadInvalid,    // < 0 or > kMaxLineMm
  kTooManyCrossings,      // more than lc::kMaxCrossings
  kCrossingInvalid,       // duplicate id, or refused by the controller (entry)
  kSchedulerInvalid,      // departures > 0 and the scheduler parameters refused
  kHandoverZoneInvalid,   // without a system boundary, or not in [0, boundary)
  kOutOfMemory,
  kCentreLinkInvalid,     // not a CentreLink
};

constexpr const char* ToString(ConfigError e) noexcept {
  return core::EnumName(e, std::array<const char*, 12>{"NONE", "NO_KEY_PROVIDER", "RADIO_INVALID", "LINE_INVALID", "BASE_STATION_CAPACITY_INVALID", "SECURE_AHEAD_INVALID", "TOO_MANY_CROSSINGS", "CROSSING_INVALID", "SCHEDULER_INVALID", "HANDOVER_ZONE_INVALID", "OUT_OF_MEMORY", "CENTRE_LINK_INVALID"});
}

enum class AdmitStatus : std::uint8_t {
  kAdmitted,
  kDuplicateTrain,
  kCapacityFull,  // every radio slot of the unit's base stations is in use
  kRadioIdInvalid,  // the unit's own radio id
  kNoKey,           // the key provider has no key for the train
};

constexpr const char* ToString(AdmitStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 5>{"ADMITTED", "DUPLICATE_TRAIN", "CAPACITY_FULL", "RADIO_ID_INVALID", "NO_KEY"});
}

enum class RegisterStatus : std::uint8_t {
  kRegistered,
  kNotAdmitted,
  kAlreadyRegistered,
  kBaseStationFull,  // a base station under the train's extended range has no room
  kGroundRefused,    // see ground (mb::wayside::RegisterStatus)
};

constexpr const char* ToString(RegisterStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 5>{"REGISTERED", "NOT_ADMITTED", "ALREADY_REGISTERED", "BASE_STATION_FULL", "GROUND_REFUSED"});
}

struct RegisterResult {
  RegisterStatus status = RegisterStatus::kRegistered;
  mb::wayside::RegisterStatus ground = mb::wayside::RegisterStatus::kRegistered;
};

// What became of one received frame (Receive). A frame the telegram layer or the codec
// refuses changes nothing; otherwise each message has its own status.
enum class FrameStatus : std::uint8_t {
  kAccepted,
  kUnknownTrain,    // no radio slot for the train
  kFrameRejected,   // tg_reason
  kPayloadInvalid,  // decode_error, field, entry (the codec's reasons)
};

constexpr const char* ToString(FrameStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 4>{"ACCEPTED", "UNKNOWN_TRAIN", "FRAME_REJECTED", "PAYLOAD_INVALID"});
}

enum class MessageStatus : std::uint8_t {
  kAccepted,
  kReportRejected,   // report (mb::wayside::ReportStatus)
  kWrongTrain,       // names another train than the link's
  kUnknownCrossing,
  kQueueFull,        // more requests or withdrawals for a crossing in one cycle than it takes
  kNoDeparture,      // a centre position report without a departure of the train
  kUnexpectedType,   // a ground -> train message from a train
};

constexpr const char* ToString(MessageStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 7>{"ACCEPTED", "REPORT_REJECTED", "WRONG_TRAIN", "UNKNOWN_CROSSING", "QUEUE_FULL", "NO_DEPARTURE", "UNEXPECTED_TYPE"});
}

struct MessageResult {
  messages::MessageType type = messages::MessageType::kNoPosition;
  MessageStatus status = MessageStatus::kAccepted;
  mb::wayside::ReportStatus report = mb::wayside::ReportStatus::kAccepted;
};

struct ReceiveResult {
  FrameStatus status = FrameStatus::kAccepted;
  tg::RejectReason tg_reason = tg::RejectReason::kNone;
  std::uint32_t gap = 0;  // telegrams lost before this one (tg::Endpoint::RxResult::gap)
  tg::LinkState link = tg::LinkState::kNone;  // the train's link after this frame
  messages::DecodeError decode_error = messages::DecodeError::kNone;
  messages::Field field = messages::Field::kNone;
  std::size_t entry = 0;
  std::array<MessageResult, messages::kBundleMax> messages{};
  std::size_t message_count = 0;
  [[nodiscard]] std::span<const MessageResult> Messages() const noexcept { return {messages.data(), message_count}; }
};

// ---- cycle inputs and outputs ----------------------------------------------------------------

// The equipment of one crossing this cycle. A crossing without an entry detects nothing (both
// false: the barrier timers then fail it, the safe side).
struct CrossingSensors {
  std::uint32_t crossing_id = 0;
  bool barrier_down = false;
  bool barrier_up = false;
  lc::wayside::ClockInput clock = lc::wayside::ClockInput::kGnss;
};

// Centre -> crossing controllers (the centre link): the departures' start times and stops.
struct ToCrossings {
  std::span<const lc::wayside::StartTimeMessage> start_times;
  std::span<const lc::wayside::WarningStopMessage> warning_stops;
};

// Crossing controllers -> centre: the acknowledgements and the crossings' reports (the centre
// takes a crossing's clock fault from its last report).
struct ToCentre {
  std::span<const lc::wayside::StartTimeAck> start_acks;
  std::span<const lc::wayside::WarningStopAck> stop_acks;
  std::span<const messages::CrossingReport> reports;
};

// Releasing unit -> accepting unit (global chainage).
struct HandoverRequest {
  std::uint32_t train_id = 0;
  std::uint16_t radio_id = 0;
  std::int64_t front_mm = 0;
  std::int64_t length_mm = 0;
  std::int64_t correction_mm = 0;
};

enum class HandoverVerdict : std::uint8_t {
  kAccepted,
  kNoRoom,        // no radio slot, or its entry base station is full
  kTrackNotClear, // the ground refuses the position (another train, off the line, ...)
};

constexpr const char* ToString(HandoverVerdict v) noexcept {
  return core::EnumName(v, std::array<const char*, 3>{"ACCEPTED", "NO_ROOM", "TRACK_NOT_CLEAR"});
}

// Accepting unit -> releasing unit: the verdict and, once accepted, the accepting unit's last
// issued limit for the train (global chainage) and its issue time.
struct HandoverResponse {
  std::uint32_t train_id = 0;
  HandoverVerdict verdict = HandoverVerdict::kNoRoom;
  std::optional<std::int64_t> limit_mm;
  messages::Obstruction kind = messages::Obstruction::kNone;
  std::int64_t issue_time_ms = 0;
};

struct CycleInput {
  std::span<const CrossingSensors> crossings;
  std::span<const HandoverRequest> from_previous;   // requests of the unit before this one
  std::span<const HandoverResponse> from_next;      // answers of the unit after this one
  // CentreLink::kExternal: what the crossings and the centre received since the last cycle
  ToCrossings to_crossings;
  ToCentre to_centre;
};

// Why a cycle input was not used.
enum class InputStatus : std::uint8_t {
  kUnknownCrossing,        // sensors of a crossing the unit does not hold
  kUnknownTrain,           // an answer about a train the unit is not handing over
  kTooManyMessages,        // neighbour messages beyond kMaxNeighbourMessages (ignored)
  kControllerRefused,      // a controller refused its cycle (controller_error)
  kSchedulerRefused,       // a scheduler refused its cycle
  kBaseStationFull,        // a handover point ahead of the train cannot be secured (no room)
  kHandoverRefused,        // the next unit refused the train (verdict)
  kUnknownDeparture,       // a centre-link acknowledgement of a departure no scheduler holds
  kLinkNotExternal,        // centre-link messages given to a unit that connects them itself
};

constexpr const char* ToString(InputStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 9>{"UNKNOWN_CROSSING", "UNKNOWN_TRAIN", "TOO_MANY_MESSAGES", "CONTROLLER_REFUSED", "SCHEDULER_REFUSED", "BASE_STATION_FULL", "HANDOVER_REFUSED", "UNKNOWN_DEPARTURE", "LINK_NOT_EXTERNAL"});
}

struct InputEvent {
  InputStatus status = InputStatus::kUnknownCrossing;
  std::uint32_t id = 0;  // the crossing, train or departure
  HandoverVerdict verdict = HandoverVerdict::kAccepted;
};

struct TrainFrame {
  std::uint32_t train_id = 0;
  tg::EncodedFrame frame{};
};

// Per train after the cycle: its link, tracking and the limit actually sent (after the cap of
// a handover), or none (keep-alive).
struct TrainStatus {
  std::uint32_t train_id = 0;
  tg::LinkState link = tg::LinkState::kNone;
  bool registered = false;
  bool abnormal = false;
  std::optional<std::int64_t> limit_mm;
  messages::Obstruction kind = messages::Obstruction::kNone;
};

// Equipment commands and the report of one crossing.
struct CrossingOutput {
  std::uint32_t crossing_id = 0;
  bool lights_on = false;
  bool barriers_down_commanded = false;
  bool alarm = false;
  messages::CrossingReport report{};
};

struct DepartureOutput {
  std::uint32_t train_id = 0;
  std::uint32_t departure_id = 0;
  bool cleared = false;
  lc::wayside::DepartureBlock block = lc::wayside::DepartureBlock::kNoDeparture;
};

enum class CycleStatus : std::uint8_t { kDone, kClockWentBack };

struct CycleOutput {
  CycleStatus status = CycleStatus::kDone;
  core::FixedVector<TrainFrame> frames;
  core::FixedVector<TrainStatus> trains;
  core::FixedVector<CrossingOutput> crossings;
  core::FixedVector<DepartureOutput> departures;
  core::FixedVector<HandoverRequest> handover_requests;    // to the next unit
  core::FixedVector<HandoverResponse> handover_responses;  // to the previous unit
  core::FixedVector<std::uint32_t> released;               // trains handed over and removed
  // the centre link this cycle (kInternal: already delivered, listed for the record)
  core::FixedVector<lc::wayside::StartTimeMessage> start_times;  // centre -> crossings
  core::FixedVector<lc::wayside::WarningStopMessage> warning_stops;
  core::FixedVector<lc::wayside::StartTimeAck> start_acks;       // crossings -> centre
  core::FixedVector<lc::wayside::WarningStopAck> stop_acks;
  core::FixedVector<messages::CrossingReport> crossing_reports;
  core::FixedVector<InputEvent> events;

  // Views valid until the unit's next Cycle (copy them to hand them back to the same unit).
  [[nodiscard]] ToCrossings ToCrossingsSent() const noexcept { return {start_times.Span(), warning_stops.Span()}; }
  [[nodiscard]] ToCentre ToCentreSent() const noexcept {
    return {start_acks.Span(), stop_acks.Span(), crossing_reports.Span()};
  }
};

// ---- the unit ----------------------------------------------------------------------------------

// @implements REQ-MB-017
// @implements REQ-MB-021
// @implements REQ-MB-023
// @implements REQ-MB-024
class WaysideUnit {
 public:
  struct CreateResult {
    ConfigError error = ConfigError::kNone;
    mb::wayside::ConfigError line_error = mb::wayside::ConfigError::kNone;
    tg::ConfigError radio_error = tg::ConfigError::kNone;
    std::size_t entry = 0;
    std::unique_ptr<WaysideUnit> unit;  // non-null iff error == kNone
  };

  static CreateResult Create(const WaysideConfig& config) noexcept;

  WaysideUnit(const WaysideUnit&) = delete;
  WaysideUnit& operator=(const WaysideUnit&) = delete;
  WaysideUnit(WaysideUnit&&) = delete;
  WaysideUnit& operator=(WaysideUnit&&) = delete;
  ~WaysideUnit();

  // -- trains --
  AdmitStatus Admit(std::uint32_t train_id, std::uint16_t radio_id) noexcept;
  RegisterResult Register(const mb::wayside::TrainRegistration& registration) noexcept;
  // The train left the area: its registration and radio slot are dropped.
  mb::wayside::CommandStatus Remove(std::uint32_t train_id) noexcept;

  // One frame received from the train's link at now_ms.
  ReceiveResult Receive(std::int64_t now_ms, std::uint32_t train_id, std::span<const std::uint8_t> frame) noexcept;

  // -- commands of system management and the centre (forwarded to the module that owns them) --
  mb::wayside::CommandStatus RequestRoute(std::uint32_t id) noexcept { return ground_->RequestRoute(id); }
  mb::wayside::CommandStatus FreeRoute(std::uint32_t id) noexcept { return ground_->FreeRoute(id); }
  mb::wayside::CommandResult RequestPossession(core::Section s) noexcept { return ground_->RequestPossession(s); }
  mb::wayside::CommandStatus CancelPossession(std::uint32_t id) noexcept { return ground_->CancelPossession(id); }
  mb::wayside::CommandResult RequestSpeedRestriction(core::Section s, std::int64_t v) noexcept {
    return ground_->RequestSpeedRestriction(s, v);
  }
  mb::wayside::CommandStatus ConfirmSpeedRestriction(std::uint32_t id) noexcept { return ground_->ConfirmSpeedRestriction(id); }
  mb::wayside::CommandStatus CancelSpeedRestriction(std::uint32_t id) noexcept { return ground_->CancelSpeedRestriction(id); }
  mb::wayside::CommandResult ReportUnequippedOccupancy(core::Section s) noexcept {
    return ground_->ReportUnequippedOccupancy(s);
  }
  mb::wayside::CommandStatus ClearUnequippedOccupancy(std::uint32_t id) noexcept {
    return ground_->ClearUnequippedOccupancy(id);
  }
  mb::wayside::CommandStatus SecureHandover(std::uint32_t train_id, std::uint32_t handover_id) noexcept {
    return ground_->SecureHandover(train_id, handover_id);
  }
  // only without a next unit (handover_zone_begin_mm): else the unit decides
  mb::wayside::CommandStatus AcceptAtBoundary(bool accepted) noexcept { return ground_->AcceptAtBoundary(accepted); }
  // Starts a GNSS-time departure over the crossings `crossing_ids` (all held by the unit).
  lc::wayside::SchedulerError StartDeparture(const lc::wayside::Departure& departure,
                                             std::span<const std::uint32_t> crossing_ids, std::int64_t now_ms) noexcept;

  // -- the ground cycle --
  const CycleOutput& Cycle(std::int64_t now_ms, const CycleInput& input) noexcept;

  // -- read-only views --
  [[nodiscard]] const mb::wayside::Ground& Ground() const noexcept { return *ground_; }
  [[nodiscard]] std::size_t TrainCapacity() const noexcept { return slots_.Size(); }
  [[nodiscard]] std::size_t BaseStationCount() const noexcept { return cell_load_.Size(); }
  [[nodiscard]] std::size_t BaseStationLoad(std::size_t cell) const noexcept { return cell_load_[cell]; }
  [[nodiscard]] const lc::wayside::CrossingController* Controller(std::uint32_t crossing_id) const noexcept;
  // the scheduler of the train's departure, or null
  [[nodiscard]] const lc::wayside::CentreScheduler* Scheduler(std::uint32_t train_id) const noexcept;
  [[nodiscard]] const CycleOutput& LastOutput() const noexcept { return out_; }

 private:
  enum class Handover : std::uint8_t { kNone, kRequested, kAccepted, kRefused };
  struct Slot {
    bool used = false;
    bool registered = false;
    bool answer_previous = false;  // the previous unit asked about the train this cycle
    std::uint32_t train_id = 0;
    std::uint16_t radio_id = 0;
    tg::Endpoint endpoint;
    std::size_t first_cell = 0;  // base stations [first_cell, last_cell] hold a channel
    std::size_t last_cell = 0;
    std::int64_t front_mm = 0;   // last accepted report (local chainage)
    std::int64_t length_mm = 0;
    std::int64_t correction_mm = 0;
    Handover handover = Handover::kNone;
    std::optional<std::int64_t> next_limit_mm;  // the next unit's limit (local chainage)
    messages::Obstruction next_kind = messages::Obstruction::kNone;
    std::int64_t next_issue_ms = 0;
    std::size_t outbox_count = 0;  // messages waiting in outbox_[slot * outbox_per_slot_ ...]
  };
  struct CrossingSlot {
    lc::CrossingData data{};
    std::optional<lc::wayside::CrossingController> controller;
    std::array<std::uint32_t, lc::wayside::kMaxControllerMessages> requests{};
    std::size_t request_count = 0;
    std::array<std::uint32_t, lc::wayside::kMaxControllerMessages> withdrawals{};
    std::size_t withdrawal_count = 0;
    std::array<lc::wayside::StartTimeMessage, lc::wayside::kMaxControllerMessages> start_times{};
    std::size_t start_time_count = 0;
    std::array<lc::wayside::WarningStopMessage, lc::wayside::kMaxControllerMessages> stops{};
    std::size_t stop_count = 0;
  };
  struct DepartureSlot {
    std::optional<lc::wayside::CentreScheduler> scheduler;
    std::optional<messages::CentrePositionReport> position;
  };

  WaysideUnit() noexcept = default;
  ConfigError Init(const WaysideConfig& config, CreateResult& result) noexcept;

  [[nodiscard]] Slot* Find(std::uint32_t train_id) noexcept;
  [[nodiscard]] std::size_t SlotIndex(const Slot& s) const noexcept;
  [[nodiscard]] CrossingSlot* FindCrossing(std::uint32_t crossing_id) noexcept;
  [[nodiscard]] std::size_t CellOf(std::int64_t position_mm) const noexcept;
  void FreeSlot(Slot& s) noexcept;
  MessageResult Dispatch(Slot& s, const messages::Message& m) noexcept;
  void Enqueue(Slot& s, const messages::Message& m) noexcept;

  // cycle steps (wayside_cycle.cpp)
  void ChannelStep() noexcept;
  void AnswerPrevious(std::span<const HandoverRequest> requests) noexcept;
  void TakeAnswers(std::span<const HandoverResponse> answers) noexcept;
  void BoundaryAcceptance() noexcept;
  [[nodiscard]] bool HoldsDeparture(std::uint32_t departure_id) const noexcept;
  void ReceiveAtCentre(const ToCentre& in) noexcept;
  void CentreStep(std::int64_t now_ms) noexcept;
  void DeliverToCrossings(const ToCrossings& in) noexcept;
  void CrossingStep(std::int64_t now_ms, std::span<const CrossingSensors> sensors) noexcept;
  void ReleaseAndRequest() noexcept;
  using StopLimitTelegramView = const messages::StopLimitTelegram*;
  [[nodiscard]] StopLimitTelegramView FindTelegram(std::uint32_t train_id) const noexcept;
  void CapAtBoundary(const Slot& s, messages::StopLimitTelegram& t) const noexcept;
  void SendStep(std::int64_t now_ms) noexcept;
  void Event(InputStatus status, std::uint32_t id, HandoverVerdict verdict = HandoverVerdict::kAccepted) noexcept;

  std::uint16_t radio_id_ = 0;
  tg::EndpointConfig radio_{};
  KeyProvider keys_ = nullptr;
  const void* key_context_ = nullptr;
  std::size_t per_station_ = 0;
  std::optional<std::int64_t> secure_ahead_mm_;
  std::int64_t origin_mm_ = 0;
  std::optional<std::int64_t> zone_begin_mm_;
  std::optional<std::int64_t> boundary_mm_;
  std::int64_t margin_boundary_mm_ = 0;
  std::int64_t last_cycle_ms_ = 0;

  std::unique_ptr<mb::wayside::Ground> ground_;
  core::FixedVector<Slot> slots_;
  core::FixedVector<std::int64_t> handover_mm_;   // the line's handover points (cell ends)
  core::FixedVector<std::uint32_t> handover_ids_;
  core::FixedVector<std::uint32_t> cell_load_;    // trains holding a channel per base station
  std::size_t outbox_per_slot_ = 0;
  core::FixedVector<messages::Message> outbox_;
  core::FixedVector<CrossingSlot> crossings_;
  core::FixedVector<DepartureSlot> departures_;
  core::FixedVector<lc::CrossingData> departure_crossings_;  // StartDeparture scratch
  core::FixedVector<std::int64_t> blocks_mm_;     // virtual block boundaries of the line (reports to fronts)
  core::FixedVector<core::RestrictionSegment> profile_;
  // what the centre takes in its next step: the controllers' last cycle (kInternal), or the
  // link input accepted (kExternal)
  CentreLink link_ = CentreLink::kInternal;
  core::FixedVector<lc::wayside::StartTimeAck> start_acks_;
  core::FixedVector<lc::wayside::WarningStopAck> stop_acks_;
  core::FixedVector<messages::CrossingReport> last_reports_;
  CycleOutput out_;
};

}  // namespace railproof::units
