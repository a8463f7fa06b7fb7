// The tg vectors of the ground role and the lc vectors of the on-board variant replayed
// through the wayside unit's external interface (the mb vectors: test_wayside_replay.cpp).
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
//       Not replayed: the GNSS-time vectors (lc_gnss*.jsonl). They drive the centre scheduler
//       and the controllers each with its own inputs, with messages lost between them; the
//       unit wires the scheduler's start times and stops to the controllers and their
//       acknowledgements and reports back to the scheduler inside its cycle, so such a
//       vector's inputs cannot be given through its interface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
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

void ReplayLc(const LcFile& f, const rc::JsonVector& v, std::vector<std::string>& problems) {
  const mb::wayside::test::LineData line = StraightLine(f.restrictions.back().end_mm);
  WaysideConfig c = BaseConfig(line);
  const auto t_ms = [&](std::size_t k) { return v.steps.at(k).at("t_ms").get<std::int64_t>(); };
  const std::int64_t tick = v.steps.size() > 1 ? t_ms(1) - t_ms(0) : 10'000;
  // the model's tick is the ground cycle: the links must outlive two of them
  c.radio.turnaround_ms = static_cast<std::uint32_t>(2 * tick);
  c.radio.link_timeout_ms = static_cast<std::uint32_t>(2 * tick);
  c.radio.echo_validity_ms = static_cast<std::uint32_t>(2 * tick);
  c.line.ground_cycle_ms = tick;
  c.crossings = f.crossings;
  c.controller = f.controller;
  const Shift shift{tick - v.steps.at(0).at("t_ms").get<std::int64_t>()};
  auto created = WaysideUnit::Create(c);
  if (created.error != ConfigError::kNone) {
    problems.push_back(std::string("unit configuration refused: ") + ToString(created.error) + " " +
                       mb::wayside::ToString(created.line_error));
    return;
  }
  WaysideUnit& unit = *created.unit;
  std::vector<Train> trains;
  for (const std::uint32_t id : {f.train_id, f.other_train_id}) {
    trains.push_back(Train{id, TrainRadio(id, static_cast<std::uint16_t>(10 + id), c.radio_id, c.radio)});
    (void)unit.Admit(id, static_cast<std::uint16_t>(10 + id));
  }
  std::vector<CrossingSensors> healthy;
  for (const lc::CrossingData& x : f.crossings) {
    healthy.push_back(CrossingSensors{x.id, false, true, lc::wayside::ClockInput::kGnss});
  }
  const CycleOutput& first = unit.Cycle(0, CycleInput{healthy, {}, {}});
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
    const CycleOutput& out = unit.Cycle(now, CycleInput{sensors, {}, {}});
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
      const auto o = std::find_if(out.crossings.begin(), out.crossings.end(),
                                  [&](const CrossingOutput& x) { return x.crossing_id == id; });
      const lc::wayside::CrossingController* ctl = unit.Controller(id);
      if (o == out.crossings.end() || ctl == nullptr) {
        chk.Fail(pre + "not held by the unit");
        continue;
      }
      chk.Expect(pre + "lights_on", rc::Bool(e.at("lights_on").get<bool>()), rc::Bool(o->lights_on));
      chk.Expect(pre + "barriers_down_commanded", rc::Bool(e.at("barriers_down_commanded").get<bool>()),
                 rc::Bool(o->barriers_down_commanded));
      chk.Expect(pre + "alarm", "false", rc::Bool(o->alarm));
      chk.Expect(pre + "report", ReportString(e.at("report")), ReportString(shift.ToModel(o->report)));
      chk.Expect(pre + "state", e.at("state").get<std::string>(), lc::wayside::ToString(ctl->Status().state));
      if (!e.at("warning_start_ms").is_null()) {
        chk.Expect(pre + "warning_start_ms", rc::OptInt(e.at("warning_start_ms")),
                   std::to_string(shift.ToModel(ctl->Status().warning_start_ms)));
      }
      chk.Expect(pre + "failure", e.at("failure").get<std::string>(), lc::wayside::ToString(ctl->Status().failure));
      chk.Expect(pre + "requesters", Ids(e.at("requesters")), Ids(ctl->Status().Requesters()));
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

TEST(WaysideVectors, CrossingVectorsOfTheOnboardVariant) {
  const LcVectors& set = LcVectorSet();
  ASSERT_EQ(set.error, "");
  std::size_t replayed = 0;
  std::size_t gnss = 0;
  std::size_t failed = 0;
  for (const rc::JsonVector& v : set.vectors) {
    const LcFile& f = set.files.at(v.file);
    if (f.gnss) {
      ++gnss;  // not expressible through the unit (header comment)
      continue;
    }
    std::vector<std::string> problems;
    ReplayLc(f, v, problems);
    ++replayed;
    if (!problems.empty()) {
      ++failed;
      ADD_FAILURE() << v.file << " " << v.id << ": " << problems.front();
    }
  }
  EXPECT_EQ(failed, 0U) << "of " << replayed;
  EXPECT_GT(replayed, 0U);
  EXPECT_GT(gnss, 0U);  // the set still holds the variant the unit cannot take
}

}  // namespace
}  // namespace railproof::units::test
