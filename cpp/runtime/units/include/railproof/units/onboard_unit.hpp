// The on-board unit (spec/design/units.md): the train-side capabilities composed into one
// cycle. Every on-board cycle (the odometry's cycle, params::ra::cycle_ms = 100 ms, D1 §3):
//   1. odometry (ra::Odometry) from the raw sensor sample and a balise read looked up in the
//      line's balise table -> the position envelope;
//   2. the held temporary restrictions follow the envelope's rear (REQ-MB-015);
//   3. when the radio is due (every radio_period_ms, by default the telegram layer's train
//      cycle params::tg::train_cycle_ms = 1000 ms, D5 §5.1.3): one telegram of one bundle, the
//      position report built from the envelope (or NO_POSITION) first, then the pending
//      crossing requests and withdrawals that fit (the rest first in the next telegram);
//   4. the received frames: telegram layer (tg::Endpoint), codec (messages::DecodeBundle), then
//      each message: stop limit -> mb::onboard::AuthorityReceiver and the restriction store,
//      crossing reports and withdrawal acknowledgements -> the crossing protection;
//   5. crossing protection (lc::onboard::CrossingProtection) with the envelope, the supervised
//      speed and the merged permitted-speed profile;
//   6. when supervision is due (every SupervisionParams::cycle_ms, params::br::cycle_ms =
//      200 ms): br::PatternCalculator against the nearer of the usable movement authority and
//      the crossing protection limit, then br::Supervisor;
//   7. the brake demand: the radio link (REQ-TG-014), the odometry's stop demand (REQ-RA-013)
//      and the supervision decision.
// The telegram of step 3 is sent before the frames of the cycle are read (a tick, then what
// arrived, as the telegram model orders them): crossing messages decided in a cycle leave
// with the next telegram.
//
// Handover between wayside units (OnboardConfig::radio_areas; spec/design/units.md). The
// line may be served by several wayside units, each from its origin on (its own chainage
// starts there) to past its system boundary; the next unit's origin lies before that
// boundary and begins the handover zone. The unit holds two preallocated links:
//   - the first, to the unit of the area the train is in; the second is opened (the same
//     telegram layer set-up) when the front enters the zone before the first's boundary;
//   - while both are open the train reports to both, each report in that unit's chainage
//     (ToArea/FromArea: the one conversion), and obeys the more restrictive limit; without a
//     usable limit of the next unit it obeys no limit past the boundary, and its link counts
//     for the brake demand only once the safe front is past the boundary;
//   - once the rearmost rear has passed the boundary the first unit's limit and link no
//     longer count; the first link is dropped when it is no longer up (the releasing unit
//     removes the train once its extended rear has passed and then stops sending to it), and
//     the second becomes the first.
// The outputs name the area of each telegram sent (radio_area: `frame`, handover_area:
// `handover_frame`); the next cycle's `frames` and `handover_frames` are those of the same
// areas' units.
//
// Runtime rules: all storage allocated by Create, none after; no exceptions; typed errors for
// the configuration and for every rejected input; deterministic (same inputs, same outputs).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "railproof/br/patterns.hpp"
#include "railproof/br/supervisor.hpp"
#include "railproof/core/enum_names.hpp"
#include "railproof/core/fixed_vector.hpp"
#include "railproof/core/track.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/mb/onboard/authority.hpp"
#include "railproof/messages/codec.hpp"
#include "railproof/ra/odometry.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"

namespace railproof::units {

// The unit's cycle: the odometry's (D1 §3).
inline constexpr std::int64_t kOnboardCycleMs = params::ra::cycle_ms;
// Frames read in one cycle; more are dropped (RxStatus::kFramesDropped).
inline constexpr std::size_t kMaxFramesPerCycle = 8;
// Events reported per cycle: one per message of every frame read, and the dropped frames.
inline constexpr std::size_t kMaxRxEvents = kMaxFramesPerCycle * messages::kBundleMax + 1;

// ---- configuration -----------------------------------------------------------------------

// A balise of the checked track database: its id and the line position it fixes.
struct BaliseEntry {
  std::uint32_t id = 0;
  std::int64_t position_mm = 0;
};

// The line as the train knows it (the on-board track database, D5 §5.1.1).
struct LineData {
  std::span<const std::int64_t> blocks_mm;                  // virtual-block boundaries: [0] = 0,
                                                            // increasing, back() = line end
  std::span<const core::GradientSegment> gradients;          // as br::PatternCalculator::SetProfile
  std::span<const core::RestrictionSegment> speed_limits;    // static limits, sorted, non-overlapping
  std::span<const BaliseEntry> balises;                      // unique ids, on the line
  std::span<const lc::CrossingData> crossings;               // as CrossingProtection::LoadCrossings
  std::span<const ra::OdometrySection> odometry_sections;    // as ra::OdometryConfig::sections
};

// The radio area of one wayside unit on the train's line (see the header comment).
struct RadioArea {
  std::uint16_t peer_id = 0;                 // the unit's radio id (the link's peer)
  std::int64_t origin_mm = 0;                // its chainage 0; a virtual-block boundary
  std::optional<std::int64_t> boundary_mm;   // its system boundary; every area but the last
};

// Links held at once: the unit the train is in and the next one.
inline constexpr std::size_t kRadioLinks = 2;

struct OnboardConfig {
  std::uint32_t train_id = 0;                  // in every application message
  br::TrainData train{};                       // length and accel_max feed odometry and crossings
  br::SupervisionParams supervision = br::DefaultSupervisionParams();
  // Odometry settings; sections, section_count, train_length_mm and initial_front_mm are the
  // unit's (from line, train and initial_front_mm).
  ra::OdometryConfig odometry{};
  std::int64_t initial_front_mm = 0;           // the front at start (initial balise fix)
  LineData line{};
  // Crossing parameters; train_id, train_length_mm and accel_max_mm_s2 are the unit's.
  lc::onboard::ProtectionConfig crossing{};
  mb::onboard::AuthorityConfig authority = mb::onboard::DefaultAuthorityConfig();
  tg::EndpointConfig radio{};                  // role kTrain; peer_id of each area's link
  // the wayside units along the line, origins increasing; none: one unit (radio.peer_id)
  // whose chainage is the line's
  std::span<const RadioArea> radio_areas;
  std::optional<tg::LinkKey> link_key;
  std::int64_t radio_period_ms = params::tg::train_cycle_ms;
  std::int64_t radio_offset_ms = 0;            // first telegram this long after the first cycle
                                               // (0 .. radio_period_ms)
};

enum class OnboardConfigError : std::uint8_t {
  kNone,
  kPeriods,          // supervision cycle, radio period or offset not a multiple of the cycle,
                     // offset not below the period
  kBlocks,           // fewer than 2 boundaries, [0] != 0 or not increasing (`entry`)
  kBalises,          // a balise off the line or an id twice (`entry`)
  kOdometry,         // ra::Odometry::Create refused (`odometry`)
  kTrainData,        // br::PatternCalculator::Create refused (`braking`)
  kLineProfile,      // SetProfile refused gradients or speed limits (`profile`, `entry`)
  kCrossings,        // CrossingProtection::Create or LoadCrossings refused (`crossings`)
  kRadio,            // role not kTrain, no link key, or Endpoint::Init refused (`radio`)
  kOutOfMemory,
  kRadioAreas,       // radio_areas refused (`areas`, `entry`)
};

constexpr const char* ToString(OnboardConfigError e) noexcept {
  return core::EnumName(e, std::array<const char*, 11>{"NONE", "PERIODS", "BLOCKS", "BALISES", "ODOMETRY",
                                                       "TRAIN_DATA", "LINE_PROFILE", "CROSSINGS", "RADIO",
                                                       "OUT_OF_MEMORY", "RADIO_AREAS"});
}

enum class RadioAreaError : std::uint8_t {
  kNone,
  kNotIncreasing,        // an origin not above the previous area's
  kOriginNotOnBlock,     // an origin that is no virtual-block boundary of the line
  kBoundaryOutsideArea,  // a boundary missing (not the last area), on the last area, or not
                         // after the next area's origin and on the line
  kPeerTwice,            // a peer id twice, or the train's own radio id
};

constexpr const char* ToString(RadioAreaError e) noexcept {
  return core::EnumName(e, std::array<const char*, 5>{"NONE", "NOT_INCREASING", "ORIGIN_NOT_ON_BLOCK",
                                                      "BOUNDARY_OUTSIDE_AREA", "PEER_TWICE"});
}

// The first error of a configuration and the module's own reason.
struct ConfigCheck {
  OnboardConfigError error = OnboardConfigError::kNone;
  std::size_t entry = 0;
  ra::ConfigError odometry = ra::ConfigError::kNone;
  br::CreateError braking = br::CreateError::kNone;
  br::ProfileResult profile{};
  lc::onboard::ProtectionError crossings = lc::onboard::ProtectionError::kNone;
  tg::ConfigError radio = tg::ConfigError::kNone;
  RadioAreaError areas = RadioAreaError::kNone;
};

// ---- one cycle's inputs and outputs ------------------------------------------------------

struct OnboardInputs {
  std::int64_t now_ms = 0;                            // previous + kOnboardCycleMs
  ra::CycleInput sensors{};                           // time_ms and balise are the unit's
  std::optional<std::uint32_t> balise_id;             // a balise read this cycle
  std::span<const std::span<const std::uint8_t>> frames;  // received frames, in order
  // frames of the next unit (the link of OnboardOutputs::handover_area); their events count
  // on after `frames`
  std::span<const std::span<const std::uint8_t>> handover_frames;
  br::DriverInputs driver{};                          // standstill is the odometry's
  std::optional<std::int64_t> dwell_departure_ms;     // standing at a scheduled stop (REQ-LC-005)
};

enum class BrakeDemand : std::uint8_t { kNone, kService, kEmergency };

constexpr const char* ToString(BrakeDemand d) noexcept {
  return core::EnumName(d, std::array<const char*, 3>{"NONE", "SERVICE", "EMERGENCY"});
}

// Why the unit brakes, the first that holds in this order.
enum class BrakeReason : std::uint8_t {
  kNone,
  kRadioLink,          // telegram link not up (REQ-TG-014)
  kOdometryStop,       // the odometry's stop demand (REQ-RA-007, REQ-RA-013, REQ-RA-015)
  kSupervisionInput,   // br::PatternCalculator::Evaluate refused its input (REQ-BR-008)
  kNoUsableLimit,      // no usable movement authority: standstill (REQ-MB-009, REQ-BR-012)
  kEmergencyPattern,   // br::Supervisor emergency brake, latched (REQ-BR-001, REQ-BR-006)
  kServicePattern,     // br::Supervisor 4N..7N (REQ-BR-002, REQ-BR-003)
};

constexpr const char* ToString(BrakeReason r) noexcept {
  return core::EnumName(r, std::array<const char*, 7>{"NONE", "RADIO_LINK", "ODOMETRY_STOP", "SUPERVISION_INPUT",
                                                      "NO_USABLE_LIMIT", "EMERGENCY_PATTERN", "SERVICE_PATTERN"});
}

// What governs the supervision: the movement authority, the crossing protection limit
// (the nearer wins), or nothing usable (standstill).
enum class LimitKind : std::uint8_t { kNone, kMovementAuthority, kCrossingProtection };

constexpr const char* ToString(LimitKind k) noexcept {
  return core::EnumName(k, std::array<const char*, 3>{"NONE", "MOVEMENT_AUTHORITY", "CROSSING_PROTECTION"});
}

struct Indications {
  std::int64_t permitted_speed_mm_s = 0;   // service pattern at the supervised front (>= 0)
  std::int64_t target_speed_mm_s = 0;      // at the limit: 0
  std::int64_t target_distance_mm = 0;     // limit - supervised front (0 without a limit)
  bool warning = false;                    // "pattern approaching" (REQ-BR-003)
  std::optional<std::int64_t> limit_mm;    // the governing limit
  LimitKind limit_kind = LimitKind::kNone;
  messages::Obstruction obstruction = messages::Obstruction::kNone;  // of the movement authority
  std::uint32_t crossing_id = 0;           // of the crossing limit
};

// What became of one received frame or message.
enum class RxStatus : std::uint8_t {
  kAccepted,          // used (a stop limit: `verdict` is kAccept)
  kFrameRejected,     // the telegram layer refused the frame (`reject`)
  kUndecodable,       // the payload is no bundle (`decode`, `field`, `entry`)
  kOtherTrain,        // a stop limit or acknowledgement addressed to another train
  kUnexpectedType,    // a message the train does not receive (`type`)
  kStopLimitRefused,  // AuthorityReceiver refused it (`verdict`)
  kMessageDropped,    // a crossing message beyond lc::onboard::kMaxMessagesPerCycle
  kFramesDropped,     // frames beyond kMaxFramesPerCycle (`entry`: how many)
};

constexpr const char* ToString(RxStatus s) noexcept {
  return core::EnumName(s, std::array<const char*, 8>{"ACCEPTED", "FRAME_REJECTED", "UNDECODABLE", "OTHER_TRAIN",
                                                      "UNEXPECTED_TYPE", "STOP_LIMIT_REFUSED", "MESSAGE_DROPPED",
                                                      "FRAMES_DROPPED"});
}

struct RxEvent {
  RxStatus status = RxStatus::kAccepted;
  std::size_t frame = 0;                                 // index in OnboardInputs::frames
  tg::RejectReason reject = tg::RejectReason::kNone;
  std::uint32_t gap = 0;                                 // telegrams lost before this frame
  tg::LinkState link = tg::LinkState::kNone;             // after this frame
  messages::DecodeError decode = messages::DecodeError::kNone;
  messages::Field field = messages::Field::kNone;
  std::size_t entry = 0;                                 // message index in the bundle
  messages::MessageType type = messages::MessageType::kPositionReport;
  mb::onboard::Verdict verdict = mb::onboard::Verdict::kAccept;
};

struct OnboardOutputs {
  std::int64_t now_ms = 0;
  BrakeDemand brake = BrakeDemand::kEmergency;  // RADIO_LINK: a link that counts is not up
  BrakeReason reason = BrakeReason::kRadioLink;
  br::BrakeLevel level = br::BrakeLevel::kNone;   // the supervisor's last decision
  Indications indications{};
  // the position envelope
  bool position_valid = false;
  std::int64_t front_mm = 0;
  std::int64_t front_error_mm = 0;
  std::int64_t rear_error_mm = 0;
  std::int64_t speed_mm_s = 0;
  ra::InputError sensor_error = ra::InputError::kNone;
  bool unknown_balise = false;                   // the balise read is not in the line data
  // the movement authority
  bool authority_usable = false;
  std::optional<std::int64_t> authority_limit_mm;
  // the radio (`link`: kUp when every link that counts is up, else the first that is not)
  tg::LinkState link = tg::LinkState::kNone;
  bool sent = false;                             // `frame` holds this cycle's telegram
  tg::LinkState send_link = tg::LinkState::kNone;  // the link supervision at the last telegram
  tg::EncodedFrame frame{};
  tg::SendStatus send_status = tg::SendStatus::kSent;
  messages::EncodeError encode_error = messages::EncodeError::kNone;  // the bundle (report sent alone)
  std::size_t crossing_messages_sent = 0;
  // the handover: the area of the first link (0 without radio areas) and of the second
  std::size_t radio_area = 0;
  std::optional<std::size_t> handover_area;
  tg::LinkState handover_link = tg::LinkState::kNone;
  bool handover_sent = false;                    // `handover_frame` holds a telegram to it
  tg::EncodedFrame handover_frame{};
  std::array<RxEvent, 2 * kMaxRxEvents> events{};
  std::size_t event_count = 0;
  // the modules' verdicts of this cycle
  lc::onboard::ProtectionError crossing_error = lc::onboard::ProtectionError::kNone;
  br::EvalStatus evaluation = br::EvalStatus::kOk;
  br::ProfileVerdict profile = br::ProfileVerdict::kAccept;

  [[nodiscard]] std::span<const RxEvent> Events() const noexcept { return {events.data(), event_count}; }
};

struct OnboardCreateResult;

class OnboardUnit {
  struct Token {
    explicit Token() = default;
  };

 public:
  using CreateResult = OnboardCreateResult;
  explicit OnboardUnit(Token /*only Create makes a unit*/) noexcept {}

  // Validates the configuration and allocates every buffer of the unit.
  static CreateResult Create(const OnboardConfig& config) noexcept;

  // One on-board cycle (the steps of the header comment). Never fails: a rejected input is
  // reported in the outputs and handled on the safe side.
  const OnboardOutputs& Cycle(const OnboardInputs& in) noexcept;

  [[nodiscard]] const OnboardOutputs& Outputs() const noexcept { return out_; }
  [[nodiscard]] std::span<const core::RestrictionSegment> Profile() const noexcept { return profile_.Span(); }
  [[nodiscard]] const ra::OdometryOutput& Odometry() const noexcept { return odometry_.output(); }
  [[nodiscard]] const lc::onboard::CrossingProtection& Crossings() const noexcept { return *crossings_; }

 private:
  // One wayside unit's link: its area, endpoint, authority and the restrictions it sent last
  // (line chainage).
  struct RadioLink {
    std::optional<std::size_t> area;  // engaged while open
    tg::Endpoint endpoint;
    mb::onboard::AuthorityReceiver authority{mb::onboard::DefaultAuthorityConfig()};
    messages::Obstruction obstruction = messages::Obstruction::kNone;
    std::array<messages::SpeedRestriction, messages::kTelegramRestrictionsMax> restrictions{};
    std::size_t restriction_count = 0;
  };

  [[nodiscard]] ConfigCheck Init(const OnboardConfig& config) noexcept;
  [[nodiscard]] ConfigCheck InitAreas(const OnboardConfig& config) noexcept;
  [[nodiscard]] tg::ConfigError Open(RadioLink& link, std::size_t area) noexcept;
  void Close(RadioLink& link) noexcept;
  [[nodiscard]] RadioLink& First() noexcept { return links_[first_]; }
  [[nodiscard]] RadioLink& Second() noexcept { return links_[1 - first_]; }
  [[nodiscard]] std::int64_t ToArea(const RadioLink& link, std::int64_t line_mm) const noexcept;
  [[nodiscard]] std::int64_t FromArea(const RadioLink& link, std::int64_t area_mm) const noexcept;
  [[nodiscard]] std::optional<std::int64_t> BoundaryOf(const RadioLink& link) const noexcept;
  [[nodiscard]] bool Released(const ra::OdometryOutput& o) const noexcept;
  void Authority(const ra::OdometryOutput& o) noexcept;
  [[nodiscard]] tg::LinkState LinkDemand(const ra::OdometryOutput& o) const noexcept;
  void ManageLinks(const ra::OdometryOutput& o) noexcept;
  void Send(const ra::OdometryOutput& o) noexcept;
  [[nodiscard]] std::size_t SendOn(RadioLink& link, const ra::OdometryOutput& o, tg::EncodedFrame& frame,
                                   tg::Endpoint::CycleOutput& sent) noexcept;
  [[nodiscard]] messages::Message Report(const ra::OdometryOutput& o, const RadioLink& link) const noexcept;
  void Receive(const OnboardInputs& in, std::size_t frames_area,
               std::optional<std::size_t> handover_frames_area) noexcept;
  void ReceiveOn(RadioLink& link, std::span<const std::span<const std::uint8_t>> frames, std::size_t first_index,
                 std::int64_t now_ms) noexcept;
  void OnMessage(RadioLink& link, const messages::Message& m, RxEvent event) noexcept;
  void UpdateRestrictions() noexcept;
  void AddEvent(const RxEvent& e) noexcept;
  void UpdateProfile() noexcept;
  void Protect(const OnboardInputs& in, const ra::OdometryOutput& o) noexcept;
  void Supervise(const ra::OdometryOutput& o, const br::DriverInputs& driver) noexcept;
  void Demand(const ra::OdometryOutput& o) noexcept;
  [[nodiscard]] std::int64_t StoreFront(const ra::OdometryOutput& o) const noexcept;

  std::uint32_t train_id_ = 0;
  std::int64_t length_mm_ = 0;
  std::int64_t radio_period_ms_ = 0;
  std::int64_t radio_offset_ms_ = 0;
  std::int64_t supervision_period_ms_ = 0;
  std::optional<std::int64_t> next_radio_ms_;
  std::optional<std::int64_t> next_supervision_ms_;
  // line data (copied at Create)
  core::FixedVector<std::int64_t> blocks_;
  core::FixedVector<BaliseEntry> balises_;
  core::FixedVector<core::GradientSegment> gradients_;
  core::FixedVector<core::RestrictionSegment> line_limits_;
  core::FixedVector<ra::OdometrySection> sections_;
  // the merged profile, the held restrictions it was built from, and the merge's scratch
  core::FixedVector<core::RestrictionSegment> profile_;
  core::FixedVector<std::int64_t> scratch_;
  std::array<messages::SpeedRestriction, mb::onboard::kStoredRestrictionsMax> merged_held_{};
  std::size_t merged_held_count_ = 0;
  bool profile_stale_ = true;
  // the modules
  ra::Odometry odometry_;
  std::optional<br::PatternCalculator> patterns_;
  br::Supervisor supervisor_;
  mb::onboard::AuthorityConfig authority_config_ = mb::onboard::DefaultAuthorityConfig();
  mb::onboard::SpeedRestrictionStore restrictions_;
  std::optional<lc::onboard::CrossingProtection> crossings_;
  // the radio: the areas (one without radio_areas), the block index of each origin, the links
  tg::EndpointConfig radio_{};
  std::optional<tg::LinkKey> link_key_;
  core::FixedVector<RadioArea> areas_;
  core::FixedVector<std::uint32_t> origin_blocks_;
  std::array<RadioLink, kRadioLinks> links_{};
  std::size_t first_ = 0;
  // this cycle's usable movement authority of the links that count, and its obstruction
  std::optional<std::int64_t> authority_mm_;
  messages::Obstruction obstruction_ = messages::Obstruction::kNone;
  // this cycle's crossing messages received, the rotation of the pending ones to send
  std::array<messages::CrossingReport, lc::onboard::kMaxMessagesPerCycle> reports_{};
  std::size_t report_count_ = 0;
  std::array<messages::WithdrawalAck, lc::onboard::kMaxMessagesPerCycle> acks_{};
  std::size_t ack_count_ = 0;
  std::size_t pending_cursor_ = 0;
  std::int64_t last_store_front_mm_ = 0;
  // the last supervision
  br::Evaluation evaluation_{};
  br::Decision decision_{};
  std::optional<std::int64_t> supervised_limit_mm_;
  std::array<std::uint8_t, tg::kPayloadMax> rx_payload_{};
  OnboardOutputs out_{};
};

struct OnboardCreateResult {
  ConfigCheck check{};
  std::optional<OnboardUnit> unit;  // engaged iff check.error == kNone
};

}  // namespace railproof::units
