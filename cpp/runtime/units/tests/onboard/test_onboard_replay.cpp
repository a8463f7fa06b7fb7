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
//   ra  the vectors without a detection (53 of 150): a model cycle is 20 sensor cycles (the
//       odometry's warm-up over the model's, 40 / 2) while the history is not trusted and one
//       while it is, because the machine then reads only TG motion (the warm-up count) or only
//       a deviation (a count of consecutive cycles, 3 in the model and in the odometry); what a
//       step's state does not read is made false. TG motion: the train creeps over one pulse
//       edge in the last cycle; a deviation at standstill: the IMU's longitudinal reading sets
//       the 3 s average of a_x to 0.5 m/s^2 (checked), above Ta plus the TG resolution (0.37).
//       The IMU or TG fails throughout a step, a balise is read in its last cycle. Out: position
//       validity, the odometry's stop demand as the brake reason, its mode and stop reason.
//       Not replayed: the 97 that detect. The counts there stay 1:1 (3 deviations to detect,
//       3 agreeing cycles to adopt) while the times do not scale alike: the start ages 2 or 4
//       cycles against the odometry's 25..75 (lookback 2.5 s plus a 5 s search), the spacing
//       2 against 25, the compensation limits 3 or 9 against 30..320 cycles. Each compensation
//       cycle would need its own stretch, so that each candidate times out in the model's
//       cycle, with every cycle of an agreement run one sensor cycle, and the stream would have
//       to make each candidate's agreement (|v_TG - v_c| <= 0.056 m/s^2 * t_c, + 0.03 m/s below
//       1.4 m/s) per sensor cycle, the deviation false where both agree: a per-vector search
//       over wheel-slip and IMU streams, not written. The ra runner replays them module by
//       module.
//   br  every vector of br.unit.jsonl (73, the variant REALISABLE of models/br.pml: the
//       relations between v_s and the pattern speeds the unit's calculator can give), and the
//       vectors of br.jsonl whose every step has a concrete state (41 of 74, 10 of them with a
//       speed restriction): a step's abstract speeds count only as the set of pattern speeds v_s
//       exceeds (the decision compares nothing else; the model's equalities and "one above"
//       are not kept). The rig's train stands or runs at 5 m/s; each supervision's stop limit
//       and one restriction, answered to the telegram before it, are chosen with the braking
//       module's pattern calculator on the profile the unit merges: a restriction under the
//       train whose ceiling is released between two lead points makes the nearer service
//       points exceeded (its speed also sets v_e's), the stop limit the farther ones (checked
//       after the cycle with the unit's own envelope, profile and speed). The next telegram
//       withdraws the restriction. Starts and stops between a standing and a running step take
//       supervisions of their own, which change nothing the next step reads. Out: the level,
//       "pattern approaching" and the brake demand. The other 33 of br.jsonl ask for what real
//       pattern speeds never give (the default configuration draws each independently; the
//       variant excludes exactly these), shown on the pattern
//       calculator in br/tests/test_patterns.cpp: 11 v_e below v_7n
//       (EmergencyNeverBelowService), 22 a run of exceeded points with one not exceeded on
//       either side among x_s and the 6N, 5N, 4N and release leads, which at 5 m/s lie within
//       one train length (NoExceededRunBetweenLeadsWithinTheCeilingExtension).
//   lc  test_onboard_crossing_replay.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "br/conformance/vector_keys.hpp"
#include "br/conformance/vector_steps.hpp"
#include "mb/conformance/vector_keys.hpp"
#include "onboard_rig.hpp"
#include "replay_vectors.hpp"
#include "ra/conformance/vector_keys.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "railproof/testing/jsonl_vectors.hpp"
#include "railproof/units/onboard_profile.hpp"
#include "tg/conformance/vector_reader.hpp"
#include "../tg_vectors.hpp"

namespace railproof::units::test {
namespace {

using json = nlohmann::json;
namespace rc = railproof::conformance;

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

// A vector the replay cannot map: the odometry detects a slip (detection, compensation).
bool Detects(const json& steps) {
  return std::any_of(steps.begin(), steps.end(), [](const json& s) {
    const json& out = s.at("out");
    return out.at("detected").get<bool>() || out.at("mode").get<std::string>() == "COMPENSATING";
  });
}

// The unit fed for the ra vectors: the train stands but for creeps over one TG pulse edge, and
// the IMU's longitudinal reading sets the odometry's 3 s average of a_x (the IMU values of the
// accepted cycles since its history last restarted, design note §3).
class OdometryDrive {
 public:
  explicit OdometryDrive(const OnboardConfig& c) : rig_(c) {}
  Rig& rig() { return rig_; }

  // One cycle standing, the average of a_x set to `average` (m/s^2).
  const OnboardOutputs& Stand(double average) {
    const std::size_t n = std::min<std::size_t>(ax_.size(), kAverageCycles - 1);
    double a = average * static_cast<double>(n + 1);
    for (std::size_t j = ax_.size() - n; j < ax_.size(); ++j) {
      a -= ax_[j];
    }
    return Cycle(0.0, a);
  }
  // Two cycles from rest to rest, over the next pulse edge in the second only (the IMU
  // measuring the motion): TG motion in that cycle and not in the first.
  void CreepFirst() {
    pulses_ = rig_.Sensors().pulses();
    const double edge_m = static_cast<double>(pulses_ + 1) * ra::test::kPulseUm * 1e-6;
    creep_ = (edge_m - rig_.Sensors().x()) / 0.0075;  // 2/3 of the way in the first cycle
    Cycle(creep_, creep_);
    EXPECT_EQ(rig_.Sensors().pulses(), pulses_);
  }
  const OnboardOutputs& CreepSecond() {
    const OnboardOutputs& o = Cycle(-creep_, -creep_);
    EXPECT_EQ(rig_.Sensors().pulses(), pulses_ + 1);
    return o;
  }

 private:
  static constexpr std::size_t kAverageCycles =
      static_cast<std::size_t>(params::ra::moving_average_ms / params::ra::cycle_ms);

  const OnboardOutputs& Cycle(double accel, double imu_ax) {
    ra::test::ImuValues imu;
    imu.ax = imu_ax;
    const OnboardOutputs& o = rig_.Step({accel, 0.0}, imu);
    if (o.sent) {
      rig_.Answer(messages::KeepAlive{});
    }
    if (o.sensor_error == ra::InputError::kNone) {
      ax_.push_back(imu_ax);
    } else {
      ax_.clear();  // the odometry's history restarts with the next accepted cycle
    }
    return o;
  }

  Rig rig_;
  std::vector<double> ax_;
  double creep_ = 0;
  std::int64_t pulses_ = 0;
};

// One vector. The machine reads of a step's predicates only what its state lets it read
// (readhesion_machine.cpp): TG motion while the history is not trusted (the warm-up), a
// deviation while it is (TG odometry, or stopped and trusted); speed agreement and start ages
// only while detecting or compensating, which these vectors never do. So a model cycle is
// `scale` sensor cycles (the odometry's warm-up over the model's) while the history is not
// trusted, and one while it is: the deviation count is of consecutive cycles, 3 in the model
// and in the odometry. An unread predicate is made false. TG motion: a creep over a pulse edge
// in the last cycle. A deviation at standstill: the 3 s average of a_x at 0.5 m/s^2, above
// Ta plus the TG resolution (0.34 + 0.03), else 0 (a_p is 0 at standstill). The IMU or TG
// fails throughout the step, a balise is read in its last cycle. Out: position validity, the
// odometry's stop demand as the brake reason, its mode and stop reason.
void ReplayRa(const json& steps, int scale, std::vector<std::string>& problems) {
  const Line line;
  OdometryDrive drive(Config(line));
  Rig& rig = drive.rig();
  bool trusted = false;  // the model's, before the step
  for (std::size_t k = 0; k < steps.size() && problems.empty(); ++k) {
    const json& in = steps[k].at("in");
    const json& out = steps[k].at("out");
    rig.imu_fault = !in.at("imu_ok").get<bool>();
    rig.tg_fault = !in.at("tg_ok").get<bool>();
    const bool creep = !trusted && in.at("tg_moving").get<bool>() && !rig.imu_fault && !rig.tg_fault;
    const double average = trusted && in.at("deviation").get<bool>() ? 0.5 : 0.0;
    const int cycles = trusted ? 1 : scale;
    for (int s = 0; s < cycles; ++s) {
      if (s + 1 == cycles && in.at("balise").get<bool>()) {
        rig.Balise(7);
      }
      if (creep && s + 2 == cycles) {
        drive.CreepFirst();
      } else if (creep && s + 1 == cycles) {
        drive.CreepSecond();
      } else {
        drive.Stand(average);
      }
    }
    rc::Checker chk(problems, "step " + std::to_string(k) + ": ", &in);
    const OnboardOutputs& o = rig.Unit().Outputs();
    const ra::OdometryOutput& od = rig.Unit().Odometry();
    // the stream made the comparison the step reads (a_p is 0: no pulse for the last 3 s)
    if (trusted && !rig.imu_fault && !rig.tg_fault && std::fabs(od.ax_avg - od.ap_avg - average) > 1e-6) {
      chk.Fail("the stream missed the deviation's comparison: a_x " + std::to_string(od.ax_avg) + ", a_p " +
               std::to_string(od.ap_avg));
    }
    chk.Expect("link", ToString(tg::LinkState::kUp), ToString(o.link));
    chk.Expect("position_valid", rc::Bool(out.at("position_valid").get<bool>()), rc::Bool(o.position_valid));
    chk.Expect("stop_demand (" + std::string(ToString(o.reason)) + ")", rc::Bool(out.at("stop_demand").get<bool>()),
               rc::Bool(o.reason == BrakeReason::kOdometryStop));
    chk.Expect("mode", out.at("mode").get<std::string>(), ra::ToString(od.mode));
    chk.Expect("stop_reason", out.at("stop_reason").get<std::string>(), ra::ToString(od.stop_reason));
    trusted = out.at("trusted").get<bool>();
  }
}

TEST(OnboardReplay, OdometryVectorsWithoutDetection) {
  const Loaded l = Load("ra", rc::RaVectorKeys());
  std::size_t replayed = 0;
  std::size_t detecting = 0;
  for (const auto& [file, v] : l.vectors) {
    if (file == "ra.unit.jsonl") {
      continue;  // the unit's environment at its own times: test_onboard_slip_replay.cpp
    }
    const json& steps = v.at("steps");
    if (Detects(steps)) {
      ++detecting;
      continue;
    }
    SCOPED_TRACE(file + ": " + v.at("id").get<std::string>());
    const std::int64_t model_warmup = l.headers.at(file).at("parameters").at("warmup_cycles").get<std::int64_t>();
    ASSERT_EQ(ra::test::kWarmupCycles % model_warmup, 0);
    std::vector<std::string> problems;
    ReplayRa(steps, static_cast<int>(ra::test::kWarmupCycles / model_warmup), problems);
    for (const std::string& p : problems) {
      ADD_FAILURE() << p;
    }
    ++replayed;
  }
  EXPECT_EQ(replayed, 53U);
  EXPECT_EQ(detecting, 97U);
  RecordProperty("replayed", std::to_string(replayed));
}

// ---- br ---------------------------------------------------------------------------------------

// What the unit's real pattern speeds can give (shown on the pattern calculator in the br tests):
//   - v_e >= v_7n at the supervised front (BrakingPatternsProperty.EmergencyNeverBelowService);
//   - of the service pattern's five points, x_s (7N) and the 6N, 5N, 4N and release leads, the
//     ones v_s exceeds form a prefix and a suffix: a restriction's ceiling is released where the
//     rear, extended by both errors, leaves it (REQ-BR-004), which between two lead points
//     makes the nearer one exceeded and the farther one not; the stop limit (or a restriction
//     ahead) makes the farther points exceeded. A run of exceeded points with one not exceeded
//     on either side would need a ceiling shorter than the train: at the rig's speed the five
//     points lie within one train length, and no such run exists there
//     (BrakingPatternsProperty.NoExceededRunBetweenLeadsWithinTheCeilingExtension).
// A step asking for another set has no concrete state.
enum class BrGap { kNone, kEmergencyBelowService, kRunBetweenLeads };

// A step's exceeded set as the rig realises it: the service points exceeded from x_s on
// (`prefix`, by a restriction under the train) and back from the release lead (`suffix`, by the
// stop limit), and v_e (by the restriction's speed with a prefix, else by the stop limit with
// every service point exceeded); or its gap.
struct BrShape {
  bool emergency = false;
  int prefix = 0;
  int suffix = 0;
  BrGap gap = BrGap::kNone;
};

BrShape ShapeOf(const rc::BrExceeded& e) {
  constexpr int kPoints = 5;  // v_7n, v_6n, v_5n, v_4n, v_release
  const auto service = [&](int i) { return e[static_cast<std::size_t>(i) + 1]; };
  BrShape s;
  s.emergency = e[0];
  while (s.suffix < kPoints && service(kPoints - 1 - s.suffix)) {
    ++s.suffix;
  }
  while (s.suffix < kPoints && service(s.prefix)) {
    ++s.prefix;
  }
  if (s.emergency && !service(0)) {
    s.gap = BrGap::kEmergencyBelowService;
  } else if (s.prefix + s.suffix != static_cast<int>(std::count(e.begin() + 1, e.end(), true))) {
    s.gap = BrGap::kRunBetweenLeads;
  }
  return s;
}

// The step reads the level applied before it: v_s above v_release alone (the hold rule).
bool ReadsTheLevelBefore(const rc::BrExceeded& e) {
  return e == rc::BrExceeded{false, false, false, false, false, true};
}

BrakeDemand DemandOf(const std::string& level) {
  return level == "NONE" ? BrakeDemand::kNone : level == "EB" ? BrakeDemand::kEmergency : BrakeDemand::kService;
}

// The lowest x in [lo, hi] with pred(x), for pred false then true over the range and true at hi.
template <class Pred>
std::int64_t Lowest(std::int64_t lo, std::int64_t hi, Pred pred) {
  if (pred(lo)) {
    return lo;
  }
  while (hi - lo > 1) {
    const std::int64_t mid = lo + (hi - lo) / 2;
    (pred(mid) ? hi : lo) = mid;
  }
  return hi;
}

// The rig's train for the br vectors: it stands, or runs at kBrCruise (the TG speed then timed
// over 100 pulses, steady to a mm/s), and the ground answers every telegram of the unit with a
// stop limit and one restriction, kBrRestrictionId: the step's, or one wholly behind the train,
// which withdraws the last (the store would keep a restriction the ground no longer sends while
// the train is inside it) and is dropped on receipt. The radio period is the supervision
// cycle, each telegram sent in the cycle before a supervision, so the limit and restriction
// answered to a telegram are the ones supervised next.
constexpr double kBrCruise = 5.0;             // m/s
constexpr double kBrAccel = 1.0;              // m/s^2, the IMU measuring it (no slip detected)
constexpr int kBrSettleCycles = 10;           // at the cruising speed: the TG window holds it only
constexpr std::int64_t kBrFarMm = 2'000'000;  // a limit this far ahead: every pattern above v_s
constexpr std::uint32_t kBrRestrictionId = 1;
constexpr std::int64_t kBrRestrictionMm = 1'000;  // its length: it ends under the train

class BrakingDrive {
 public:
  BrakingDrive(const Line& line, const OnboardConfig& c)
      : rig_(c), gradients_(line.gradients), limits_(line.limits) {
    rig_.Start(ra::test::kInitialFrontMm + kBrFarMm);
    auto created = br::PatternCalculator::Create(c.train, c.supervision);
    EXPECT_EQ(created.error, br::CreateError::kNone);
    patterns_.emplace(std::move(*created.calculator));
    Restrict(std::nullopt);
    prev_ = Envelope();
  }

  // Cycles until the train stands (the odometry's standstill) or runs settled at kBrCruise,
  // then to the cycle that sends the telegram before a supervision. Returns the supervisions
  // this took, each with the limit far ahead, no restriction and no reset.
  int Prepare(bool standing) {
    int supervisions = 0;
    for (int n = 0; n < 1'000; ++n) {
      const double v = rig_.Sensors().speed();
      const double gap = standing ? -v : kBrCruise - v;
      const double a = std::fabs(gap) < 1e-9 ? 0.0 : std::clamp(gap / 0.1, -kBrAccel, kBrAccel);
      settled_ = a == 0.0 && !standing ? settled_ + 1 : 0;
      const bool there = standing ? rig_.Unit().Odometry().standstill : settled_ > kBrSettleCycles;
      if (Cycle(a).sent) {
        if (there) {
          return supervisions;
        }
        Restrict(std::nullopt);
        Answer(Next().front_mm + kBrFarMm);
        ++supervisions;
      }
    }
    ADD_FAILURE() << "the train did not " << (standing ? "stop" : "reach its cruising speed");
    return supervisions;
  }

  // The restriction and stop limit of a step's shape at the next cycle's envelope and speed
  // (extrapolated from the last two cycles); none if the search finds none.
  std::optional<std::int64_t> Concretise(const BrShape& s) {
    Restrict(std::nullopt);
    if (s.prefix > 0 && !RestrictPrefix(s.prefix, s.emergency)) {
      return std::nullopt;
    }
    if (s.suffix == 0) {
      return Next().front_mm + kBrFarMm;
    }
    return LimitFor(static_cast<int>(s.emergency) + s.prefix + s.suffix);
  }

  // The supervision of a step: the limit and restriction answered to the telegram just sent,
  // the driver's handle and reset in that cycle.
  const OnboardOutputs& Supervise(std::int64_t limit, const br::DriverInputs& d) {
    Answer(limit);
    rig_.Drive(br::DriverInputs{.standstill = false, .handle_emergency = d.handle_emergency, .reset = d.reset});
    const OnboardOutputs& out = Cycle(0.0);
    rig_.Drive({});
    return out;
  }

  // Which pattern speeds v_s exceeded in the unit's last cycle with this limit and the unit's
  // own profile (the concrete state checked against the step's, not the decision).
  [[nodiscard]] rc::BrExceeded Realised(std::int64_t limit) {
    EXPECT_EQ(patterns_->SetProfile(gradients_, rig_.Unit().Profile()).verdict, br::ProfileVerdict::kAccept);
    return rc::BrExceededOf(patterns_->Evaluate(Envelope(), limit).speeds);
  }
  [[nodiscard]] const ra::OdometryOutput& Odometry() const { return rig_.Unit().Odometry(); }

 private:
  // The restriction answered next, and the profile the unit will merge with it.
  void Restrict(std::optional<messages::SpeedRestriction> r) {
    restriction_ = r.value_or(messages::SpeedRestriction{kBrRestrictionId, 0, 1, limits_.front().limit_mm_s});
    const std::span<const messages::SpeedRestriction> held =
        r ? std::span<const messages::SpeedRestriction>(&restriction_, 1) : std::span<const messages::SpeedRestriction>();
    std::vector<core::RestrictionSegment> merged(MergeCapacity(limits_.size(), held.size()));
    std::vector<std::int64_t> scratch(merged.size());
    const MergeResult m = MergeRestrictions(limits_, held, merged, scratch);
    EXPECT_TRUE(m.ok);
    merged.resize(m.count);
    EXPECT_EQ(patterns_->SetProfile(gradients_, merged).verdict, br::ProfileVerdict::kAccept);
  }

  // A restriction under the train whose ceiling ends halfway between the service pattern's
  // points prefix - 1 and prefix, at the middle of the speeds that make v_s exceed v_7n at x_s
  // and v_e exactly if `emergency` (both pattern speeds rise with it). False if none does.
  bool RestrictPrefix(int prefix, bool emergency) {
    const core::PositionEstimate pe = Next();
    const std::int64_t v_s = patterns_->SupervisedSpeed(pe.speed_mm_s, pe.standstill);
    const br::SupervisionParams& p = patterns_->params();
    const std::array<std::int64_t, 5> leads{0, p.lead_6n_ms, p.lead_5n_ms, p.lead_4n_ms, p.release_lead_ms};
    const auto point = [&](int i) {  // as PatternCalculator::Evaluate places them
      return pe.front_mm + pe.front_error_mm + (v_s * leads[static_cast<std::size_t>(i)] + 999) / 1'000;
    };
    const std::int64_t released = point(prefix - 1) + (point(prefix) - point(prefix - 1)) / 2;
    const std::int64_t end = released - patterns_->train().length_mm - pe.front_error_mm - pe.rear_error_mm;
    const auto exceeds = [&](std::size_t pattern) {
      return [&, pattern](std::int64_t speed) {
        Restrict(messages::SpeedRestriction{kBrRestrictionId, end - kBrRestrictionMm, end, speed});
        return !rc::BrExceededOf(patterns_->Evaluate(pe, pe.front_mm + kBrFarMm).speeds)[pattern];
      };
    };
    const std::int64_t top = limits_.front().limit_mm_s;
    const std::int64_t emergency_from = Lowest(1, top, exceeds(0));  // lowest speed v_e stays above v_s
    const std::int64_t service_from = Lowest(1, top, exceeds(1));
    const std::int64_t lo = emergency ? 1 : emergency_from;
    const std::int64_t hi = emergency ? emergency_from : service_from;
    if (lo >= hi) {
      Restrict(std::nullopt);
      return false;
    }
    Restrict(messages::SpeedRestriction{kBrRestrictionId, end - kBrRestrictionMm, end, lo + (hi - lo) / 2});
    return true;
  }

  // The stop limit that makes v_s exceed exactly k pattern speeds, the suffix of the service
  // points among them: the middle of the limits that do, found by bisection (the number
  // exceeded falls as the limit moves ahead); none if none does.
  [[nodiscard]] std::optional<std::int64_t> LimitFor(int k) const {
    const core::PositionEstimate pe = Next();
    const auto exceeded = [&](std::int64_t limit) {
      const rc::BrExceeded e = rc::BrExceededOf(patterns_->Evaluate(pe, limit).speeds);
      return static_cast<int>(std::count(e.begin(), e.end(), true));
    };
    const auto lowest = [&](int n) {  // the lowest limit ahead with at most n exceeded
      return Lowest(pe.front_mm, pe.front_mm + kBrFarMm, [&](std::int64_t limit) { return exceeded(limit) <= n; });
    };
    const std::int64_t from = lowest(k);
    const std::int64_t to = lowest(k - 1);
    const std::int64_t limit = from + (to - from) / 2;
    if (from >= to || exceeded(limit) != k) {
      return std::nullopt;
    }
    return limit;
  }

  void Answer(std::int64_t limit) { rig_.Answer(StopLimit(limit, rig_.Now(), {restriction_})); }
  const OnboardOutputs& Cycle(double a) {
    ra::test::ImuValues imu;
    imu.ax = a;
    prev_ = Envelope();
    return rig_.Step({a, 0.0}, imu);
  }
  [[nodiscard]] core::PositionEstimate Envelope() const { return ra::ToPositionEstimate(rig_.Unit().Odometry()); }
  [[nodiscard]] core::PositionEstimate Next() const {
    core::PositionEstimate n = Envelope();
    n.front_mm += n.front_mm - prev_.front_mm;
    n.front_error_mm = std::max<std::int64_t>(0, 2 * n.front_error_mm - prev_.front_error_mm);
    n.rear_error_mm = std::max<std::int64_t>(0, 2 * n.rear_error_mm - prev_.rear_error_mm);
    return n;
  }

  Rig rig_;
  std::vector<core::GradientSegment> gradients_;
  std::vector<core::RestrictionSegment> limits_;
  std::optional<br::PatternCalculator> patterns_;
  messages::SpeedRestriction restriction_{};
  core::PositionEstimate prev_{};
  int settled_ = 0;
};

// One vector, each step one supervision of the unit. Between a standing step and a running one
// the train starts or stops over supervisions the model does not have (the limit far ahead, no
// restriction, no reset): they keep a latched emergency brake latched and leave the applied
// level NONE, which the next step reads only through the hold rule (v_s above v_release alone);
// that step stands (nothing exceeded) or follows a standing one (level NONE already), so the
// insertion is exact (checked). Out: the supervisor's level, "pattern approaching" and the
// unit's brake demand (emergency exactly while the model's brake is latched, service for
// 4N..7N).
void ReplayBr(const json& steps, std::vector<std::string>& problems) {
  Line line;
  line.crossings.clear();  // the limit far ahead governs, not a crossing's protection
  OnboardConfig c = Config(line);
  c.radio_period_ms = c.supervision.cycle_ms;
  c.radio_offset_ms = kOnboardCycleMs;
  ASSERT_EQ(c.supervision.cycle_ms, 2 * kOnboardCycleMs);
  BrakingDrive drive(line, c);
  std::string before = "NONE";
  for (std::size_t k = 0; k < steps.size() && problems.empty(); ++k) {
    const json& in = steps[k].at("in");
    const json& expected = steps[k].at("out");
    rc::Checker chk(problems, "step " + std::to_string(k) + ": ", &in);
    const br::DriverInputs d = rc::BrDriverInputsOf(in);
    const rc::BrExceeded wanted = rc::BrExceededOf(rc::BrPatternSpeedsOf(in));
    if (drive.Prepare(d.standstill) > 0 && ReadsTheLevelBefore(wanted) && DemandOf(before) == BrakeDemand::kService) {
      chk.Fail("supervisions inserted before a step that reads the level applied before it");
      return;
    }
    const auto limit = drive.Concretise(ShapeOf(wanted));
    if (!limit) {
      chk.Fail("no restriction and stop limit give the step's exceeded set");
      return;
    }
    const OnboardOutputs& o = drive.Supervise(*limit, d);
    // the concrete state is the step's
    chk.Expect("standstill", rc::Bool(d.standstill), rc::Bool(drive.Odometry().standstill));
    chk.Expect("odometry mode", ra::ToString(ra::Mode::kTg), ra::ToString(drive.Odometry().mode));
    chk.Expect("governing limit", std::to_string(*limit), rc::OptInt(o.indications.limit_mm));
    chk.Expect("limit kind", ToString(LimitKind::kMovementAuthority), ToString(o.indications.limit_kind));
    if (drive.Realised(*limit) != wanted) {
      chk.Fail("the concrete speeds missed the step's relations (limit " + std::to_string(*limit) + ")");
    }
    if (!problems.empty()) {
      return;
    }
    // the unit's outputs against the vector's
    const std::string level = expected.at("level").get<std::string>();
    chk.Expect("level", level, br::ToString(o.level));
    chk.Expect("pattern_approaching", rc::Bool(expected.at("pattern_approaching").get<bool>()),
               rc::Bool(o.indications.warning));
    chk.Expect("brake demand (emergency_latched " + rc::Bool(expected.at("emergency_latched").get<bool>()) + ")",
               ToString(expected.at("emergency_latched").get<bool>() ? BrakeDemand::kEmergency : DemandOf(level)),
               ToString(o.brake));
    before = level;
  }
}

TEST(OnboardReplay, BrakingVectorsWithConcretePatterns) {
  const Loaded l = Load("br", rc::BrVectorKeys());
  std::map<std::string, std::size_t> replayed;           // per file
  std::map<std::string, std::size_t> with_restrictions;  // per file
  std::map<BrGap, std::size_t> gaps;                     // br.jsonl only
  for (const auto& [file, v] : l.vectors) {
    const json& steps = v.at("steps");
    const bool unit_set = l.headers.at(file).at("configuration").get<std::string>() == "REALISABLE";
    BrGap gap = BrGap::kNone;
    bool restricted = false;
    for (std::size_t k = 0; k < steps.size() && gap == BrGap::kNone; ++k) {
      const BrShape s = ShapeOf(rc::BrExceededOf(rc::BrPatternSpeedsOf(steps[k].at("in"))));
      gap = s.gap;
      restricted = restricted || s.prefix > 0;
    }
    if (gap != BrGap::kNone) {
      // the unit's environment (models/br.pml, REALISABLE) gives concrete states only
      EXPECT_FALSE(unit_set) << file << ": " << v.at("id").get<std::string>()
                             << ": a step the on-board unit's pattern calculator cannot give";
      ++gaps[gap];
      continue;
    }
    SCOPED_TRACE(file + ": " + v.at("id").get<std::string>());
    std::vector<std::string> problems;
    ReplayBr(steps, problems);
    for (const std::string& p : problems) {
      ADD_FAILURE() << p;
    }
    ++replayed[file];
    with_restrictions[file] += restricted ? 1 : 0;
  }
  // br.jsonl, the model's default configuration (every relation between the speeds): every
  // boundary vector, the trap vectors but G21 (EB with v_s not above v_7n), and 18 of the 50
  // random walks, whose pattern speeds are drawn independently; G22 (7N with v_s not above
  // v_6n) and 9 of those walks with a restriction. Not replayed (a vector counted at its first
  // step without a concrete state): G21 and 10 walks with v_e below v_7n, 22 walks with a run
  // of exceeded points between lead points. They are replayed module by module (the br
  // runner), which the unit's external interface cannot reach.
  EXPECT_EQ(replayed["br.jsonl"], 41U);
  EXPECT_EQ(with_restrictions["br.jsonl"], 10U);
  EXPECT_EQ(gaps[BrGap::kEmergencyBelowService], 11U);
  EXPECT_EQ(gaps[BrGap::kRunBetweenLeads], 22U);
  // br.unit.jsonl, the variant REALISABLE (the unit's environment): every vector, i.e. the 23
  // goals reachable there (all but G21) and 50 random walks.
  const std::size_t unit_vectors = l.headers.at("br.unit.jsonl").at("vector_count").get<std::size_t>();
  EXPECT_EQ(unit_vectors, 73U);
  EXPECT_EQ(replayed["br.unit.jsonl"], unit_vectors);
  EXPECT_EQ(with_restrictions["br.unit.jsonl"], 40U);
  RecordProperty("replayed", std::to_string(replayed["br.jsonl"] + replayed["br.unit.jsonl"]));
  RecordProperty("replayed_unit_set", std::to_string(replayed["br.unit.jsonl"]));
  RecordProperty("with_restrictions_unit_set", std::to_string(with_restrictions["br.unit.jsonl"]));
}

}  // namespace
}  // namespace railproof::units::test
