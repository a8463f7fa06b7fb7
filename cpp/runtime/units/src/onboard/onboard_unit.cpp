// The on-board unit's cycle (onboard_unit.hpp, spec/design/units.md). The glue implements
// no requirement of its own except the position report built from the envelope (Report);
// elsewhere it connects the modules that implement them, named where they meet.
#include "railproof/units/onboard_unit.hpp"

#include <algorithm>
#include <initializer_list>
#include <limits>
#include <variant>

#include "railproof/core/seeded_fault.hpp"
#include "railproof/units/onboard_profile.hpp"

namespace railproof::units {

namespace {

bool MultipleOfCycle(std::int64_t ms) noexcept { return ms > 0 && ms % kOnboardCycleMs == 0; }

// Copies `from` into `to`, allocated to its size (at least 1 so that a span is never dangling).
template <typename T>
bool CopyInto(std::span<const T> from, core::FixedVector<T>& to) noexcept {
  return to.AssignFrom(from, std::max<std::size_t>(from.size(), 1));
}

ConfigCheck Fail(OnboardConfigError e, std::size_t entry = 0) noexcept {
  ConfigCheck c;
  c.error = e;
  c.entry = entry;
  return c;
}

}  // namespace

OnboardCreateResult OnboardUnit::Create(const OnboardConfig& config) noexcept {
  OnboardCreateResult r;
  r.unit.emplace(Token{});
  r.check = r.unit->Init(config);
  if (r.check.error != OnboardConfigError::kNone) {
    r.unit.reset();
  }
  return r;
}

ConfigCheck OnboardUnit::Init(const OnboardConfig& c) noexcept {
  if (!MultipleOfCycle(c.supervision.cycle_ms) || !MultipleOfCycle(c.radio_period_ms) || c.radio_offset_ms < 0 ||
      c.radio_offset_ms % kOnboardCycleMs != 0 || c.radio_offset_ms > c.radio_period_ms) {
    return Fail(OnboardConfigError::kPeriods);
  }
  const auto blocks = c.line.blocks_mm;
  if (blocks.size() < 2 || blocks[0] != 0) {
    return Fail(OnboardConfigError::kBlocks);
  }
  for (std::size_t i = 1; i < blocks.size(); ++i) {
    if (blocks[i] <= blocks[i - 1] || blocks[i] > core::kMaxPositionMm) {
      return Fail(OnboardConfigError::kBlocks, i);
    }
  }
  const auto balises = c.line.balises;
  for (std::size_t i = 0; i < balises.size(); ++i) {
    const bool on_line = balises[i].position_mm >= 0 && balises[i].position_mm <= blocks.back();
    const bool twice = std::any_of(balises.begin(), balises.begin() + static_cast<std::ptrdiff_t>(i),
                                   [&](const BaliseEntry& b) { return b.id == balises[i].id; });
    if (!on_line || twice) {
      return Fail(OnboardConfigError::kBalises, i);
    }
  }
  if (!CopyInto(blocks, blocks_) || !CopyInto(balises, balises_) || !CopyInto(c.line.gradients, gradients_) ||
      !CopyInto(c.line.speed_limits, line_limits_) || !CopyInto(c.line.odometry_sections, sections_)) {
    return Fail(OnboardConfigError::kOutOfMemory);  // GCOVR_EXCL_LINE defensive
  }
  train_id_ = c.train_id;
  length_mm_ = c.train.length_mm;
  radio_period_ms_ = c.radio_period_ms;
  radio_offset_ms_ = c.radio_offset_ms;
  supervision_period_ms_ = c.supervision.cycle_ms;

  ra::OdometryConfig oc = c.odometry;
  oc.train_length_mm = c.train.length_mm;
  oc.sections = sections_.Span().data();
  oc.section_count = static_cast<int>(c.line.odometry_sections.size());
  oc.initial_front_mm = c.initial_front_mm;
  if (const ra::ConfigError e = ra::Odometry::Create(oc, odometry_); e != ra::ConfigError::kNone) {
    ConfigCheck check = Fail(OnboardConfigError::kOdometry);
    check.odometry = e;
    return check;
  }
  last_store_front_mm_ = c.initial_front_mm;

  // the patterns hold the line's gradients and the merge of its limits with every restriction
  // the train can hold: a line whose merged profile could not fit is refused here, not at run time
  const std::size_t merged = MergeCapacity(c.line.speed_limits.size(), mb::onboard::kStoredRestrictionsMax);
  const std::size_t capacity = std::max({c.line.gradients.size(), merged, std::size_t{1}});
  if (capacity > core::kMaxProfileCapacity) {
    ConfigCheck check = Fail(OnboardConfigError::kLineProfile);
    check.profile.verdict = c.line.gradients.size() > core::kMaxProfileCapacity
                                ? br::ProfileVerdict::kTooManyGradients
                                : br::ProfileVerdict::kTooManyRestrictions;
    return check;
  }
  auto created = br::PatternCalculator::Create(c.train, c.supervision, capacity);
  if (created.error != br::CreateError::kNone) {
    ConfigCheck check = Fail(OnboardConfigError::kTrainData);
    check.braking = created.error;
    return check;
  }
  patterns_.emplace(std::move(*created.calculator));
  if (const br::ProfileResult p = patterns_->SetProfile(gradients_.Span(), line_limits_.Span());
      p.verdict != br::ProfileVerdict::kAccept) {
    ConfigCheck check = Fail(OnboardConfigError::kLineProfile, p.entry);
    check.profile = p;
    return check;
  }
  if (!profile_.Allocate(merged) || !scratch_.Allocate(merged) || !scratch_.Resize(merged)) {
    return Fail(OnboardConfigError::kOutOfMemory);  // GCOVR_EXCL_LINE defensive
  }

  lc::onboard::ProtectionConfig pc = c.crossing;
  pc.train_id = c.train_id;
  pc.train_length_mm = c.train.length_mm;
  pc.accel_max_mm_s2 = c.train.accel_max_mm_s2;
  auto protection = lc::onboard::CrossingProtection::Create(pc);
  lc::onboard::ProtectionError pe = protection.error;
  if (pe == lc::onboard::ProtectionError::kNone) {
    crossings_.emplace(*protection.protection);
    pe = crossings_->LoadCrossings(c.line.crossings);
  }
  if (pe != lc::onboard::ProtectionError::kNone) {
    ConfigCheck check = Fail(OnboardConfigError::kCrossings);
    check.crossings = pe;
    return check;
  }

  authority_config_ = c.authority;
  if (c.radio.role != tg::Role::kTrain || !c.link_key) {
    return Fail(OnboardConfigError::kRadio);
  }
  radio_ = c.radio;
  link_key_.emplace(*c.link_key);
  if (const ConfigCheck areas = InitAreas(c); areas.error != OnboardConfigError::kNone) {
    return areas;
  }
  // the first link: the unit protecting the initial front (the last area whose previous
  // boundary lies at or before it; a front in a handover zone opens the next link at once)
  std::size_t area = 0;
  while (area + 1 < areas_.Size() && *areas_[area].boundary_mm <= c.initial_front_mm) {
    ++area;
  }
  if (const tg::ConfigError e = Open(First(), area); e != tg::ConfigError::kNone) {
    ConfigCheck check = Fail(OnboardConfigError::kRadio);
    check.radio = e;
    return check;
  }
  out_.radio_area = area;
  return {};
}

// The radio areas (none: one unit with the line's chainage and the configured peer). An
// origin must be a block boundary: the report to a unit is a block and an offset of its line.
ConfigCheck OnboardUnit::InitAreas(const OnboardConfig& c) noexcept {
  const auto areas = c.radio_areas;
  const auto fail = [](RadioAreaError e, std::size_t entry) {
    ConfigCheck check = Fail(OnboardConfigError::kRadioAreas, entry);
    check.areas = e;
    return check;
  };
  for (std::size_t i = 0; i < areas.size(); ++i) {
    const RadioArea& a = areas[i];
    if (i > 0 && a.origin_mm <= areas[i - 1].origin_mm) {
      return fail(RadioAreaError::kNotIncreasing, i);
    }
    if (!std::binary_search(blocks_.begin(), blocks_.end(), a.origin_mm) || a.origin_mm == blocks_.Span().back()) {
      return fail(RadioAreaError::kOriginNotOnBlock, i);
    }
    const bool last = i + 1 == areas.size();
    if (last ? a.boundary_mm.has_value()
             : !a.boundary_mm || *a.boundary_mm <= areas[i + 1].origin_mm || *a.boundary_mm > blocks_.Span().back()) {
      return fail(RadioAreaError::kBoundaryOutsideArea, i);
    }
    const bool twice = std::any_of(areas.begin(), areas.begin() + static_cast<std::ptrdiff_t>(i),
                                   [&](const RadioArea& b) { return b.peer_id == a.peer_id; });
    if (twice || a.peer_id == c.radio.own_id) {
      return fail(RadioAreaError::kPeerTwice, i);
    }
  }
  const RadioArea single{c.radio.peer_id, 0, std::nullopt};
  const auto list = areas.empty() ? std::span<const RadioArea>(&single, 1) : areas;
  if (!areas_.AssignFrom(list, list.size()) || !origin_blocks_.Allocate(list.size())) {
    return Fail(OnboardConfigError::kOutOfMemory);  // GCOVR_EXCL_LINE defensive
  }
  for (const RadioArea& a : list) {
    const auto at = std::lower_bound(blocks_.begin(), blocks_.end(), a.origin_mm);
    (void)origin_blocks_.PushBack(static_cast<std::uint32_t>(at - blocks_.begin()));
  }
  return {};
}

// Opens `link` to the unit of `area`: a fresh telegram layer link (the same set-up as at start)
// and no authority yet.
tg::ConfigError OnboardUnit::Open(RadioLink& link, std::size_t area) noexcept {
  tg::EndpointConfig config = radio_;
  config.peer_id = areas_[area].peer_id;
  const tg::ConfigError e = link.endpoint.Init(config, *link_key_);
  if (e == tg::ConfigError::kNone) {
    link.area = area;
    link.authority = mb::onboard::AuthorityReceiver(authority_config_);
    link.obstruction = messages::Obstruction::kNone;
    link.restriction_count = 0;
  }
  return e;
}

void OnboardUnit::Close(RadioLink& link) noexcept {
  link.area.reset();
  link.restriction_count = 0;
  UpdateRestrictions();
}

// The one conversion between the line's chainage and a unit's.
std::int64_t OnboardUnit::ToArea(const RadioLink& link, std::int64_t line_mm) const noexcept {
  return line_mm - areas_[*link.area].origin_mm;
}

std::int64_t OnboardUnit::FromArea(const RadioLink& link, std::int64_t area_mm) const noexcept {
  // the next unit's positions taken as the line's
  if (RAILPROOF_FAULT(FAULT_UNIT_HANDOVER_NO_ORIGIN) && &link != &links_[first_]) {
    return area_mm;
  }
  return area_mm + areas_[*link.area].origin_mm;
}

std::optional<std::int64_t> OnboardUnit::BoundaryOf(const RadioLink& link) const noexcept {
  return link.area ? areas_[*link.area].boundary_mm : std::nullopt;
}

// The first unit no longer protects the train once its rearmost rear (front - length - rear
// error) has passed that unit's boundary: past it the next unit's limit governs.
bool OnboardUnit::Released(const ra::OdometryOutput& o) const noexcept {
  const auto boundary = BoundaryOf(links_[first_]);
  return boundary && links_[1 - first_].area && o.position_valid &&
         o.front_mm - length_mm_ - o.rear_error_mm >= *boundary;
}

// ---- the cycle -----------------------------------------------------------------------------

const OnboardOutputs& OnboardUnit::Cycle(const OnboardInputs& in) noexcept {
  out_.now_ms = in.now_ms;
  out_.sent = false;
  out_.frame.size = 0;
  out_.handover_sent = false;
  out_.handover_frame.size = 0;
  out_.crossing_messages_sent = 0;
  out_.encode_error = messages::EncodeError::kNone;
  out_.event_count = 0;
  out_.unknown_balise = false;

  // 1. odometry (the balise read becomes the fix of the track database)
  ra::CycleInput sensors = in.sensors;
  sensors.time_ms = in.now_ms;
  sensors.balise.reset();
  if (in.balise_id) {
    const auto it = std::find_if(balises_.begin(), balises_.end(),
                                 [&](const BaliseEntry& b) { return b.id == *in.balise_id; });
    if (it != balises_.end()) {
      sensors.balise = ra::BaliseFix{it->position_mm};
    } else {
      out_.unknown_balise = true;
    }
  }
  const ra::OdometryOutput& o = odometry_.Step(sensors);
  out_.position_valid = o.position_valid;
  out_.front_mm = o.front_mm;
  out_.front_error_mm = o.front_error_mm;
  out_.rear_error_mm = o.rear_error_mm;
  out_.speed_mm_s = o.speed_mm_s;
  out_.sensor_error = o.input_error;

  // 2. the held restrictions apply until the rear has left them (REQ-MB-015)
  if (o.position_valid) {
    last_store_front_mm_ = StoreFront(o);
  }
  restrictions_.Advance(last_store_front_mm_, length_mm_);

  // the links of the handover; this cycle's frames come from the areas the last outputs named
  const std::size_t frames_area = out_.radio_area;
  const std::optional<std::size_t> handover_frames_area = out_.handover_area;
  ManageLinks(o);

  // 3. the telegram of this cycle
  if (!next_radio_ms_) {
    next_radio_ms_ = in.now_ms + radio_offset_ms_;
    next_supervision_ms_ = in.now_ms;
  }
  if (in.now_ms >= *next_radio_ms_) {
    Send(o);
    *next_radio_ms_ += radio_period_ms_;
  }

  // 4. what arrived
  Receive(in, frames_area, handover_frames_area);
  Authority(o);
  out_.link = LinkDemand(o);
  out_.handover_link = Second().area ? Second().endpoint.Link() : tg::LinkState::kNone;
  out_.authority_usable = authority_mm_.has_value();
  out_.authority_limit_mm = authority_mm_ ? authority_mm_ : First().authority.Limit();

  // 5.-7.
  UpdateProfile();
  Protect(in, o);
  if (in.now_ms >= *next_supervision_ms_) {
    Supervise(o, in.driver);
    *next_supervision_ms_ += supervision_period_ms_;
  }
  Demand(o);
  return out_;
}

// The movement authority of the links that count (header comment): the first unit's until it
// has released the train, then the more restrictive of the next unit's; before the next unit's
// limit is usable, none past the first unit's boundary.
void OnboardUnit::Authority(const ra::OdometryOutput& o) noexcept {
  authority_mm_.reset();
  obstruction_ = messages::Obstruction::kNone;
  const RadioLink& first = First();
  const RadioLink& second = Second();
  const bool first_counts = !Released(o);
  if (first_counts) {
    if (!first.authority.Usable(out_.now_ms) || !first.authority.Limit()) {
      return;
    }
    authority_mm_ = first.authority.Limit();
    obstruction_ = first.obstruction;
  }
  if (!second.area) {
    return;
  }
  if (second.authority.Usable(out_.now_ms) && second.authority.Limit()) {
    if (!authority_mm_ || *second.authority.Limit() < *authority_mm_) {
      authority_mm_ = second.authority.Limit();
      obstruction_ = second.obstruction;
    }
  } else if (!first_counts) {
    authority_mm_.reset();
    obstruction_ = messages::Obstruction::kNone;
  } else if (const auto boundary = BoundaryOf(first); *authority_mm_ > *boundary) {
    authority_mm_ = boundary;
    obstruction_ = messages::Obstruction::kSystemBoundary;
  }
}

// The link state the brake demand reads (REQ-TG-014 in tg): the first link until the train is
// released, the second once the safe front is past the first unit's boundary.
tg::LinkState OnboardUnit::LinkDemand(const ra::OdometryOutput& o) const noexcept {
  const RadioLink& first = links_[first_];
  const RadioLink& second = links_[1 - first_];
  if (!Released(o) && first.endpoint.Link() != tg::LinkState::kUp) {
    return first.endpoint.Link();
  }
  const auto boundary = BoundaryOf(first);
  const bool second_counts = second.area && (!o.position_valid || o.front_mm + o.front_error_mm > *boundary);
  return second_counts ? second.endpoint.Link() : tg::LinkState::kUp;
}

// Opens the next unit's link when the front enters the handover zone; drops the first once the
// train is released and that unit no longer sends (after it removed the train the telegram
// layer's supervision finds the link lost): the second becomes the first. Runs before the
// telegram of the cycle, so that the outputs name the areas of this cycle's telegrams and of
// the next cycle's frames.
void OnboardUnit::ManageLinks(const ra::OdometryOutput& o) noexcept {
  RadioLink& second = Second();
  const std::size_t area = *First().area;
  if (!second.area && area + 1 < areas_.Size() && o.position_valid && o.front_mm >= areas_[area + 1].origin_mm) {
    (void)Open(second, area + 1);  // the configuration Create accepted: never refused
  }
  if (second.area && Released(o) && First().endpoint.Link() != tg::LinkState::kUp) {
    Close(First());
    first_ = 1 - first_;
  }
  out_.radio_area = *First().area;
  out_.handover_area = Second().area;
}

// The front the restriction store measures the rear from: the rearmost the front may be
// (REQ-MB-015: until the rear has left; rear_min = front - length - rear_error, REQ-RA-012).
std::int64_t OnboardUnit::StoreFront(const ra::OdometryOutput& o) const noexcept {
  return o.front_mm - o.rear_error_mm;
}

// The position report of the envelope (REQ-MB-001): the nominal front as virtual block and
// offset (the block holding the foremost millimetre), the correction covering both ends of the
// envelope (ra::ReportCorrectionMm: the ground extends the range by it front and rear,
// REQ-MB-003), the last balise and the measured speed. No valid position, or a front off the
// block table: NO_POSITION.
// @implements REQ-MB-001
// To a unit of a radio area the block counts from the area's origin and the balise is in its
// chainage; a front before the area is no position for it. A balise behind the origin is
// reported at the origin (the unit's line does not hold it; the reported correction, the
// train's own bound, still covers the run from the balise).
messages::Message OnboardUnit::Report(const ra::OdometryOutput& o, const RadioLink& link) const noexcept {
  const std::int64_t correction = ra::ReportCorrectionMm(o);
  // The envelope's rear end of the front would report the train behind where it may be.
  const std::int64_t front = RAILPROOF_FAULT(FAULT_UNIT_REPORT_UNSAFE_END) ? o.front_mm - correction : o.front_mm;
  const auto at = core::LocateFront(blocks_.Span(), front);
  const std::uint32_t origin_block = origin_blocks_[*link.area];
  if (!o.position_valid || !at || at->block < origin_block) {
    return messages::NoPosition{};
  }
  return messages::PositionReport{train_id_,
                                  at->block - origin_block,
                                  at->offset_mm,
                                  length_mm_,
                                  correction,
                                  std::max<std::int64_t>(0, ToArea(link, o.last_balise_mm)),
                                  o.speed_mm_s,
                                  messages::Direction::kNominal};
}

// One telegram (REQ-TG-008): the report first, then the crossing messages of the last
// crossing cycle that fit, continuing where the previous telegram stopped (REQ-LC-002,
// REQ-LC-004: every message repeated until its state changes).
// With two links each gets its own telegram: its report and the same crossing messages (each
// unit takes those of its own crossings).
void OnboardUnit::Send(const ra::OdometryOutput& o) noexcept {
  tg::Endpoint::CycleOutput sent{};
  const std::size_t added = SendOn(First(), o, out_.frame, sent);
  out_.send_status = sent.status;
  out_.send_link = sent.link;
  out_.sent = sent.status == tg::SendStatus::kSent;
  out_.crossing_messages_sent = out_.sent ? added : 0;
  if (Second().area) {
    const messages::EncodeError first_error = out_.encode_error;
    (void)SendOn(Second(), o, out_.handover_frame, sent);
    out_.handover_sent = sent.status == tg::SendStatus::kSent;
    out_.encode_error = first_error != messages::EncodeError::kNone ? first_error : out_.encode_error;
  }
  const lc::onboard::ProtectionOutput& p = crossings_->Output();
  const std::size_t pending = p.request_count + p.withdrawal_count;
  pending_cursor_ = pending == 0 ? 0 : (pending_cursor_ + added) % pending;
}

// One link's telegram; returns the crossing messages it carries.
std::size_t OnboardUnit::SendOn(RadioLink& link, const ra::OdometryOutput& o, tg::EncodedFrame& frame,
                                tg::Endpoint::CycleOutput& sent) noexcept {
  messages::Bundle bundle;
  (void)bundle.Add(Report(o, link));
  const lc::onboard::ProtectionOutput& p = crossings_->Output();
  const std::size_t pending = p.request_count + p.withdrawal_count;
  std::size_t added = 0;
  for (std::size_t k = 0; k < pending; ++k) {
    const std::size_t i = (pending_cursor_ + k) % pending;
    const messages::CrossingRequest r{train_id_, i < p.request_count ? p.requests[i] : p.withdrawals[i - p.request_count]};
    const messages::Message m = i < p.request_count ? messages::Message{r} : messages::Message{messages::CrossingWithdrawal{r}};
    if (!messages::AddIfFits(bundle, m)) {
      break;
    }
    ++added;
  }
  messages::Encoded e = messages::EncodeBundle(bundle.View());
  if (!e.Ok()) {
    // a report the codec refuses (a value out of its range) goes as NO_POSITION, alone
    out_.encode_error = e.error;
    e = messages::Encode(messages::NoPosition{});
    added = 0;
  }
  sent = link.endpoint.Cycle(static_cast<std::uint32_t>(out_.now_ms), e.payload.View(), frame);
  return added;
}

void OnboardUnit::AddEvent(const RxEvent& e) noexcept {
  if (out_.event_count < out_.events.size()) {
    out_.events[out_.event_count++] = e;
  }
}

// The frames of the cycle through the telegram layer (REQ-TG-001..012 in tg::Endpoint) and
// the codec; each message to its module.
// Each input goes to the link of the area it came from (a link dropped since: not read).
void OnboardUnit::Receive(const OnboardInputs& in, std::size_t frames_area,
                          std::optional<std::size_t> handover_frames_area) noexcept {
  report_count_ = 0;
  ack_count_ = 0;
  for (RadioLink& link : links_) {
    if (link.area && *link.area == frames_area) {
      ReceiveOn(link, in.frames, 0, in.now_ms);
    } else if (link.area && link.area == handover_frames_area) {
      ReceiveOn(link, in.handover_frames, in.frames.size(), in.now_ms);
    }
  }
}

void OnboardUnit::ReceiveOn(RadioLink& link, std::span<const std::span<const std::uint8_t>> frames,
                            std::size_t first_index, std::int64_t now_ms) noexcept {
  const std::size_t n = std::min(frames.size(), kMaxFramesPerCycle);
  for (std::size_t f = 0; f < n; ++f) {
    RxEvent event;
    event.frame = first_index + f;
    const auto r = link.endpoint.Receive(static_cast<std::uint32_t>(now_ms), frames[f], rx_payload_);
    event.gap = r.gap;
    event.link = r.link;
    if (r.reason != tg::RejectReason::kNone) {
      event.status = RxStatus::kFrameRejected;
      event.reject = r.reason;
      AddEvent(event);
      continue;
    }
    const std::size_t len = std::min<std::size_t>(r.header.payload_len, rx_payload_.size());
    const messages::DecodedBundle d = messages::DecodeBundle(std::span<const std::uint8_t>(rx_payload_).first(len));
    if (!d.Ok()) {
      event.status = RxStatus::kUndecodable;
      event.decode = d.error;
      event.field = d.field;
      event.entry = d.entry;
      AddEvent(event);
      continue;
    }
    for (std::size_t k = 0; k < d.bundle.size; ++k) {
      event.entry = k;
      OnMessage(link, d.bundle.messages[k], event);
    }
  }
  if (frames.size() > n) {
    RxEvent dropped;
    dropped.status = RxStatus::kFramesDropped;
    dropped.frame = first_index;
    dropped.entry = frames.size() - n;
    AddEvent(dropped);
  }
}

// The store holds the restrictions of both links' last telegrams (each unit sends those of its
// own line; together they fit the store: kStoredRestrictionsMax is two telegrams').
void OnboardUnit::UpdateRestrictions() noexcept {
  std::array<messages::SpeedRestriction, mb::onboard::kStoredRestrictionsMax> all{};
  std::size_t n = 0;
  for (const std::size_t k : {first_, 1 - first_}) {
    const RadioLink& link = links_[k];
    for (std::size_t i = 0; i < link.restriction_count && n < all.size(); ++i) {
      all[n++] = link.restrictions[i];
    }
  }
  (void)restrictions_.Update(std::span<const messages::SpeedRestriction>(all.data(), n), last_store_front_mm_,
                             length_mm_);
}

void OnboardUnit::OnMessage(RadioLink& link, const messages::Message& m, RxEvent event) noexcept {
  event.type = messages::TypeOf(m);
  if (const auto* t = std::get_if<messages::StopLimitTelegram>(&m)) {
    if (t->train_id != train_id_) {
      event.status = RxStatus::kOtherTrain;
    } else {
      // REQ-MB-009 (AuthorityReceiver), then the restrictions of the accepted telegram
      // (REQ-MB-015, SpeedRestrictionStore)
      event.verdict = link.authority.Receive(FromArea(link, t->limit_mm), t->issue_time_ms, out_.now_ms);
      event.status = event.verdict == mb::onboard::Verdict::kAccept ? RxStatus::kAccepted : RxStatus::kStopLimitRefused;
      if (event.verdict == mb::onboard::Verdict::kAccept) {
        link.obstruction = t->kind;
        link.restriction_count = std::min<std::size_t>(t->restriction_count, t->restrictions.size());
        for (std::size_t i = 0; i < link.restriction_count; ++i) {
          messages::SpeedRestriction r = t->restrictions[i];
          r.begin_mm = FromArea(link, r.begin_mm);
          r.end_mm = FromArea(link, r.end_mm);
          link.restrictions[i] = r;
        }
        UpdateRestrictions();
      }
    }
  } else if (std::holds_alternative<messages::KeepAlive>(m)) {
    event.status = RxStatus::kAccepted;  // REQ-MB-024: the link is kept, no limit
  } else if (const auto* c = std::get_if<messages::CrossingReport>(&m)) {
    event.status = report_count_ < reports_.size() ? RxStatus::kAccepted : RxStatus::kMessageDropped;
    if (report_count_ < reports_.size()) {
      reports_[report_count_++] = *c;
    }
  } else if (const auto* a = std::get_if<messages::WithdrawalAck>(&m)) {
    if (a->train_id != train_id_) {
      event.status = RxStatus::kOtherTrain;
    } else {
      event.status = ack_count_ < acks_.size() ? RxStatus::kAccepted : RxStatus::kMessageDropped;
      if (ack_count_ < acks_.size()) {
        acks_[ack_count_++] = *a;
      }
    }
  } else {
    event.status = RxStatus::kUnexpectedType;
  }
  AddEvent(event);
}

// The profile of the patterns and of the crossing arrival times: rebuilt when the held
// restrictions changed.
void OnboardUnit::UpdateProfile() noexcept {
  const auto held = restrictions_.Held();
  const bool same = !profile_stale_ && held.size() == merged_held_count_ &&
                    std::equal(held.begin(), held.end(), merged_held_.begin(), [](const auto& a, const auto& b) {
                      return a.id == b.id && a.begin_mm == b.begin_mm && a.end_mm == b.end_mm &&
                             a.speed_mm_s == b.speed_mm_s;
                    });
  if (same) {
    return;
  }
  std::copy(held.begin(), held.end(), merged_held_.begin());
  merged_held_count_ = held.size();
  profile_stale_ = false;
  (void)profile_.Resize(profile_.Capacity());
  // out and scratch hold MergeCapacity (Init): the merge always fits
  const MergeResult m = MergeRestrictions(line_limits_.Span(), held, profile_.Span(), scratch_.Span());
  (void)profile_.Resize(m.count);
  out_.profile = patterns_->SetProfile(gradients_.Span(), profile_.Span()).verdict;
}

// Crossing protection (REQ-LC-001..005 in lc::onboard::CrossingProtection) with the envelope
// and the supervised speed (an upper bound of the speed, as the protection asks); standing at
// a scheduled stop it is the dwell rule's standstill. Without a valid position the cycle is not
// run: the protection keeps its requests and its limit (its refused-cycle rule).
void OnboardUnit::Protect(const OnboardInputs& in, const ra::OdometryOutput& o) noexcept {
  if (!o.position_valid) {
    out_.crossing_error = lc::onboard::ProtectionError::kNone;
    return;
  }
  lc::onboard::ProtectionInput pi;
  pi.now_ms = in.now_ms;
  pi.front_mm = o.front_mm;
  pi.front_error_mm = o.front_error_mm;
  pi.rear_error_mm = o.rear_error_mm;
  pi.dwell = in.dwell_departure_ms.has_value() && o.standstill;
  pi.departure_ms = in.dwell_departure_ms.value_or(0);
  pi.speed_mm_s = pi.dwell ? 0 : patterns_->SupervisedSpeed(o.speed_mm_s, o.standstill);
  pi.restrictions = profile_.Span();
  pi.reports = std::span<const messages::CrossingReport>(reports_.data(), report_count_);
  pi.acks = std::span<const messages::WithdrawalAck>(acks_.data(), ack_count_);
  out_.crossing_error = crossings_->Cycle(pi);
}

// Braking supervision (REQ-BR-001..007 in br::PatternCalculator and br::Supervisor) against the
// nearer of the usable movement authority (REQ-MB-009) and the crossing protection limit
// (REQ-LC-003); no usable authority: the standstill supervision (REQ-BR-012).
void OnboardUnit::Supervise(const ra::OdometryOutput& o, const br::DriverInputs& driver) noexcept {
  br::PositionEstimate pe = ra::ToPositionEstimate(o);
  if (RAILPROOF_FAULT(FAULT_UNIT_REAR_FOR_FRONT)) {
    // the undercounting bound of the front where the safe front belongs
    pe.front_mm = o.front_mm - o.rear_error_mm;
    pe.front_error_mm = 0;
  }
  Indications& ind = out_.indications;
  ind = Indications{};
  std::optional<std::int64_t> limit;
  if (authority_mm_) {
    limit = authority_mm_;
    ind.limit_kind = LimitKind::kMovementAuthority;
    ind.obstruction = obstruction_;
    const auto& p = crossings_->Output();
    if (p.stop_limit_mm && *p.stop_limit_mm < *limit && !RAILPROOF_FAULT(FAULT_UNIT_CROSSING_LIMIT_IGNORED)) {
      limit = p.stop_limit_mm;
      ind.limit_kind = LimitKind::kCrossingProtection;
      ind.obstruction = messages::Obstruction::kNone;
      ind.crossing_id = p.limiting_crossing_id;
    }
  }
  supervised_limit_mm_ = limit;
  evaluation_ = patterns_->Evaluate(pe, limit);
  out_.evaluation = evaluation_.status;
  br::DriverInputs d = driver;
  d.standstill = o.standstill;
  decision_ = supervisor_.Step(evaluation_.speeds, d);
  ind.permitted_speed_mm_s = std::max<std::int64_t>(0, evaluation_.speeds.v_7n);
  ind.warning = decision_.pattern_approaching;
  ind.limit_mm = limit;
  ind.target_distance_mm = limit ? *limit - (pe.front_mm + pe.front_error_mm) : 0;
}

void OnboardUnit::Demand(const ra::OdometryOutput& o) noexcept {
  out_.level = decision_.level;
  const bool eb = decision_.level == br::BrakeLevel::kEmergency;
  if (out_.link != tg::LinkState::kUp) {
    out_.reason = BrakeReason::kRadioLink;
  } else if (o.stop_demand) {
    out_.reason = BrakeReason::kOdometryStop;
  } else if (eb && evaluation_.status != br::EvalStatus::kOk) {
    out_.reason = BrakeReason::kSupervisionInput;
  } else if (eb && !supervised_limit_mm_) {
    out_.reason = BrakeReason::kNoUsableLimit;
  } else if (eb) {
    out_.reason = BrakeReason::kEmergencyPattern;
  } else if (decision_.level != br::BrakeLevel::kNone) {
    out_.reason = BrakeReason::kServicePattern;
  } else {
    out_.reason = BrakeReason::kNone;
  }
  out_.brake = out_.reason == BrakeReason::kNone             ? BrakeDemand::kNone
               : out_.reason == BrakeReason::kServicePattern ? BrakeDemand::kService
                                                             : BrakeDemand::kEmergency;
}

}  // namespace railproof::units
