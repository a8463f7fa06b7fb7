// The capabilities' vectors replayed through the on-board unit's external interface: sensor
// samples and telegram bytes in, telegram bytes, statuses and brake demands out (the
// conformance runners replay the same vectors module by module). The files are read with the
// runners' readers and key lists. What each replay covers and what it cannot express:
//   tg  every vector of the train role: the ground's telegrams built from the vector as
//       frames, the unit's telegrams read back (sequence number, echo), verdicts, gaps, link
//       and emergency brake (the brake reason RADIO_LINK at the end of each cycle). The unit's
//       radio period is the vectors' tick.
//   mb  the on-board events of every vector, one unit per train: stop limits issued at
//       now - age, coded by the codec and framed by the ground's endpoint; the authority's
//       verdict, limit and usability out. The ground's own events are the wayside's.
//   ra  the vectors at standstill without a deviation: each model cycle is as many sensor
//       cycles as the odometry's warm-up is longer than the model's (40 / 2), with the IMU or TG
//       failing, or a balise read in the last of them; position validity and the odometry's
//       stop demand (as the brake reason) out. Not replayed: the vectors with a deviation or
//       motion (124 of 150). Their steps state the odometry's own comparisons as predicates per
//       model cycle (a deviation seen, each start point's speed agreeing with the TG, the start
//       ages, sections of abstract margin units and compensation limits of 3 or 9 cycles); a
//       sensor stream (the odometry tests' slip stream) produces a slip that the odometry
//       detects, but not a given sequence of those predicates at the model's cycles, so such a
//       replay would check the stream, not the vector. They are replayed module by module (the
//       ra runner) only.
//   br  not replayed: the vectors give abstract pattern speeds (0..6 mm/s), which no position
//       and stop limit produce through the pattern calculator; the decision with real patterns
//       is checked in test_onboard_unit.cpp (SupervisesTheSafeFrontOfTheEnvelope).
//   lc  test_onboard_crossing_replay.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mb/conformance/vector_keys.hpp"
#include "onboard_rig.hpp"
#include "ra/conformance/vector_keys.hpp"
#include "railproof/testing/jsonl_vectors.hpp"
#include "tg/conformance/vector_reader.hpp"
#include "../tg_vectors.hpp"

namespace railproof::units::test {
namespace {

using json = nlohmann::json;
namespace rc = railproof::conformance;

constexpr const char* kVectors = RAILPROOF_UNITS_VECTORS;

// Every vector of the files <prefix>*.jsonl with its file's header; the test fails on a
// missing, empty or unreadable set.
struct Loaded {
  std::vector<std::pair<std::string, json>> vectors;  // file, vector
  std::map<std::string, json> headers;
};
Loaded Load(const std::string& prefix, const rc::VectorKeys& keys) {
  Loaded l;
  std::size_t files = 0;
  const std::string e = rc::ReadVectorDirectory(
      kVectors, prefix, keys,
      [&](const std::string& file, const json& h) {
        l.headers[file] = h;
        return std::string();
      },
      [&](const rc::VectorLineRef& v) {
        l.vectors.emplace_back(v.file, *v.obj);
        return std::string();
      },
      files);
  EXPECT_EQ(e, "");
  EXPECT_FALSE(l.vectors.empty()) << "no " << prefix << " vector in " << kVectors;
  return l;
}

// ---- tg ---------------------------------------------------------------------------------------

std::span<const std::uint8_t> KeepAlivePayload() {
  static const messages::Encoded keep_alive = messages::Encode(messages::KeepAlive{});
  return keep_alive.payload.View();
}

// The model's time 0 is the unit's first cycle; a tick is the unit's telegram; the frames
// received at a tick's time are read in that cycle, after the telegram.
void ReplayTg(const rc::Vector& v, const rc::FileHeader& h) {
  const Line line;
  OnboardConfig c = Config(line);
  c.radio = h.endpoint;
  c.radio.role = tg::Role::kTrain;
  c.radio.own_id = h.train_id;
  c.radio.peer_id = h.ground_id;
  c.radio_period_ms = h.time_ms_per_tick;
  c.radio_offset_ms = h.time_ms_per_tick;
  Rig rig(c, 0);
  const std::int64_t t0 = kOnboardCycleMs;
  std::int64_t clock = 0;
  std::size_t i = 0;
  while (i < v.steps.size()) {
    const bool tick = v.steps[i].kind == rc::Step::Kind::kTick;
    if (tick) {
      clock += h.time_ms_per_tick;
    }
    while (rig.Now() + kOnboardCycleMs < t0 + clock) {
      rig.Step();
    }
    const std::size_t first_rx = tick ? i + 1 : i;
    std::size_t end = first_rx;
    while (end < v.steps.size() && v.steps[end].kind == rc::Step::Kind::kRx) {
      rig.Deliver(VectorFrame(v.steps[end].tg, t0 + clock, kKey, KeepAlivePayload()));
      ++end;
    }
    const OnboardOutputs& out = rig.Step();
    ASSERT_EQ(out.now_ms, t0 + clock);
    if (tick) {
      SCOPED_TRACE("step " + std::to_string(i) + " (tick)");
      const rc::Expected& e = v.steps[i].out;
      ASSERT_TRUE(out.sent);
      tg::DecodedFrame d{};
      ASSERT_EQ(tg::DecodeFrame(out.frame.View(), d), tg::RejectReason::kNone);
      EXPECT_EQ(d.header.seq, e.tx_seq);
      EXPECT_EQ(d.header.echo_valid, e.tx_echo.has_value());
      if (e.tx_echo) {
        EXPECT_EQ(d.header.echo, *e.tx_echo);
      }
      EXPECT_EQ(out.send_link, e.link);
    }
    for (std::size_t k = first_rx; k < end; ++k) {
      SCOPED_TRACE("step " + std::to_string(k) + " (rx)");
      const rc::Expected& e = v.steps[k].out;
      const auto ev = out.Events();
      const auto it = std::find_if(ev.begin(), ev.end(), [&](const RxEvent& x) { return x.frame == k - first_rx; });
      ASSERT_NE(it, ev.end());
      EXPECT_STREQ(rc::ToString(rc::VerdictOf(it->reject)), rc::ToString(e.verdict));
      EXPECT_EQ(it->gap, e.gap);
      EXPECT_EQ(it->link, e.link);
      if (it->reject == tg::RejectReason::kNone) {
        EXPECT_EQ(it->status, RxStatus::kAccepted);  // the keep-alive payload decoded
      }
    }
    // The emergency brake: the unit brakes for the radio link (the first brake reason) exactly
    // when the model's train brakes, as the link stands at the end of the cycle, that is after
    // the cycle's last step (its last frame, or its telegram if no frame arrived).
    const rc::Expected& last = v.steps[end - 1].out;
    if (last.eb) {
      SCOPED_TRACE("step " + std::to_string(end - 1) + " (end of cycle)");
      EXPECT_EQ(out.reason == BrakeReason::kRadioLink, *last.eb) << ToString(out.reason);
    }
    i = end;
  }
}

TEST(OnboardReplay, TelegramVectorsOfTheTrainRole) {
  const rc::LoadResult& loaded = TgVectorSet();
  ASSERT_TRUE(loaded.ok) << loaded.error;
  std::size_t replayed = 0;
  for (const rc::Vector& v : loaded.set.vectors) {
    if (v.role != tg::Role::kTrain) {
      continue;
    }
    SCOPED_TRACE(v.file + ": " + v.id);
    ReplayTg(v, loaded.set.headers[v.header_index]);
    ++replayed;
  }
  EXPECT_GT(replayed, 0U);
}

// ---- mb ---------------------------------------------------------------------------------------

void ReplayMbTrain(const json& steps, std::int64_t tick_ms, std::size_t train) {
  const Line line;
  OnboardConfig c = Config(line);
  Rig rig(c);
  rig.Step();
  rig.Answer(messages::KeepAlive{});
  rig.Step();
  const std::int64_t t0 = rig.Now() + kOnboardCycleMs;
  std::int64_t clock = 0;
  for (std::size_t k = 0; k < steps.size();) {
    const json& in = steps[k].at("in");
    const std::string ev = in.at("ev").get<std::string>();
    if (ev == "tick") {
      clock += tick_ms;
      while (rig.Now() < t0 + clock) {
        rig.Step();
        if (rig.Unit().Outputs().sent) {
          rig.Answer(messages::KeepAlive{});
        }
      }
      SCOPED_TRACE("step " + std::to_string(k) + " (tick)");
      const json& expected = steps[k].at("out").at("trains")[train];
      EXPECT_EQ(rig.Unit().Outputs().authority_usable, expected.at("authority_usable").get<bool>());
      ++k;
      continue;
    }
    if (ev != "deliver" || in.at("train").get<std::size_t>() != train) {
      ++k;
      continue;
    }
    // this train's deliveries of this instant, in one cycle: issued `age` before it
    std::vector<std::size_t> group;
    std::vector<messages::Message> sent;
    for (; k < steps.size(); ++k) {
      const json& d = steps[k].at("in");
      if (d.at("ev").get<std::string>() == "tick") {
        break;
      }
      if (d.at("ev").get<std::string>() == "deliver" && d.at("train").get<std::size_t>() == train) {
        group.push_back(k);
        const std::int64_t at = rig.Now() + kOnboardCycleMs;
        sent.emplace_back(StopLimit(d.at("limit_mm").get<std::int64_t>(), at - d.at("age_ms").get<std::int64_t>()));
      }
    }
    for (const messages::Message& m : sent) {
      rig.Answer(m);
    }
    const OnboardOutputs& out = rig.Step();
    const auto events = out.Events();
    ASSERT_EQ(events.size(), group.size());
    std::optional<std::int64_t> limit = rig.Unit().Outputs().authority_limit_mm;
    for (std::size_t g = 0; g < group.size(); ++g) {
      SCOPED_TRACE("step " + std::to_string(group[g]) + " (deliver)");
      const json& expected = steps[group[g]].at("out");
      EXPECT_EQ(events[g].frame, g);
      EXPECT_STREQ(mb::onboard::ToString(events[g].verdict), expected.at("verdict").get<std::string>().c_str());
      if (g + 1 == group.size()) {
        EXPECT_EQ(limit, expected.at("limit_mm").is_null() ? std::nullopt
                                                            : std::optional(expected.at("limit_mm").get<std::int64_t>()));
      }
    }
  }
}

TEST(OnboardReplay, MovingBlockOnboardVectors) {
  const Loaded l = Load("mb", rc::MbVectorKeys());
  for (const auto& [file, v] : l.vectors) {
    SCOPED_TRACE(file + ": " + v.at("id").get<std::string>());
    const json& h = l.headers.at(file);
    const std::int64_t tick_ms = h.at("unit_scales").at("time_ms_per_tick").get<std::int64_t>();
    const std::size_t trains = h.at("parameters").at("initial_front_mm").size();
    for (std::size_t t = 0; t < trains; ++t) {
      SCOPED_TRACE("train " + std::to_string(t));
      ReplayMbTrain(v.at("steps"), tick_ms, t);
    }
  }
}

// ---- ra ---------------------------------------------------------------------------------------

bool StandstillWithoutDeviation(const json& steps) {
  return std::all_of(steps.begin(), steps.end(), [](const json& s) {
    const json& in = s.at("in");
    return !in.at("deviation").get<bool>() && !in.at("tg_moving").get<bool>() && !in.at("speed_agrees")[0].get<bool>() &&
           !in.at("speed_agrees")[1].get<bool>();
  });
}

TEST(OnboardReplay, OdometryVectorsAtStandstill) {
  const Loaded l = Load("ra", rc::RaVectorKeys());
  std::size_t replayed = 0;
  for (const auto& [file, v] : l.vectors) {
    const json& steps = v.at("steps");
    if (!StandstillWithoutDeviation(steps)) {
      continue;
    }
    SCOPED_TRACE(file + ": " + v.at("id").get<std::string>());
    const std::int64_t model_warmup = l.headers.at(file).at("parameters").at("warmup_cycles").get<std::int64_t>();
    ASSERT_EQ(ra::test::kWarmupCycles % model_warmup, 0);
    const int scale = static_cast<int>(ra::test::kWarmupCycles / model_warmup);
    const Line line;
    Rig rig(Config(line));
    for (std::size_t k = 0; k < steps.size(); ++k) {
      const json& in = steps[k].at("in");
      const json& out = steps[k].at("out");
      rig.imu_fault = !in.at("imu_ok").get<bool>();
      rig.tg_fault = !in.at("tg_ok").get<bool>();
      for (int s = 0; s < scale; ++s) {
        if (s + 1 == scale && in.at("balise").get<bool>()) {
          rig.Balise(7);
        }
        rig.Step();
        if (rig.Unit().Outputs().sent) {
          rig.Answer(messages::KeepAlive{});
        }
      }
      SCOPED_TRACE("step " + std::to_string(k));
      const OnboardOutputs& o = rig.Unit().Outputs();
      ASSERT_EQ(o.link, tg::LinkState::kUp);
      EXPECT_EQ(o.position_valid, out.at("position_valid").get<bool>());
      EXPECT_EQ(o.reason == BrakeReason::kOdometryStop, out.at("stop_demand").get<bool>()) << ToString(o.reason);
    }
    ++replayed;
  }
  EXPECT_GT(replayed, 0U);
}

}  // namespace
}  // namespace railproof::units::test
