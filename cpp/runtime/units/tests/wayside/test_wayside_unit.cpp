// The wayside unit through its interface: configuration, admission and registration by base
// station, telegram bytes in and out, typed rejections, crossings, the centre and its link to
// the crossings, no heap after Create.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "railproof/testing/alloc_counter.hpp"
#include "wayside_test_support.hpp"

namespace railproof::units::test {
namespace {

using messages::Obstruction;

constexpr std::int64_t kLen = 200'000;
constexpr std::uint16_t kGround = 1;

struct Fixture {
  mb::wayside::test::LineData line = StraightLine(5'000'000);
  std::vector<lc::CrossingData> crossings{{7, 3'000'000, 3'010'000, 30'000}};
  WaysideConfig config;
  std::unique_ptr<WaysideUnit> unit;
  std::int64_t now = 0;
  CycleInput input{};

  explicit Fixture(std::size_t per_station = kTrainsPerBaseStation, std::size_t departures = 0,
                   CentreLink link = CentreLink::kInternal) {
    config = BaseConfig(line);
    config.centre_link = link;
    config.trains_per_base_station = per_station;
    config.crossings = crossings;
    config.departures = departures;
    config.scheduler = lc::wayside::DefaultSchedulerConfig(1000);
    auto created = WaysideUnit::Create(config);
    EXPECT_EQ(created.error, ConfigError::kNone) << ToString(created.error);
    unit = std::move(created.unit);
  }
  const CycleOutput& Cycle() { return unit->Cycle(now, input); }
  // admits and registers a train and brings its link up (one cycle and one report)
  void Enter(std::uint32_t id, std::int64_t front, TrainRadio& radio) {
    ASSERT_EQ(unit->Admit(id, static_cast<std::uint16_t>(id + 10)), AdmitStatus::kAdmitted);
    ASSERT_EQ(unit->Register({id, kLen, front, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
              RegisterStatus::kRegistered);
    (void)radio.Take(now, Cycle());
  }
};

TEST(WaysideUnitConfig, RefusesEachInvalidPartWithItsReason) {
  const auto line = StraightLine(1'000'000);
  WaysideConfig c = BaseConfig(line);
  c.keys = nullptr;
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kNoKeyProvider);
  c = BaseConfig(line);
  c.radio.seq_window = 0;
  const auto radio = WaysideUnit::Create(c);
  EXPECT_EQ(radio.error, ConfigError::kRadioInvalid);
  EXPECT_EQ(radio.radio_error, tg::ConfigError::kSeqWindowOutOfRange);
  c = BaseConfig(line);
  c.line.length_mm = 0;
  EXPECT_EQ(WaysideUnit::Create(c).line_error, mb::wayside::ConfigError::kLineLengthInvalid);
  c = BaseConfig(line);
  c.trains_per_base_station = 0;
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kBaseStationCapacityInvalid);
  c = BaseConfig(line);
  c.secure_ahead_mm = -1;  // NOLINT
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kSecureAheadInvalid);
  c = BaseConfig(line);
  const std::vector<lc::CrossingData> twice{{1, 100, 200, 1000}, {1, 300, 400, 1000}};
  c.crossings = twice;
  const auto dup = WaysideUnit::Create(c);
  EXPECT_EQ(dup.error, ConfigError::kCrossingInvalid);
  EXPECT_EQ(dup.entry, 1U);
  c = BaseConfig(line);
  c.handover_zone_begin_mm = 500'000;  // no system boundary
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kHandoverZoneInvalid);
  c = BaseConfig(line);
  c.departures = 1;
  c.scheduler.accel_max_mm_s2 = 0;
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kSchedulerInvalid);
  c = BaseConfig(line);
  c.centre_link = static_cast<CentreLink>(2);
  EXPECT_EQ(WaysideUnit::Create(c).error, ConfigError::kCentreLinkInvalid);
}

TEST(WaysideUnitTrains, CapacityIsTheBaseStationsCapacity) {
  auto line = StraightLine(3'000'000);
  line.handovers = {{1, 1'000'000}, {2, 2'000'000}};
  WaysideConfig c = BaseConfig(line);
  auto created = WaysideUnit::Create(c);
  ASSERT_TRUE(created.unit);
  EXPECT_EQ(created.unit->BaseStationCount(), 3U);
  EXPECT_EQ(created.unit->TrainCapacity(), 3 * kTrainsPerBaseStation);
  for (std::uint32_t id = 1; id <= 3 * kTrainsPerBaseStation; ++id) {
    ASSERT_EQ(created.unit->Admit(id, static_cast<std::uint16_t>(id + 1)), AdmitStatus::kAdmitted);
  }
  EXPECT_EQ(created.unit->Admit(500, 500), AdmitStatus::kCapacityFull);
}

TEST(WaysideUnitTrains, AdmissionAndRegistrationAreChecked) {
  Fixture f(1);
  WaysideUnit& u = *f.unit;
  EXPECT_EQ(u.Admit(5, kGround), AdmitStatus::kRadioIdInvalid);
  EXPECT_EQ(u.Admit(999, 9), AdmitStatus::kNoKey);
  EXPECT_EQ(u.Register({5, kLen, 1'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kNotAdmitted);
  ASSERT_EQ(u.Admit(5, 5), AdmitStatus::kAdmitted);
  EXPECT_EQ(u.Admit(5, 6), AdmitStatus::kDuplicateTrain);
  const auto off = u.Register({5, kLen, 9'000'000, 0, mb::wayside::InitialPosition::kEntryBalise});
  EXPECT_EQ(off.status, RegisterStatus::kGroundRefused);
  EXPECT_EQ(off.ground, mb::wayside::RegisterStatus::kFrontOffLine);
  EXPECT_EQ(u.Register({5, kLen, 1'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  EXPECT_EQ(u.Register({5, kLen, 1'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kAlreadyRegistered);
  EXPECT_EQ(u.BaseStationLoad(0), 1U);
  EXPECT_EQ(u.Remove(5), mb::wayside::CommandStatus::kAccepted);
  EXPECT_EQ(u.BaseStationLoad(0), 0U);
  EXPECT_FALSE(u.Ground().Train(5).has_value());
  EXPECT_EQ(u.Remove(5), mb::wayside::CommandStatus::kUnknownTrain);
}

// Each train gets its own stop limit in its own telegram: the follower's ends at the leader's
// rear minus the margin.
TEST(WaysideUnitRadio, EveryTrainGetsItsOwnStopLimitAsBytes) {
  Fixture f;
  TrainRadio lead(1, 1 + 10, kGround);
  TrainRadio follow(2, 2 + 10, kGround);
  ASSERT_EQ(f.unit->Admit(1, 11), AdmitStatus::kAdmitted);
  ASSERT_EQ(f.unit->Admit(2, 12), AdmitStatus::kAdmitted);
  ASSERT_EQ(f.unit->Register({1, kLen, 2'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  ASSERT_EQ(f.unit->Register({2, kLen, 1'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  for (int k = 0; k < 4; ++k) {
    f.now += kGroundCycleMs;
    const auto& out = f.Cycle();
    const auto b1 = lead.Take(f.now, out);
    const auto b2 = follow.Take(f.now, out);
    if (k == 0) {
      // the first control telegrams echo nothing yet: the trains refuse them, then report
      EXPECT_EQ(lead.LastReason(), tg::RejectReason::kNoEcho);
      (void)f.unit->Receive(f.now, 1, lead.Send(f.now, {ReportAt(*f.unit, 1, 2'000'000, kLen)}));
      (void)f.unit->Receive(f.now, 2, follow.Send(f.now, {ReportAt(*f.unit, 2, 1'000'000, kLen)}));
      continue;
    }
    const auto* t1 = StopLimitOf(b1);
    const auto* t2 = StopLimitOf(b2);
    ASSERT_NE(t1, nullptr);
    ASSERT_NE(t2, nullptr);
    EXPECT_EQ(t1->train_id, 1U);
    EXPECT_EQ(t2->train_id, 2U);
    EXPECT_EQ(t2->kind, Obstruction::kPrecedingTrain);
    EXPECT_EQ(t2->limit_mm, 2'000'000 - kLen - f.config.line.margins.preceding_train_mm);
    EXPECT_EQ(t1->kind, Obstruction::kEndOfTrack);
    // the trains report every cycle (both links come up after the first exchange)
    const auto r1 = f.unit->Receive(f.now, 1, lead.Send(f.now, {ReportAt(*f.unit, 1, 2'000'000, kLen)}));
    const auto r2 = f.unit->Receive(f.now, 2, follow.Send(f.now, {ReportAt(*f.unit, 2, 1'000'000, kLen)}));
    EXPECT_EQ(r1.status, FrameStatus::kAccepted) << ToString(r1.tg_reason);
    EXPECT_EQ(r2.status, FrameStatus::kAccepted) << ToString(r2.tg_reason);
    ASSERT_EQ(r1.message_count, 1U);
    EXPECT_EQ(r1.messages[0].status, MessageStatus::kAccepted);
  }
  ASSERT_EQ(f.unit->LastOutput().trains.Size(), 2U);
  EXPECT_EQ(f.unit->LastOutput().trains[0].link, tg::LinkState::kUp);
}

TEST(WaysideUnitRadio, RejectedInputsHaveTypedReasons) {
  Fixture f;
  TrainRadio radio(3, 13, kGround);
  ASSERT_EQ(f.unit->Admit(3, 13), AdmitStatus::kAdmitted);
  ASSERT_EQ(f.unit->Register({3, kLen, 1'000'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  // no echo yet: the telegram layer refuses the first frame
  const auto first = f.unit->Receive(f.now, 3, radio.Send(f.now, {messages::NoPosition{}}));
  EXPECT_EQ(first.status, FrameStatus::kFrameRejected);
  EXPECT_EQ(first.tg_reason, tg::RejectReason::kNoEcho);
  (void)radio.Take(f.now, f.Cycle());
  EXPECT_EQ(f.unit->Receive(f.now, 4, radio.Send(f.now, {messages::NoPosition{}})).status, FrameStatus::kUnknownTrain);
  const std::vector<std::uint8_t> garbage(70, 0x5A);
  const auto bad = f.unit->Receive(f.now, 3, garbage);
  EXPECT_EQ(bad.status, FrameStatus::kFrameRejected);
  EXPECT_NE(bad.tg_reason, tg::RejectReason::kNone);
  const std::array<std::uint8_t, 2> unknown_type{0x63, 0x00};
  const auto undecodable = f.unit->Receive(f.now, 3, radio.SendPayload(f.now, unknown_type));
  EXPECT_EQ(undecodable.status, FrameStatus::kPayloadInvalid);
  EXPECT_EQ(undecodable.decode_error, messages::DecodeError::kUnknownType);
  const auto mixed = f.unit->Receive(
      f.now, 3,
      radio.Send(f.now, {ReportAt(*f.unit, 4, 1'000'000, kLen), messages::CrossingRequest{3, 8},
                         messages::KeepAlive{}, messages::CentrePositionReport{3, 0, 1'000'000, 800'000, 0}}));
  ASSERT_EQ(mixed.status, FrameStatus::kAccepted) << ToString(mixed.decode_error);
  ASSERT_EQ(mixed.message_count, 4U);
  EXPECT_EQ(mixed.messages[0].status, MessageStatus::kWrongTrain);
  EXPECT_EQ(mixed.messages[1].status, MessageStatus::kUnknownCrossing);
  EXPECT_EQ(mixed.messages[2].status, MessageStatus::kUnexpectedType);
  EXPECT_EQ(mixed.messages[3].status, MessageStatus::kNoDeparture);
  const auto length = f.unit->Receive(f.now, 3, radio.Send(f.now, {ReportAt(*f.unit, 3, 1'000'000, kLen + 1)}));
  ASSERT_EQ(length.message_count, 1U);
  EXPECT_EQ(length.messages[0].status, MessageStatus::kReportRejected);
  EXPECT_EQ(length.messages[0].report, mb::wayside::ReportStatus::kLengthMismatch);
  const std::array<CrossingSensors, 1> sensors{CrossingSensors{99, true, false, lc::wayside::ClockInput::kGnss}};
  f.input.crossings = sensors;
  f.now += kGroundCycleMs;
  const auto& out = f.Cycle();
  ASSERT_EQ(out.events.Size(), 1U);
  EXPECT_EQ(out.events[0].status, InputStatus::kUnknownCrossing);
  EXPECT_EQ(out.events[0].id, 99U);
  EXPECT_EQ(f.unit->Cycle(f.now - 1, f.input).status, CycleStatus::kClockWentBack);
}

// A request in the train's telegram reaches the crossing's controller: the warning starts, the
// report goes back to the train behind its stop limit; a withdrawal is acknowledged.
TEST(WaysideUnitCrossings, RequestsAndWithdrawalsTravelAsBytes) {
  Fixture f;
  TrainRadio radio(3, 13, kGround);
  f.Enter(3, 1'000'000, radio);
  std::array<CrossingSensors, 1> sensors{CrossingSensors{7, false, true, lc::wayside::ClockInput::kGnss}};
  f.input.crossings = sensors;
  const auto r = f.unit->Receive(f.now, 3, radio.Send(f.now, {messages::NoPosition{}, messages::CrossingRequest{3, 7}}));
  ASSERT_EQ(r.status, FrameStatus::kAccepted) << ToString(r.tg_reason);
  f.now += kGroundCycleMs;
  const auto& out = f.Cycle();
  ASSERT_EQ(out.crossings.Size(), 1U);
  EXPECT_TRUE(out.crossings[0].lights_on);
  EXPECT_EQ(out.crossings[0].report.status, messages::CrossingStatus::kWarning);
  const auto b = radio.Take(f.now, out);
  ASSERT_EQ(b.size, 2U);
  ASSERT_NE(StopLimitOf(b), nullptr);
  const auto* report = std::get_if<messages::CrossingReport>(&b.messages[1]);
  ASSERT_NE(report, nullptr);
  EXPECT_EQ(report->crossing_id, 7U);
  EXPECT_TRUE(report->Lists(3));
  (void)f.unit->Receive(f.now, 3, radio.Send(f.now, {messages::CrossingWithdrawal{{3, 7}}}));
  f.now += kGroundCycleMs;
  const auto b2 = radio.Take(f.now, f.Cycle());
  ASSERT_EQ(b2.size, 2U);
  const auto* ack = std::get_if<messages::WithdrawalAck>(&b2.messages[1]);
  ASSERT_NE(ack, nullptr);
  EXPECT_EQ(ack->crossing_id, 7U);
  EXPECT_EQ(ack->train_id, 3U);
}

// A handover point ahead is secured only while the next base station has room; otherwise the
// point stops the train (REQ-MB-017).
TEST(WaysideUnitTrains, HandoverPointHoldsTheTrainWhileTheNextBaseStationIsFull) {
  auto line = StraightLine(3'000'000);
  line.handovers = {{1, 1'500'000}};
  WaysideConfig c = BaseConfig(line);
  c.trains_per_base_station = 1;
  auto unit = std::move(WaysideUnit::Create(c).unit);
  ASSERT_TRUE(unit);
  ASSERT_EQ(unit->Admit(1, 11), AdmitStatus::kAdmitted);
  ASSERT_EQ(unit->Admit(2, 12), AdmitStatus::kAdmitted);
  ASSERT_EQ(unit->Register({1, kLen, 2'500'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  EXPECT_EQ(unit->Register({2, kLen, 2'900'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kBaseStationFull);
  ASSERT_EQ(unit->Register({2, kLen, 1'200'000, 0, mb::wayside::InitialPosition::kEntryBalise}).status,
            RegisterStatus::kRegistered);
  const auto& out = unit->Cycle(kGroundCycleMs, {});
  ASSERT_EQ(out.trains.Size(), 2U);
  EXPECT_EQ(out.trains[1].kind, Obstruction::kHandover);
  EXPECT_EQ(out.trains[1].limit_mm, 1'500'000 - c.line.margins.handover_mm);
  ASSERT_GE(out.events.Size(), 1U);
  EXPECT_EQ(out.events[0].status, InputStatus::kBaseStationFull);
  ASSERT_EQ(unit->Remove(1), mb::wayside::CommandStatus::kAccepted);
  const auto& freed = unit->Cycle(2 * kGroundCycleMs, {});
  ASSERT_EQ(freed.trains.Size(), 1U);
  EXPECT_EQ(freed.trains[0].kind, Obstruction::kEndOfTrack);
  EXPECT_EQ(unit->BaseStationLoad(1), 1U);
}

// The centre takes the train's centre position report with its envelope as sent: the tracked
// front is the report's front (not its rear).
TEST(WaysideUnitCentre, CentrePositionReportReachesTheDepartureScheduler) {
  Fixture f(kTrainsPerBaseStation, 1);
  TrainRadio radio(3, 13, kGround);
  f.Enter(3, 1'000'000, radio);
  const std::array<std::uint32_t, 1> ids{7};
  ASSERT_EQ(f.unit->StartDeparture({3, 1, 60'000, 1'000'000}, ids, f.now), lc::wayside::SchedulerError::kNone);
  const auto r = f.unit->Receive(
      f.now, 3, radio.Send(f.now, {messages::CentrePositionReport{3, f.now, 1'050'000, 850'000, 1000}}));
  ASSERT_EQ(r.status, FrameStatus::kAccepted) << ToString(r.tg_reason);
  EXPECT_EQ(r.messages[0].status, MessageStatus::kAccepted);
  f.now += kGroundCycleMs;
  const auto& out = f.Cycle();
  ASSERT_EQ(out.departures.Size(), 1U);
  EXPECT_EQ(out.departures[0].train_id, 3U);
  EXPECT_FALSE(out.departures[0].cleared);
  const auto* s = f.unit->Scheduler(3);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->TrackedFrontMm(), 1'050'000);
  // the start time reached the controller, which acknowledges it; the next cycle the centre
  // counts the acknowledgement
  EXPECT_TRUE(f.unit->Controller(7)->Status().pending.present);
  f.now += kGroundCycleMs;
  (void)f.Cycle();
  EXPECT_TRUE(f.unit->Scheduler(3)->Crossings()[0].acked);
}

// With an external link the centre's start time leaves the unit instead of reaching the
// controller; what comes back over the link is checked: a crossing the unit does not hold, an
// acknowledgement of a departure it does not hold, and lists longer than a cycle takes are
// refused with typed events, the rest is used, and nothing is allocated.
TEST(WaysideUnitCentre, ExternalLinkCarriesTheMessagesAndRefusesUnknownNames) {
  Fixture f(kTrainsPerBaseStation, 1, CentreLink::kExternal);
  const std::array<std::uint32_t, 1> ids{7};
  ASSERT_EQ(f.unit->StartDeparture({3, 1, 60'000, 1'000'000}, ids, f.now), lc::wayside::SchedulerError::kNone);
  const auto& sent = f.Cycle();
  ASSERT_EQ(sent.start_times.Size(), 1U);
  EXPECT_EQ(sent.start_times[0].crossing_id, 7U);
  EXPECT_FALSE(f.unit->Controller(7)->Status().pending.present);
  EXPECT_EQ(sent.start_acks.Size(), 0U);
  ASSERT_EQ(sent.crossing_reports.Size(), 1U);

  const std::array<lc::wayside::StartTimeMessage, 2> starts{sent.start_times[0], {99, 1, 0}};
  const std::array<lc::wayside::WarningStopMessage, 1> stops{{{98, 1}}};
  f.input.to_crossings = ToCrossings{starts, stops};
  f.now += kGroundCycleMs;
  testing::StartCountingAllocations();
  const auto& delivered = f.Cycle();
  EXPECT_EQ(testing::StopCountingAllocations(), 0U);
  EXPECT_TRUE(f.unit->Controller(7)->Status().pending.present);
  ASSERT_EQ(delivered.start_acks.Size(), 1U);
  ASSERT_EQ(delivered.events.Size(), 2U);
  EXPECT_EQ(delivered.events[0].status, InputStatus::kUnknownCrossing);
  EXPECT_EQ(delivered.events[0].id, 99U);
  EXPECT_EQ(delivered.events[1].id, 98U);

  const std::array<lc::wayside::StartTimeAck, 3> acks{
      delivered.start_acks[0], lc::wayside::StartTimeAck{7, 42, 0, true}, lc::wayside::StartTimeAck{97, 1, 0, true}};
  std::array<messages::CrossingReport, 1> reports{};
  reports[0].crossing_id = 96;
  f.input = CycleInput{};
  f.input.to_centre = ToCentre{acks, {}, reports};
  f.now += kGroundCycleMs;
  const auto& answered = f.Cycle();
  EXPECT_TRUE(f.unit->Scheduler(3)->Crossings()[0].acked);
  ASSERT_EQ(answered.events.Size(), 3U);
  EXPECT_EQ(answered.events[0].status, InputStatus::kUnknownDeparture);
  EXPECT_EQ(answered.events[0].id, 42U);
  EXPECT_EQ(answered.events[1].status, InputStatus::kUnknownCrossing);
  EXPECT_EQ(answered.events[1].id, 97U);
  EXPECT_EQ(answered.events[2].id, 96U);

  const std::vector<messages::CrossingReport> flood(kMaxLinkMessages + 1, answered.crossing_reports[0]);
  f.input = CycleInput{};
  f.input.to_centre.reports = flood;
  f.now += kGroundCycleMs;
  const auto& flooded = f.Cycle();
  ASSERT_EQ(flooded.events.Size(), 1U);
  EXPECT_EQ(flooded.events[0].status, InputStatus::kTooManyMessages);
}

// A unit that connects the centre to its controllers itself uses no link input.
TEST(WaysideUnitCentre, InternalLinkRefusesLinkInput) {
  Fixture f(kTrainsPerBaseStation, 1);
  const std::array<lc::wayside::StartTimeMessage, 1> starts{{{7, 1, 0}}};
  f.input.to_crossings.start_times = starts;
  const auto& out = f.Cycle();
  ASSERT_EQ(out.events.Size(), 1U);
  EXPECT_EQ(out.events[0].status, InputStatus::kLinkNotExternal);
  EXPECT_FALSE(f.unit->Controller(7)->Status().pending.present);
}

TEST(WaysideUnitRadio, NoHeapAfterCreate) {
  Fixture f;
  TrainRadio radio(3, 13, kGround);
  f.Enter(3, 1'000'000, radio);
  const auto frame = radio.Send(f.now, {ReportAt(*f.unit, 3, 1'000'000, kLen), messages::CrossingRequest{3, 7}});
  testing::StartCountingAllocations();
  const auto r = f.unit->Receive(f.now, 3, frame);
  f.now += kGroundCycleMs;
  const auto& out = f.Cycle();
  const std::size_t allocations = testing::StopCountingAllocations();
  EXPECT_EQ(allocations, 0U);
  EXPECT_EQ(r.status, FrameStatus::kAccepted);
  EXPECT_EQ(out.frames.Size(), 1U);
}

}  // namespace
}  // namespace railproof::units::test
