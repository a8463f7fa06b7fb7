// The tg vectors of the ground role and the lc vectors of both variants replayed through the
// wayside unit's external interface (the mb vectors: test_wayside_replay.cpp).
// The files are read with the conformance runners' readers and key lists.
//   tg  every vector of the ground role: the unit admits the vector's train with the vector's
//       radio settings (the header's endpoint parameters as the unit's radio configuration);
//       a tick is a ground cycle, whose frame for the train is decoded (sequence number, echo)
//       with the train's link; an rx step is the vector's telegram as bytes into Receive,
//       carrying NO_POSITION (verdict, gap, link). Not checked: the vectors' "tracking
//       abnormal" (REQ-TG-015); the unit does not derive it from the link (its tracking is the
//       ground's, fed by position reports).
//   lc  every vector of the ONBOARD variant (lc.jsonl, lc.long_warning, lc.two_trains): the
//       requests and withdrawals the controllers get are CROSSING_REQUEST / _WITHDRAWAL
//       messages in telegrams from the trains they name, the barrier detection the unit's
//       sensor input; out: each crossing's equipment commands and report (the unit's output),
//       the report as every listed train decodes it from its frame, the withdrawal
//       acknowledgements decoded from the frames, and the controller's state, failure and
//       requesters (the unit's read-only view). The model's 10 s tick is the ground cycle, so
//       the radio's time limits are widened to two ticks in the unit's configuration, and one
//       cycle one tick before the vector's time 0 (healthy barrier, nothing received) brings
//       the links up so that the trains' first telegrams carry an echo.
//   lc  every vector of the GNSS-TIME variant (lc_gnss*.jsonl): the centre and the crossings
//       are two places joined by a lossy ground network, so two units with an external centre
//       link, each with the header's crossings: the centre unit holds the departure (started
//       at the header's time) and the train's link, the crossing unit drives the controllers.
//       A step at t is the centre unit's cycle at t, then the crossing unit's at t: the model's
//       centre also runs before the controllers in a tick, and its start times and stops reach
//       them in the same tick. Between the units the test is the network: of what one unit's
//       CycleOutput sent (and the other has not received), it passes to the other's
//       CycleInput the messages the vector delivers, in the vector's order, and keeps back the
//       others (lost, or delivered later: a report of the model's one-tick delay); a delivery
//       the units never sent fails the step. In: the centre position report (or NO_POSITION)
//       in a telegram from the train before the centre's cycle, the clock and barrier
//       detection as the crossing unit's sensor input; out: the centre's start times and
//       stops, departure signal and block (CycleOutput) and each crossing's scheduling state
//       (read-only view); each controller's equipment commands, alarm, report,
//       acknowledgements (CycleOutput) and state, warning start, pending departure, clock and
//       failure (read-only view); neither unit may report an input it did not use. One cycle
//       of the centre unit at 0 before the vector (no departure yet) brings the train's link
//       up; the model's tick is the ground cycle, the radio's time limits two ticks as above.
//       The centre unit's own controllers and the crossing unit's (absent) schedulers take no
//       part. Every step is expressible; the vectors' steps carry no crossing requests.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <iterator>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "../lc_vectors.hpp"
#include "../tg_vectors.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "wayside_test_support.hpp"

namespace railproof::units::test {
namespace {

namespace rc = railproof::conformance;
using json = nlohmann::json;

std::span<const std::uint8_t> NoPositionPayload() {
  static const messages::Encoded no_position = messages::Encode(messages::NoPosition{});
  return no_position.payload.View();
}

// ---- tg: the ground role ---------------------------------------------------------------------

constexpr std::uint32_t kTgTrain = 7;

// The model's time 0 is the unit's start; a tick is one ground cycle at the tick's time, the
// rx steps after it are received at that time.
void ReplayTg(const rc::Vector& v, const rc::FileHeader& h) {
  const mb::wayside::test::LineData line = StraightLine(1'000'000);
  WaysideConfig c = BaseConfig(line);
  c.radio = h.endpoint;
  c.radio_id = h.ground_id;
  auto created = WaysideUnit::Create(c);
  ASSERT_EQ(created.error, ConfigError::kNone)
      << ToString(created.error) << " " << mb::wayside::ToString(created.line_error);
  WaysideUnit& unit = *created.unit;
  ASSERT_EQ(unit.Admit(kTgTrain, h.train_id), AdmitStatus::kAdmitted);
  std::int64_t clock = 0;
  for (std::size_t i = 0; i < v.steps.size(); ++i) {
    const rc::Step& s = v.steps[i];
    const rc::Expected& e = s.out;
    if (s.kind == rc::Step::Kind::kTick) {
      SCOPED_TRACE("step " + std::to_string(i) + " (tick)");
      clock += h.time_ms_per_tick;
      const CycleOutput& out = unit.Cycle(clock, {});
      ASSERT_EQ(out.frames.Size(), 1U);
      ASSERT_EQ(out.frames[0].train_id, kTgTrain);
      tg::DecodedFrame d{};
      ASSERT_EQ(tg::DecodeFrame(out.frames[0].frame.View(), d), tg::RejectReason::kNone);
      EXPECT_EQ(d.header.seq, e.tx_seq);
      EXPECT_EQ(d.header.echo_valid, e.tx_echo.has_value());
      if (e.tx_echo) {
        EXPECT_EQ(d.header.echo, *e.tx_echo);
      }
      EXPECT_EQ(out.trains[0].link, e.link) << tg::ToString(out.trains[0].link);
      continue;
    }
    SCOPED_TRACE("step " + std::to_string(i) + " (rx)");
    const ReceiveResult r =
        unit.Receive(clock, kTgTrain, VectorFrame(s.tg, clock, KeyOf(kTgTrain), NoPositionPayload()));
    EXPECT_STREQ(rc::ToString(rc::VerdictOf(r.tg_reason)), rc::ToString(e.verdict));
    EXPECT_EQ(r.gap, e.gap);
    EXPECT_EQ(r.link, e.link) << tg::ToString(r.link);
    if (r.tg_reason == tg::RejectReason::kNone) {
      EXPECT_EQ(r.status, FrameStatus::kAccepted) << ToString(r.status);
      ASSERT_EQ(r.message_count, 1U);
      EXPECT_EQ(r.messages[0].status, MessageStatus::kAccepted);
    } else {
      EXPECT_EQ(r.status, FrameStatus::kFrameRejected);
    }
  }
}

TEST(WaysideVectors, TelegramVectorsOfTheGroundRole) {
  const rc::LoadResult& loaded = TgVectorSet();
  ASSERT_TRUE(loaded.ok) << loaded.error;
  std::size_t replayed = 0;
  for (const rc::Vector& v : loaded.set.vectors) {
    if (v.role != tg::Role::kGround) {
      continue;
    }
    SCOPED_TRACE(v.file + ": " + v.id);
    ReplayTg(v, loaded.set.headers[v.header_index]);
    ++replayed;
  }
  EXPECT_GT(replayed, 0U);
}

// ---- lc: the controllers of the on-board variant ------------------------------------------------

using lc::conformance::Ids;
using lc::conformance::ReportString;

// The unit runs the vector shifted by one tick (the ground cannot start before 0): a time of
// the unit in the model's time; 0 (no warning) stays 0.
struct Shift {
  std::int64_t ms = 0;
  [[nodiscard]] std::int64_t ToModel(std::int64_t t) const { return t == 0 ? 0 : t - ms; }
  [[nodiscard]] messages::CrossingReport ToModel(messages::CrossingReport r) const {
    r.warning_start_ms = ToModel(r.warning_start_ms);
    r.issued_ms -= ms;
    return r;
  }
};

// A crossing of the vector as the unit holds it: its output of the cycle and its controller's
// state, or a failure naming it.
struct HeldCrossing {
  const CrossingOutput* output = nullptr;
  const lc::wayside::ControllerStatus* status = nullptr;
};
HeldCrossing Held(const WaysideUnit& unit, const CycleOutput& out, std::uint32_t id, const std::string& pre,
                  rc::Checker& chk) {
  const auto o = std::find_if(out.crossings.begin(), out.crossings.end(),
                              [&](const CrossingOutput& x) { return x.crossing_id == id; });
  const lc::wayside::CrossingController* ctl = unit.Controller(id);
  if (o == out.crossings.end() || ctl == nullptr) {
    chk.Fail(pre + "not held by the unit");
    return {};
  }
  return {&*o, &ctl->Status()};
}

// What both variants compare of a crossing: the equipment commands and the alarm, the report,
// the controller's state, warning start and failure (times in the model's clock).
void ExpectCrossing(const std::string& pre, const json& e, const HeldCrossing& x, const Shift& shift,
                    rc::Checker& chk) {
  const CrossingOutput& o = *x.output;
  const lc::wayside::ControllerStatus& st = *x.status;
  chk.Expect(pre + "lights_on", rc::Bool(e.at("lights_on").get<bool>()), rc::Bool(o.lights_on));
  chk.Expect(pre + "barriers_down_commanded", rc::Bool(e.at("barriers_down_commanded").get<bool>()),
             rc::Bool(o.barriers_down_commanded));
  chk.Expect(pre + "alarm", "false", rc::Bool(o.alarm));
  chk.Expect(pre + "report", ReportString(e.at("report")), ReportString(shift.ToModel(o.report)));
  chk.Expect(pre + "state", e.at("state").get<std::string>(), lc::wayside::ToString(st.state));
  if (!e.at("warning_start_ms").is_null()) {
    chk.Expect(pre + "warning_start_ms", rc::OptInt(e.at("warning_start_ms")),
               std::to_string(shift.ToModel(st.warning_start_ms)));
  }
  chk.Expect(pre + "failure", e.at("failure").get<std::string>(), lc::wayside::ToString(st.failure));
}

bool Lists(const json& ids, std::uint32_t train) {
  return std::any_of(ids.begin(), ids.end(), [&](const json& x) { return x.get<std::uint32_t>() == train; });
}

// One train's end of its link with the unit (radio id = 10 + train id).
struct Train {
  std::uint32_t id;
  TrainRadio radio;
};

// The step's requests and withdrawals as telegrams from the trains they name, in the order of
// each controller's lists (a new telegram whenever the train changes or the bundle is full).
void SendRequests(WaysideUnit& unit, std::vector<Train>& trains, const json& step, std::int64_t now,
                  rc::Checker& chk) {
  std::vector<std::pair<std::uint32_t, messages::Message>> sequence;
  for (const json& c : step.at("controllers")) {
    const auto crossing = c.at("crossing_id").get<std::uint32_t>();
    for (const json& x : c.at("in").at("requests")) {
      sequence.emplace_back(x.get<std::uint32_t>(), messages::CrossingRequest{x.get<std::uint32_t>(), crossing});
    }
    for (const json& x : c.at("in").at("withdrawals")) {
      sequence.emplace_back(x.get<std::uint32_t>(),
                            messages::CrossingWithdrawal{messages::CrossingRequest{x.get<std::uint32_t>(), crossing}});
    }
  }
  for (std::size_t k = 0; k < sequence.size();) {
    const std::uint32_t id = sequence[k].first;
    auto train = std::find_if(trains.begin(), trains.end(), [&](const Train& t) { return t.id == id; });
    if (train == trains.end()) {
      chk.Fail("a request of train " + std::to_string(id) + ", which the header does not name");
      return;
    }
    messages::Bundle b;
    for (; k < sequence.size() && sequence[k].first == id && b.Add(sequence[k].second); ++k) {
    }
    const ReceiveResult r =
        unit.Receive(now, id, train->radio.SendPayload(now, messages::EncodeBundle(b.View()).payload.View()));
    const auto taken = r.Messages();
    const bool accepted = r.status == FrameStatus::kAccepted &&
                          std::all_of(taken.begin(), taken.end(),
                                      [](const MessageResult& m) { return m.status == MessageStatus::kAccepted; });
    if (!accepted) {
      chk.Fail("train " + std::to_string(id) + "'s telegram not taken: " + ToString(r.status) + "/" +
               tg::ToString(r.tg_reason) + "/" + ToString(r.messages[0].status));
    }
  }
}

// The model's tick of a vector (the time between its first two steps).
std::int64_t TickOf(const rc::JsonVector& v) {
  const auto t_ms = [&](std::size_t k) { return v.steps.at(k).at("t_ms").get<std::int64_t>(); };
  return v.steps.size() > 1 ? t_ms(1) - t_ms(0) : 10'000;
}

// A unit of the file's crossings on a line as long as its permitted-speed profile, on a ground
// cycle of the model's tick; the links must outlive two of them.
WaysideConfig LcUnitConfig(const mb::wayside::test::LineData& line, const LcFile& f, std::int64_t tick) {
  WaysideConfig c = BaseConfig(line);
  c.radio.turnaround_ms = static_cast<std::uint32_t>(2 * tick);
  c.radio.link_timeout_ms = static_cast<std::uint32_t>(2 * tick);
  c.radio.echo_validity_ms = static_cast<std::uint32_t>(2 * tick);
  c.line.ground_cycle_ms = tick;
  c.crossings = f.crossings;
  c.controller = f.controller;
  return c;
}

// The unit of `c`, or null and a problem.
std::unique_ptr<WaysideUnit> LcUnit(const WaysideConfig& c, std::vector<std::string>& problems) {
  auto created = WaysideUnit::Create(c);
  if (created.error != ConfigError::kNone) {
    problems.push_back(std::string("unit configuration refused: ") + ToString(created.error) + " " +
                       mb::wayside::ToString(created.line_error));
  }
  return std::move(created.unit);
}

void ReplayLc(const LcFile& f, const rc::JsonVector& v, std::vector<std::string>& problems) {
  const mb::wayside::test::LineData line = StraightLine(f.restrictions.back().end_mm);
  const std::int64_t tick = TickOf(v);
  const WaysideConfig c = LcUnitConfig(line, f, tick);
  const Shift shift{tick - v.steps.at(0).at("t_ms").get<std::int64_t>()};
  const std::unique_ptr<WaysideUnit> created = LcUnit(c, problems);
  if (!created) {
    return;
  }
  WaysideUnit& unit = *created;
  std::vector<Train> trains;
  for (const std::uint32_t id : {f.train_id, f.other_train_id}) {
    trains.push_back(Train{id, TrainRadio(id, static_cast<std::uint16_t>(10 + id), c.radio_id, c.radio)});
    (void)unit.Admit(id, static_cast<std::uint16_t>(10 + id));
  }
  std::vector<CrossingSensors> healthy;
  for (const lc::CrossingData& x : f.crossings) {
    healthy.push_back(CrossingSensors{x.id, false, true, lc::wayside::ClockInput::kGnss});
  }
  CycleInput warm_up;
  warm_up.crossings = healthy;
  const CycleOutput& first = unit.Cycle(0, warm_up);
  for (Train& t : trains) {
    (void)t.radio.Take(0, first);
    (void)unit.Receive(0, t.id, t.radio.Send(0, {messages::NoPosition{}}));
  }
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& step = v.steps[k];
    const std::int64_t now = step.at("t_ms").get<std::int64_t>() + shift.ms;
    rc::Checker chk(problems, "step " + std::to_string(k) + " (t=" + std::to_string(now - shift.ms) + " ms): ");
    SendRequests(unit, trains, step, now, chk);
    std::vector<CrossingSensors> sensors;
    for (const json& x : step.at("controllers")) {
      const json& xin = x.at("in");
      sensors.push_back(CrossingSensors{x.at("crossing_id").get<std::uint32_t>(), xin.at("barrier_down").get<bool>(),
                                        xin.at("barrier_up").get<bool>(), lc::wayside::ClockInput::kGnss});
    }
    CycleInput input;
    input.crossings = sensors;
    const CycleOutput& out = unit.Cycle(now, input);
    // what each train decodes from its frame
    std::map<std::uint32_t, messages::Bundle> heard;
    for (Train& t : trains) {
      heard[t.id] = t.radio.Take(now, out);
      if (heard[t.id].size == 0) {
        chk.Fail("train " + std::to_string(t.id) + " got no frame it accepts (" +
                 tg::ToString(t.radio.LastReason()) + ")");
      }
    }
    const json& controllers = step.at("controllers");
    for (std::size_t i = 0; i < controllers.size(); ++i) {
      const json& e = controllers[i].at("out");
      const auto id = controllers[i].at("crossing_id").get<std::uint32_t>();
      const std::string pre = "crossing " + std::to_string(id) + " ";
      const HeldCrossing held = Held(unit, out, id, pre, chk);
      if (held.output == nullptr) {
        continue;
      }
      ExpectCrossing(pre, e, held, shift, chk);
      chk.Expect(pre + "requesters", Ids(e.at("requesters")), Ids(held.status->Requesters()));
      for (const Train& t : trains) {
        const std::string tpre = pre + "to train " + std::to_string(t.id) + ": ";
        std::string report = "none";
        bool acked = false;
        for (const messages::Message& m : heard[t.id].View()) {
          if (const auto* r = std::get_if<messages::CrossingReport>(&m); r != nullptr && r->crossing_id == id) {
            report = ReportString(shift.ToModel(*r));
          }
          if (const auto* a = std::get_if<messages::WithdrawalAck>(&m); a != nullptr && a->crossing_id == id) {
            acked = acked || a->train_id == t.id;
          }
        }
        const bool listed = Lists(e.at("report").at("requesters"), t.id);
        chk.Expect(tpre + "report", listed ? ReportString(e.at("report")) : "none", report);
        chk.Expect(tpre + "withdrawal acknowledged", rc::Bool(Lists(e.at("withdrawal_acks"), t.id)), rc::Bool(acked));
      }
    }
    // every train answers, as an on-board unit without a request due does, so that the
    // next ground telegram echoes it
    for (Train& t : trains) {
      (void)unit.Receive(now, t.id, t.radio.Send(now, {messages::NoPosition{}}));
    }
  }
}

// ---- lc: the centre and the crossings of the GNSS-time variant -----------------------------------

using lc::conformance::ReportOf;

lc::wayside::ClockInput ClockOf(const std::string& name) {
  using lc::wayside::ClockInput;
  for (const ClockInput c : {ClockInput::kGnss, ClockInput::kNoGnss, ClockInput::kFault}) {
    if (name == lc::wayside::ToString(c)) {
      return c;
    }
  }
  return ClockInput::kGnss;  // as the lc runner (its step checks refuse other names)
}

// One direction of the centre link: what one unit sent that the other has not received.
template <typename T>
struct InFlight {
  std::vector<T> sent;

  void Add(std::span<const T> out) { sent.insert(sent.end(), out.begin(), out.end()); }
  // The vector's deliveries (in its order) taken out of what was sent.
  std::vector<T> Deliver(const std::vector<T>& delivered, const std::string& what, rc::Checker& chk) {
    std::vector<T> passed;
    for (const T& m : delivered) {
      const auto it = std::find_if(sent.begin(), sent.end(), [&](const T& x) { return Text(x) == Text(m); });
      if (it == sent.end()) {
        chk.Fail(what + " " + Text(m) + " delivered but never sent");
        continue;
      }
      passed.push_back(*it);
      sent.erase(it);
    }
    return passed;
  }
};

template <typename T>
std::span<const T> View(const std::vector<T>& v) {
  return {v.data(), v.size()};
}

// The events of a cycle (none expected: every input is used).
std::string Events(const CycleOutput& out) {
  std::string s;
  for (const InputEvent& e : out.events) {
    s += std::string(ToString(e.status)) + "(" + std::to_string(e.id) + ") ";
  }
  return s;
}

// The centre unit's cycle: its outputs against the vector's centre.
void CheckCentre(const WaysideUnit& unit, const CycleOutput& out, const json& e, std::uint32_t train,
                 rc::Checker& chk) {
  chk.Expect("centre events", "", Events(out));
  if (out.departures.Size() != 1) {
    chk.Fail("centre: " + std::to_string(out.departures.Size()) + " departures");
    return;
  }
  chk.Expect("departure_cleared", rc::Bool(e.at("departure_cleared").get<bool>()), rc::Bool(out.departures[0].cleared));
  chk.Expect("block", e.at("block").get<std::string>(), lc::wayside::ToString(out.departures[0].block));
  chk.Expect("start_times", Text(View(ListOf(e.at("start_times"), StartTimeOf))), Text(out.start_times.Span()));
  chk.Expect("warning_stops", Text(View(ListOf(e.at("warning_stops"), StopOf))), Text(out.warning_stops.Span()));
  const lc::wayside::CentreScheduler* centre = unit.Scheduler(train);
  for (const json& x : e.at("crossings")) {
    const auto id = x.at("crossing_id").get<std::uint32_t>();
    const std::string pre = "centre crossing " + std::to_string(id) + " ";
    const lc::wayside::ScheduledCrossing* sc = centre != nullptr ? centre->Find(id) : nullptr;
    if (sc == nullptr) {
      chk.Fail(pre + "not scheduled");
      continue;
    }
    chk.Expect(pre + "start_ms", std::to_string(x.at("start_ms").get<std::int64_t>()), std::to_string(sc->start_ms));
    for (const auto& [key, actual] :
         {std::pair{"start_pending", sc->start_pending}, std::pair{"acked", sc->acked}, std::pair{"passed", sc->passed},
          std::pair{"stop_pending", sc->stop_pending}, std::pair{"stop_acked", sc->stop_acked},
          std::pair{"clock_fault", sc->clock_fault}}) {
      chk.Expect(pre + key, rc::Bool(x.at(key).get<bool>()), rc::Bool(actual));
    }
  }
}

// The crossing unit's cycle: each controller against the vector's.
void CheckCrossings(const WaysideUnit& unit, const CycleOutput& out, const json& controllers, rc::Checker& chk) {
  chk.Expect("crossing unit events", "", Events(out));
  for (const json& x : controllers) {
    const json& e = x.at("out");
    const auto id = x.at("crossing_id").get<std::uint32_t>();
    const std::string pre = "crossing " + std::to_string(id) + " ";
    const HeldCrossing held = Held(unit, out, id, pre, chk);
    if (held.output == nullptr) {
      continue;
    }
    ExpectCrossing(pre, e, held, Shift{}, chk);  // the GNSS-time replay runs in the model's clock
    const lc::wayside::ControllerStatus& st = *held.status;
    std::vector<lc::wayside::StartTimeAck> start_acks;
    std::copy_if(out.start_acks.begin(), out.start_acks.end(), std::back_inserter(start_acks),
                 [&](const lc::wayside::StartTimeAck& a) { return a.crossing_id == id; });
    std::vector<lc::wayside::WarningStopAck> stop_acks;
    std::copy_if(out.stop_acks.begin(), out.stop_acks.end(), std::back_inserter(stop_acks),
                 [&](const lc::wayside::WarningStopAck& a) { return a.crossing_id == id; });
    chk.Expect(pre + "start_acks", Text(View(ListOf(e.at("start_acks"), StartAckOf))), Text(View(start_acks)));
    chk.Expect(pre + "stop_acks", Text(View(ListOf(e.at("stop_acks"), StopAckOf))), Text(View(stop_acks)));
    const json& p = e.at("pending");
    chk.Expect(pre + "pending.present", rc::Bool(p.at("present").get<bool>()), rc::Bool(st.pending.present));
    if (p.at("present").get<bool>() && st.pending.present) {
      chk.Expect(pre + "pending.departure_id", rc::OptInt(p.at("departure_id")),
                 std::to_string(st.pending.departure_id));
      chk.Expect(pre + "pending.start_ms", rc::OptInt(p.at("start_ms")), std::to_string(st.pending.start_ms));
      chk.Expect(pre + "pending.active", rc::Bool(p.at("active").get<bool>()), rc::Bool(st.pending.active));
    }
    chk.Expect(pre + "clock", e.at("clock").get<std::string>(), lc::wayside::ToString(st.clock));
  }
}

void ReplayGnss(const LcFile& f, const rc::JsonVector& v, std::vector<std::string>& problems) {
  const mb::wayside::test::LineData line = StraightLine(f.restrictions.back().end_mm);
  WaysideConfig c = LcUnitConfig(line, f, TickOf(v));
  c.centre_link = CentreLink::kExternal;
  const std::unique_ptr<WaysideUnit> crossings = LcUnit(c, problems);
  c.departures = 1;
  c.scheduler = f.scheduler;
  c.profile = f.restrictions;
  const std::unique_ptr<WaysideUnit> centre = LcUnit(c, problems);
  if (!crossings || !centre) {
    return;
  }
  const std::uint32_t train = f.departure.train_id;
  TrainRadio radio(train, static_cast<std::uint16_t>(10 + train), c.radio_id, c.radio);
  if (centre->Admit(train, static_cast<std::uint16_t>(10 + train)) != AdmitStatus::kAdmitted) {
    problems.push_back("the centre unit does not admit the train");
    return;
  }
  (void)radio.Take(0, centre->Cycle(0, {}));
  std::vector<std::uint32_t> ids;
  for (const lc::CrossingData& x : f.crossings) {
    ids.push_back(x.id);
  }
  if (const lc::wayside::SchedulerError e = centre->StartDeparture(f.departure, ids, f.started_at_ms);
      e != lc::wayside::SchedulerError::kNone) {
    problems.push_back(std::string("StartDeparture: ") + lc::wayside::ToString(e));
    return;
  }
  InFlight<lc::wayside::StartTimeMessage> start_times;
  InFlight<lc::wayside::WarningStopMessage> stops;
  InFlight<lc::wayside::StartTimeAck> start_acks;
  InFlight<lc::wayside::WarningStopAck> stop_acks;
  InFlight<messages::CrossingReport> reports;
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& step = v.steps[k];
    const std::int64_t now = step.at("t_ms").get<std::int64_t>();
    rc::Checker chk(problems, "step " + std::to_string(k) + " (t=" + std::to_string(now) + " ms): ");
    // the centre: the train's position report, then what reached it from the crossings
    const json& cin = step.at("centre").at("in");
    const json& p = cin.at("position");
    const messages::Message position =
        p.is_null() ? messages::Message{messages::NoPosition{}}
                    : messages::Message{messages::CentrePositionReport{
                          p.at("train_id").get<std::uint32_t>(), p.at("time_ms").get<std::int64_t>(),
                          p.at("front_mm").get<std::int64_t>(), p.at("rear_mm").get<std::int64_t>(),
                          p.at("speed_mm_s").get<std::int64_t>()}};
    const ReceiveResult r = centre->Receive(now, train, radio.Send(now, {position}));
    if (r.status != FrameStatus::kAccepted || r.message_count != 1 ||
        r.messages[0].status != MessageStatus::kAccepted) {
      chk.Fail("the train's telegram not taken: " + std::string(ToString(r.status)) + "/" + tg::ToString(r.tg_reason) +
               "/" + ToString(r.messages[0].status));
    }
    const std::vector<lc::wayside::StartTimeAck> sacks =
        start_acks.Deliver(ListOf(cin.at("start_acks"), StartAckOf), "start-time ack", chk);
    const std::vector<lc::wayside::WarningStopAck> tacks =
        stop_acks.Deliver(ListOf(cin.at("stop_acks"), StopAckOf), "stop ack", chk);
    const std::vector<messages::CrossingReport> reps =
        reports.Deliver(ListOf(cin.at("reports"), ReportOf), "report", chk);
    CycleInput to_centre;
    to_centre.to_centre = ToCentre{View(sacks), View(tacks), View(reps)};
    const CycleOutput& cout = centre->Cycle(now, to_centre);
    (void)radio.Take(now, cout);
    CheckCentre(*centre, cout, step.at("centre").at("out"), train, chk);
    start_times.Add(cout.start_times.Span());
    stops.Add(cout.warning_stops.Span());
    // the crossings: the sensors, and what reached them from the centre
    std::vector<lc::wayside::StartTimeMessage> to_starts;
    std::vector<lc::wayside::WarningStopMessage> to_stops;
    std::vector<CrossingSensors> sensors;
    for (const json& x : step.at("controllers")) {
      const json& xin = x.at("in");
      if (!xin.at("requests").empty() || !xin.at("withdrawals").empty()) {
        chk.Fail("a crossing request in a GNSS-time step (no train telegram carries it here)");
      }
      sensors.push_back(CrossingSensors{x.at("crossing_id").get<std::uint32_t>(), xin.at("barrier_down").get<bool>(),
                                        xin.at("barrier_up").get<bool>(), ClockOf(xin.at("clock").get<std::string>())});
      for (const auto& m : start_times.Deliver(ListOf(xin.at("start_times"), StartTimeOf), "start time", chk)) {
        to_starts.push_back(m);
      }
      for (const auto& m : stops.Deliver(ListOf(xin.at("warning_stops"), StopOf), "warning stop", chk)) {
        to_stops.push_back(m);
      }
    }
    CycleInput to_crossings;
    to_crossings.crossings = sensors;
    to_crossings.to_crossings = ToCrossings{View(to_starts), View(to_stops)};
    const CycleOutput& xout = crossings->Cycle(now, to_crossings);
    CheckCrossings(*crossings, xout, step.at("controllers"), chk);
    start_acks.Add(xout.start_acks.Span());
    stop_acks.Add(xout.stop_acks.Span());
    reports.Add(xout.crossing_reports.Span());
  }
}

// Replays every vector of one variant of the set; each must match at every step. The number
// replayed.
std::size_t ReplayVariant(const LcVectors& set, bool gnss,
                   void (*replay)(const LcFile&, const rc::JsonVector&, std::vector<std::string>&)) {
  std::size_t replayed = 0;
  std::size_t failed = 0;
  for (const rc::JsonVector& v : set.vectors) {
    const LcFile& f = set.files.at(v.file);
    if (f.gnss != gnss) {
      continue;
    }
    std::vector<std::string> problems;
    replay(f, v, problems);
    ++replayed;
    if (!problems.empty()) {
      ++failed;
      ADD_FAILURE() << v.file << " " << v.id << ": " << problems.front();
    }
  }
  EXPECT_EQ(failed, 0U) << "of " << replayed;
  EXPECT_GT(replayed, 0U);
  return replayed;
}

TEST(WaysideVectors, CentreAndCrossingVectorsOfTheGnssTimeVariant) {
  const LcVectors& set = LcVectorSet();
  ASSERT_EQ(set.error, "");
  // every vector of the GNSS-time files, none left out
  const auto files = std::count_if(set.vectors.begin(), set.vectors.end(),
                                   [](const rc::JsonVector& v) { return v.file.rfind("lc_gnss", 0) == 0; });
  EXPECT_EQ(ReplayVariant(set, true, ReplayGnss), static_cast<std::size_t>(files));
}

TEST(WaysideVectors, CrossingVectorsOfTheOnboardVariant) {
  const LcVectors& set = LcVectorSet();
  ASSERT_EQ(set.error, "");
  (void)ReplayVariant(set, false, ReplayLc);
}

}  // namespace
}  // namespace railproof::units::test
