// The lc vectors of the on-board variant replayed through the on-board unit's external
// interface, as far as it reaches: sensor samples and telegram bytes in, the unit's
// telegrams and indications out (the wayside side of the same vectors:
// test_wayside_vectors.cpp). The vectors give the train's front and speed with no envelope
// error, where the unit takes them from its odometry; so the unit is driven by the rig's
// sensor stream with a train whose front and speed at every tick are the vector's:
//   - the train stands for the odometry's warm-up at the vector's first front (each vector
//     starts at standstill), then runs each tick at the constant acceleration that takes it
//     from one tick's speed to the next's (the IMU measuring it); the vector's fronts are
//     exactly those of such a run (checked: a vector whose fronts are not is counted apart);
//   - the train's speed measurement is taken as exact (no speed allowance in the train data),
//     as the model's is; the envelope's error is the odometry's own;
//   - the model's time 0 is a tick of the unit's cycle aligned with its supervision, after
//     the warm-up and a stop limit at the line's end (the crossing protection limit governs
//     the indications whenever it exists); dwelling at the station is the dwell input.
// Per tick: the ground's telegram of that cycle carries a fresh stop limit and the vector's
// crossing reports and withdrawal acknowledgements (times in the unit's clock); out: the
// crossing protection limit in the indications of that cycle, and the requests and
// withdrawals of that cycle's protection as decoded from the unit's next telegram (the unit
// sends the crossing messages decided in a cycle with its next telegram; the radio period is
// aligned to send one right after every tick).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <variant>
#include <vector>

#include "../lc_vectors.hpp"
#include "onboard_rig.hpp"

namespace railproof::units::test {
namespace {

namespace rc = railproof::conformance;
using json = nlohmann::json;

std::int64_t I(const json& o, const char* k) { return o.at(k).get<std::int64_t>(); }

// The acceleration (mm/s^2, exact) of every interval between ticks, if the vector's train is a
// standing start followed by constant accelerations between its ticks; empty otherwise.
std::optional<std::vector<double>> Accelerations(const json& steps) {
  if (I(steps.at(0).at("train"), "speed_mm_s") != 0) {
    return std::nullopt;  // the odometry warms up at standstill
  }
  std::vector<double> a;
  for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
    const json& x = steps[k].at("train");
    const json& y = steps[k + 1].at("train");
    const std::int64_t dt = I(steps[k + 1], "t_ms") - I(steps[k], "t_ms");
    const std::int64_t v0 = I(x, "speed_mm_s");
    const std::int64_t v1 = I(y, "speed_mm_s");
    if (dt <= 0 || 2'000 * (I(y, "front_mm") - I(x, "front_mm")) != (v0 + v1) * dt) {
      return std::nullopt;
    }
    a.push_back(static_cast<double>(v1 - v0) * 1'000.0 / static_cast<double>(dt));
  }
  return a;
}

// The line of the vectors' file: 100 m blocks to the end of its permitted speeds, level, a
// balise at the train's first front.
Line LcLine(const LcFile& f, std::int64_t front_mm) {
  Line line;
  line.blocks.clear();
  for (std::int64_t b = 0; b <= f.restrictions.back().end_mm; b += 100'000) {
    line.blocks.push_back(b);
  }
  line.gradients.clear();
  line.limits = f.restrictions;
  line.balises = {{7, front_mm}};
  line.crossings = f.crossings;
  return line;
}

std::set<std::uint32_t> IdSet(const json& a) {
  std::set<std::uint32_t> s;
  for (const json& x : a) {
    s.insert(x.get<std::uint32_t>());
  }
  return s;
}

// The crossing protection's outputs at a tick, the model's or the unit's.
struct Protection {
  std::optional<std::int64_t> limit_mm;
  std::set<std::uint32_t> requests;
  std::set<std::uint32_t> withdrawals;
  [[nodiscard]] std::string Text() const {
    return "limit " + rc::OptInt(limit_mm) + " requests " + lc::conformance::Ids(requests) +
           " withdrawals " + lc::conformance::Ids(withdrawals);
  }
  bool operator==(const Protection&) const = default;
};

// A difference at a decision boundary that the envelope decides on the safe side: the unit's
// limit is no farther, it requests every crossing the model requests (a late passage keeps a
// request, an early arrival makes one) and withdraws none the model keeps.
bool SafeSide(const Protection& unit, const Protection& model) {
  const bool limit_ok = unit.limit_mm.has_value() && (!model.limit_mm || *unit.limit_mm <= *model.limit_mm);
  return (limit_ok || unit.limit_mm == model.limit_mm) &&
         std::includes(unit.requests.begin(), unit.requests.end(), model.requests.begin(), model.requests.end()) &&
         std::includes(model.withdrawals.begin(), model.withdrawals.end(), unit.withdrawals.begin(),
                       unit.withdrawals.end());
}

// A vector's report in the unit's clock: an open crossing has no warning start (0), every
// other time is shifted.
messages::CrossingReport ReportOf(const json& r, std::int64_t shift_ms) {
  messages::CrossingReport rep = lc::conformance::ReportOf(r);
  rep.warning_start_ms = rep.status == messages::CrossingStatus::kOpen ? 0 : rep.warning_start_ms + shift_ms;
  rep.issued_ms += shift_ms;
  return rep;
}

// Replays one vector: its problems, or where the unit's envelope took the safe side of a
// decision boundary the model's exact front sits on (`diverged`, the replay stops there).
void ReplayLcOnboard(const LcFile& f, const json& steps, const std::vector<double>& accel,
                     std::vector<std::string>& problems, std::string& diverged) {
  const std::int64_t front0 = I(steps.at(0).at("train"), "front_mm");
  const Line line = LcLine(f, front0);
  OnboardConfig c = Config(line);
  c.train_id = f.train_id;
  c.train.length_mm = f.train_length_mm;
  c.train.accel_max_mm_s2 = f.accel_max_mm_s2;
  c.train.speed_error_ppm = 0;
  c.train.speed_error_abs_mm_s = 0;
  c.initial_front_mm = front0;
  c.crossing = f.protection;
  c.radio_offset_ms = kOnboardCycleMs;  // a telegram one cycle after every tick (below)
  const std::int64_t ma_mm = line.blocks.back();
  Rig rig(c, 0);
  // Model time t is the unit's shift + t: the first cycle (100 ms) starts the supervision and,
  // with the offset, the telegrams (every 1000 ms from 200 ms), so a shift of 100 + n * 1000
  // puts every tick on a supervision cycle and a telegram right after it; 10.1 s leaves the
  // warm-up and the link's start before the first tick.
  const std::int64_t shift = 10'100 - I(steps.at(0), "t_ms");
  const auto dwell_of = [&](const json& train) {
    return train.at("dwell").get<bool>() ? std::optional<std::int64_t>(I(train, "departure_ms") + shift) : std::nullopt;
  };
  const auto answer = [&](std::int64_t issue_ms) { rig.Answer(StopLimit(ma_mm, issue_ms, {}, f.train_id)); };
  // standing as the model's train stood at its first tick: the odometry's warm-up, then the
  // link and the stop limit
  rig.dwell_departure_ms = dwell_of(steps.at(0).at("train"));
  for (int k = 0; k < ra::test::kWarmupCycles + 1; ++k) {
    rig.Step();
  }
  for (int k = 0; k < 3; ++k) {
    rig.StepToSend();
    answer(rig.Now() + kOnboardCycleMs);
  }
  ra::test::ImuValues imu;
  double a = 0;
  for (std::size_t k = 0; k < steps.size() && problems.empty(); ++k) {
    const json& step = steps[k];
    const std::int64_t tick = I(step, "t_ms") + shift;
    // the cycles up to the tick's: the stop limit renewed at every telegram of the unit
    while (rig.Now() + kOnboardCycleMs < tick) {
      if (rig.Step({a, 0.0}, imu).sent) {
        answer(rig.Now() + kOnboardCycleMs);
      }
    }
    rig.dwell_departure_ms = dwell_of(step.at("train"));
    const json& in = step.at("onboard").at("in");
    std::vector<messages::Message> ground{StopLimit(ma_mm, tick, {}, f.train_id)};
    for (const json& r : in.at("reports")) {
      ground.emplace_back(ReportOf(r, shift));
    }
    for (const json& x : in.at("acks")) {
      ground.emplace_back(
          messages::WithdrawalAck{x.at("crossing_id").get<std::uint32_t>(), x.at("train_id").get<std::uint32_t>()});
    }
    // as many telegrams of the tick as the messages need
    const std::span<const messages::Message> all(ground);
    for (std::size_t m = 0; m < ground.size();) {
      std::size_t n = 1;
      while (m + n < ground.size() && n < messages::kBundleMax &&
             messages::BundleSize(all.subspan(m, n + 1)) <= messages::kPayloadCapacity) {
        ++n;
      }
      rig.Deliver(rig.Ground().Send(tick, all.subspan(m, n)));
      m += n;
    }
    const OnboardOutputs& out = rig.Step({a, 0.0}, imu);
    rc::Checker chk(problems, "step " + std::to_string(k) + " (t=" + std::to_string(tick - shift) + " ms): ");
    chk.Expect("cycle time", std::to_string(tick), std::to_string(out.now_ms));
    const json& e = step.at("onboard").at("out");
    // the envelope holds the model's front (the nominal front counts whole TG pulses)
    const std::int64_t front = I(step.at("train"), "front_mm");
    if (!out.position_valid || front < out.front_mm - out.rear_error_mm || front > out.front_mm + out.front_error_mm) {
      chk.Fail("the envelope " + std::to_string(out.front_mm) + " -" + std::to_string(out.rear_error_mm) + " +" +
               std::to_string(out.front_error_mm) + " does not hold the front " + std::to_string(front));
    }
    const Indications& ind = out.indications;
    Protection unit{ind.limit_kind == LimitKind::kCrossingProtection ? ind.limit_mm : std::nullopt, {}, {}};
    // the next interval's acceleration, and its first cycle: the telegram of this tick's
    // crossing messages
    a = k < accel.size() ? accel[k] / 1'000.0 : 0.0;
    imu = ra::test::ImuValues{};
    imu.ax = a;
    const OnboardOutputs& next = rig.Step({a, 0.0}, imu);
    if (!next.sent) {
      chk.Fail("no telegram one cycle after the tick");
      break;
    }
    answer(rig.Now() + kOnboardCycleMs);
    for (const messages::Message& m : rig.Heard()) {
      if (const auto* q = std::get_if<messages::CrossingRequest>(&m)) {
        unit.requests.insert(q->crossing_id);
      }
      if (const auto* w = std::get_if<messages::CrossingWithdrawal>(&m)) {
        unit.withdrawals.insert(w->request.crossing_id);
      }
    }
    const Protection model{e.at("stop_limit_mm").is_null() ? std::nullopt
                                                           : std::optional(e.at("stop_limit_mm").get<std::int64_t>()),
                           IdSet(e.at("requests")), IdSet(e.at("withdrawals"))};
    if (unit == model) {
      continue;
    }
    if (!SafeSide(unit, model)) {
      chk.Fail("expected " + model.Text() + ", got " + unit.Text());
    } else if (problems.empty()) {
      // from here the two runs follow different histories: the vector ends here
      diverged = "step " + std::to_string(k) + ": " + model.Text() + " / unit " + unit.Text();
    }
    return;
  }
}

TEST(OnboardReplay, CrossingVectorsOfTheOnboardVariant) {
  const LcVectors& set = LcVectorSet();
  ASSERT_EQ(set.error, "");
  std::size_t matched = 0;
  std::size_t safe_side = 0;
  std::size_t not_drivable = 0;
  std::size_t failed = 0;
  for (const rc::JsonVector& v : set.vectors) {
    const LcFile& f = set.files.at(v.file);
    if (f.gnss) {
      continue;  // the centre and the controllers: wayside only (test_wayside_vectors.cpp)
    }
    const auto accel = Accelerations(v.steps);
    if (!accel) {
      ++not_drivable;
      continue;
    }
    std::vector<std::string> problems;
    std::string diverged;
    ReplayLcOnboard(f, v.steps, *accel, problems, diverged);
    if (!problems.empty()) {
      ++failed;
      ADD_FAILURE() << v.file << " " << v.id << ": " << problems.front();
    } else if (!diverged.empty()) {
      ++safe_side;
    } else {
      ++matched;
    }
  }
  EXPECT_EQ(failed, 0U);
  EXPECT_EQ(not_drivable, 0U);  // every vector is a standing start with constant accelerations
  // the envelope decides only at the boundaries: most vectors match throughout
  EXPECT_GT(matched, 2 * safe_side);
  RecordProperty("matched", std::to_string(matched));
  RecordProperty("safe_side", std::to_string(safe_side));
}

}  // namespace
}  // namespace railproof::units::test
