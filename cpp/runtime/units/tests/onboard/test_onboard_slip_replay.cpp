// The ra vectors of the on-board unit's environment (ra.unit.jsonl: random walks of the variant
// UNIT of models/ra.pml, at the unit's own times) replayed through the unit's sensor interface:
// TG pulse counts with edge times and IMU samples in, one unit cycle per vector step. Each
// step's predicates are made by the stream, not handed to the machine: the test checks that
// the odometry gave its state machine exactly the predicates the step reads (design note §4),
// and that the machine's state, the position validity, the stop demand (the unit's brake
// reason), the detection with its start-point age and the adoption are the step's.
//
// The stream (spec/design/units.md, "ra through the on-board unit"). The train stands; the TG
// counts a pulse only in a cycle whose step has TG motion, read only before the history is
// trusted. The deviation compares the 3 s average of the IMU's a_x with the TG's A_p: each
// cycle's a_x sample sets that average where the step wants it. Outside compensation it
// hovers 0.004 m/s^2 on the step's side of the threshold (Ta plus the TG resolution), so that
// the start-point search's jerk conditions hold in every cycle, but in the cycles between
// the wanted start point and the look-back point, where it alternates 0.03 m/s^2 so that
// they fail: the search finds the step's start-point age (or, for the oldest usable point,
// fails throughout). The IMU's pitch rate turns a_x into gravity for the candidates, so that
// from the second start point on they integrate only what the stream wants: nothing up to
// the primary start point, where the pitch is set to the primary's own (so that both integrate
// one pitch after it), then a small acceleration the TG does not see (a slide), which brings
// their speed at the detection between the two candidates' agreement tolerances. While
// compensating, the a_x sample and the pitch rate together set
// the candidates' speed against the standing TG: inside, between or outside the two
// candidates' agreement tolerances (0.056 m/s^2 x t plus the TG resolution), as the step's
// speed agreement asks, and within the deviation band the step's deviation asks. The margin
// in force is in mm of the unit's error model and is not compared with the model's units.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "onboard_rig.hpp"
#include "ra/conformance/vector_keys.hpp"
#include "railproof/generated/ra_params.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "replay_vectors.hpp"

namespace railproof::units::test {
namespace {

using json = nlohmann::json;
namespace rc = railproof::conformance;
namespace p = params::ra;

constexpr double kDt = static_cast<double>(p::cycle_ms) / 1000.0;
constexpr double kG = static_cast<double>(p::gravity_mm_s2) / 1000.0;
constexpr double kRate = static_cast<double>(p::readhesion_rate_mm_s2) / 1000.0;
constexpr double kLowSpeed = static_cast<double>(p::low_speed_mm_s) / 1000.0;
constexpr std::int64_t kAvgCycles = p::moving_average_ms / p::cycle_ms;
constexpr std::int64_t kLookback = p::lookback_ms / p::cycle_ms;
constexpr std::int64_t kSearch = p::search_depth_ms / p::cycle_ms;
constexpr std::int64_t kSpacing = p::parallel_spacing_ms / p::cycle_ms;
constexpr std::int64_t kUsable = (p::moving_average_ms + p::tg_window_ms) / p::cycle_ms;  // first usable entry
// the stream stays within 95 % of the IMU's ranges the odometry validates
constexpr double kRateLimit = 0.95 * static_cast<double>(p::imu_max_rate_mrad_s) / 1000.0;
constexpr double kSampleLimit = 0.95 * static_cast<double>(p::imu_max_accel_mm_s2) / 1000.0;
// the TG's resolution below low_speed_mm_s: one pulse in the 1 s window (m/s, and m/s^2 over 1 s)
constexpr double kRes = ra::test::kPulseUm * 1e-6;

// The agreement tolerance of a candidate `cycles` old (design note §4).
double Tolerance(std::int64_t cycles, double res) { return kRate * static_cast<double>(cycles) * kDt + res; }

// The variant's times are the unit's (spec/parameters/ra.yaml, model_unit_*).
static_assert(p::model::model_unit_start_age == kLookback);
static_assert(p::model::model_unit_search_extra == kSearch);
static_assert(p::model::model_unit_spacing == kSpacing);
static_assert(p::model::model_unit_warmup == kUsable);
static_assert(p::model::model_unit_tmax_short * p::cycle_ms == p::min_compensation_ms);
static_assert(p::model::model_unit_tmax_long * p::cycle_ms <= p::max_compensation_limit_ms);

constexpr double kEdge = 0.002;      // m/s^2: the compared average's least distance from the threshold
constexpr double kHover = 0.04;      // m/s^2: its widest distance from it before the detection
constexpr double kNear = 0.006;      // m/s^2: its distance from it before the detection, where free
constexpr double kJerkHolds = 0.012; // m/s^2 per cycle: a change that keeps the jerk conditions (0.014)
constexpr double kJerkFails = 0.016; // m/s^2 per cycle: a change that fails them
constexpr double kBand = 0.005;      // m/s^2 inside the deviation band while compensating
constexpr double kSpeedMargin = 0.0005;  // m/s inside or outside an agreement tolerance
constexpr double kMaxA = 6.0;        // m/s^2: the largest compensated acceleration the stream gives

// What a vector asks of the stream around its detection (the variant has at most one).
struct StartPlan {
  std::optional<std::size_t> detection;  // step
  std::int64_t s0 = 0, s1 = 0;           // steps of the two start points
  std::vector<int> jerk;                 // per step: 1 must hold, -1 must fail, 0 either
  double pre_accel = 0;                  // m/s^2 the IMU measures from the primary start point on
};

StartPlan Plan(const json& steps, std::vector<std::string>& problems) {
  StartPlan plan;
  plan.jerk.assign(steps.size(), 0);
  std::int64_t index = 0;  // history index of the step (accepted cycles since the last restart)
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const json& in = steps[k].at("in");
    if (steps[k].at("out").at("detected").get<bool>()) {
      if (plan.detection) {
        problems.push_back("two detections in one vector: outside the variant UNIT");
        return plan;
      }
      plan.detection = k;
      const std::int64_t d = static_cast<std::int64_t>(k);
      const std::int64_t age = in.at("start_age_cycles").get<std::int64_t>();
      const std::int64_t fallback = std::min(kLookback + kSearch, index - kUsable);
      plan.s0 = d - age;
      plan.s1 = d - std::min(age + kSpacing, index - kUsable);  // clamped to the oldest usable entry
      // The train moves while the TG stands (a slide): by the first compensating cycle the
      // candidates' speed lies between their two agreement tolerances, from where each
      // agreement the steps ask is a small change away.
      const double tol0 = Tolerance(age + 1, kRes);
      const double tol1 = Tolerance(d - plan.s1 + 1, kRes);
      if (age >= 1) plan.pre_accel = 0.5 * (tol0 + tol1) / ((static_cast<double>(age) - 0.5) * kDt);
      auto mark = [&](std::int64_t from, std::int64_t to, int v) {
        for (std::int64_t j = std::max<std::int64_t>(from, 0); j <= to; ++j) {
          plan.jerk[static_cast<std::size_t>(j)] = v;
        }
      };
      if (age == fallback) {
        mark(d - std::min(kLookback + kSearch + 2, index - kUsable - 1), d - kLookback, -1);  // the search finds nothing
      } else if (age >= kLookback && age <= std::min(kLookback + kSearch, index - kUsable - 3)) {
        mark(plan.s0 - 2, plan.s0, 1);
        mark(plan.s0 + 1, d - kLookback, -1);
      } else {
        problems.push_back("step " + std::to_string(k) + ": start-point age " + std::to_string(age) +
                           " at history index " + std::to_string(index) + " is none the search can find");
      }
    }
    const bool healthy = in.at("imu_ok").get<bool>() && in.at("tg_ok").get<bool>();
    index = healthy ? index + 1 : 0;
  }
  return plan;
}

// The stream and the unit, with a second odometry fed the same stream (the shadow: its state
// machine is the unit's, which the test shows cycle by cycle, and a copy of it tells the TG's
// A_p of the coming cycle before its IMU samples are chosen).
class SlipReplay {
 public:
  explicit SlipReplay(const Line& line) : cfg_(Config(line)), rig_(cfg_), balise_(line.balises.front()) {
    EXPECT_EQ(ra::Odometry::Create(cfg_.odometry, shadow_), ra::ConfigError::kNone);  // line's sections
    ta_ = static_cast<double>(cfg_.odometry.detect_threshold_mm_s2) / 1000.0;
  }

  void Run(const json& steps, const StartPlan& plan, std::vector<std::string>& problems) {
    for (std::size_t k = 0; k < steps.size() && problems.empty(); ++k) {
      Cycle(k, steps[k], plan, problems);
    }
  }

 private:
  struct Want {
    bool healthy = true;
    std::optional<bool> mv, dev;
    std::array<std::optional<bool>, 2> sa{};
  };

  // The predicates the machine reads in its state before the cycle (readhesion_machine.cpp).
  Want Reads(const json& in) const {
    const ra::MachineState& st = shadow_.machine().state();
    Want w;
    w.healthy = in.at("imu_ok").get<bool>() && in.at("tg_ok").get<bool>();
    if (!w.healthy) return w;
    if (!st.trusted) w.mv = in.at("tg_moving").get<bool>();
    const bool dev_read = st.mode != ra::Mode::kStopped || st.trusted;
    if (dev_read) w.dev = in.at("deviation").get<bool>();
    if (st.mode == ra::Mode::kCompensating && !*w.dev) {
      const std::int32_t tmax = std::min(st.max_compensation_cycles,
                                         in.at("section").at("max_compensation_cycles").get<std::int32_t>());
      for (std::size_t c = 0; c < 2; ++c) {
        const ra::Candidate& k = st.candidates[c];
        if (k.active && k.age_cycles + 1 <= tmax) w.sa[c] = in.at("speed_agrees")[c].get<bool>();
      }
    }
    return w;
  }

  static double Resolution(double v_tg) { return v_tg < kLowSpeed ? kRes : 0.0; }
  double Threshold(double v_tg) const { return ta_ + Resolution(v_tg); }

  // Odometry cycles of candidate c after this cycle (its start point's history index).
  std::int64_t CandidateCycles(std::size_t c) const { return index_ - start_index_[c]; }

  // The coming cycle's sensor data (at the rig's next cycle time).
  ra::CycleInput Sensors(bool imu_ok, bool tg_ok, double ax, double wy) const {
    ra::CycleInput in;
    in.time_ms = rig_.Now() + p::cycle_ms;
    in.tg.time_us = in.time_ms * 1000;
    in.tg.pulses = pulses_;
    in.tg.last_edge_us = edge_us_;
    for (int j = 0; j < ra::kImuSamplesPerCycle; ++j) {
      ra::ImuSample& s = in.imu[static_cast<std::size_t>(j)];
      s = ra::ImuSample{in.time_ms * 1000 - (ra::kImuSamplesPerCycle - 1 - j) * 10'000, ax, 0.0, kG, 0.0, wy, 0.0};
    }
    if (!imu_ok) in.imu_count = static_cast<std::uint8_t>(ra::kImuSamplesPerCycle - 1);
    if (!tg_ok) in.tg.last_edge_us = in.tg.time_us + 1;  // an edge after the sample
    return in;
  }

  // The coming cycle's 3 s a_x window: how many samples it averages (n) and the sum of the
  // n - 1 it already holds (1e-9 m/s^2); its average is (sum + sample) / n.
  struct Window {
    std::int64_t n = 1, sum = 0;
  };
  Window Coming() const {
    Window w{std::min<std::int64_t>(index_ + 1, kAvgCycles), 0};
    for (std::int64_t j = 1; j < w.n; ++j) w.sum += samples_[samples_.size() - static_cast<std::size_t>(j)];
    return w;
  }

  // The a_x sample (in 1e-9 m/s^2) that puts the compared average at q (given A_p).
  std::int64_t SampleFor(double q, double ap) const {
    const Window w = Coming();
    return std::llround((q + ap) * static_cast<double>(w.n) * 1e9) - w.sum;
  }
  // The compared average (a_x average minus A_p) of a cycle outside compensation: on the
  // step's side of the threshold (before the detection within kHover of it), moving by at most
  // kJerkHolds where the jerk conditions must hold and by at least kJerkFails where they must
  // fail; otherwise before the detection as near as it can to kNear off the threshold, and after
  // it to the level value, at which the cycle's sample equals the average it makes (so that the
  // samples stay calm).
  double ChooseQ(bool dev, int jerk, bool narrow, bool level_wanted, double thr, double ap) const {
    const Window w = Coming();
    const double level = w.n == 1 ? prev_q_ : (static_cast<double>(w.sum) * 1e-9 - static_cast<double>(w.n) * ap) /
                                                 static_cast<double>(w.n - 1);
    // the step's side of the threshold
    const double lo = dev ? thr + kEdge : (narrow ? thr - kHover : -(thr - kEdge));
    const double hi = dev ? (narrow ? thr + kHover : thr + 1.0) : thr - kEdge;
    std::vector<std::pair<double, double>> allowed;
    if (jerk > 0) {
      allowed.emplace_back(std::max(lo, prev_q_ - kJerkHolds), std::min(hi, prev_q_ + kJerkHolds));
    } else if (jerk < 0) {
      allowed.emplace_back(lo, std::min(hi, prev_q_ - kJerkFails));
      allowed.emplace_back(std::max(lo, prev_q_ + kJerkFails), hi);
    } else {
      allowed.emplace_back(lo, hi);
    }
    // before the detection near the threshold, so that a deviation can change within the jerk
    // conditions; after it the level value
    const double target = narrow && !level_wanted ? (dev ? thr + kNear : thr - kNear) : level;
    double best = std::nan("");
    for (const auto& [a, b] : allowed) {
      if (a > b) continue;
      const double q = std::clamp(target, a, b);
      if (std::isnan(best) || std::fabs(q - target) < std::fabs(best - target)) best = q;
    }
    return best;
  }

  void Cycle(std::size_t k, const json& step, const StartPlan& plan, std::vector<std::string>& problems) {
    const json& in = step.at("in");
    const json& out = step.at("out");
    rc::Checker chk(problems, "step " + std::to_string(k) + ": ", &in);
    const Want w = Reads(in);
    const ra::MachineState before = shadow_.machine().state();
    const bool balise = in.at("balise").get<bool>();
    if (w.mv.value_or(false)) {
      pulses_ += 1;  // a creep over one pulse edge, in the middle of the cycle
      edge_us_ = (rig_.Now() + p::cycle_ms) * 1000 - 50'000;
    }
    double ax = 0.0, wy = 0.0;
    double q = 0.0;
    std::int64_t x_nano = 0;
    if (w.healthy) {
      // the coming cycle's A_p and TG speed do not depend on its IMU samples
      ra::Odometry trial = shadow_;
      const ra::OdometryOutput& t = trial.Step(Sensors(true, true, prev_x_, 0.0));
      const double ap = t.ap_avg;
      const double thr = Threshold(t.v_tg);
      const bool want_dev = w.dev.value_or(false);
      if (before.mode == ra::Mode::kCompensating) {
        if (!Compensate(w, ap, thr, t.v_tg, ax, wy, chk)) return;
        x_nano = std::llround(ax * 1e9);
        ax = static_cast<double>(x_nano) * 1e-9;
      } else {
        const bool narrow = plan.detection && k < *plan.detection;
        // at the start points a level sample, so that the candidates start without a kick
        const bool start = plan.detection && (static_cast<std::int64_t>(k) == plan.s0 ||
                                              static_cast<std::int64_t>(k) == plan.s1);
        q = ChooseQ(want_dev, plan.jerk[k], narrow, start, thr, ap);
        if (std::isnan(q)) {
          chk.Fail("no a_x average gives this step's deviation with the jerk conditions the start point needs");
          return;
        }
        x_nano = SampleFor(q, ap);
        ax = static_cast<double>(x_nano) * 1e-9;
        // The pitch from the second start point on: gravity takes the whole a_x, so both
        // candidates keep their start speed; at the primary's start point the pitch is the
        // one the primary takes there (its average), so that both integrate one pitch after it.
        const auto kk = static_cast<std::int64_t>(k);
        if (plan.detection && kk > plan.s1 && k <= *plan.detection) {
          const double target = kk == plan.s0 ? q : ax - (kk > plan.s0 ? plan.pre_accel : 0.0);
          wy = (std::asin(std::clamp(target / kG, -0.99, 0.99)) - theta_[1]) / kDt;
        }
      }
      if (std::fabs(wy) > kRateLimit || std::fabs(ax) > kSampleLimit) {
        chk.Fail("the stream cannot make this step within the IMU's range (a_x " + std::to_string(ax) +
                 ", pitch rate " + std::to_string(wy) + ")");
        return;
      }
    }
    if (balise) rig_.Balise(balise_.id);
    const ra::CycleInput sensors = Sensors(in.at("imu_ok").get<bool>(), in.at("tg_ok").get<bool>(), ax, wy);
    (void)rig_.Sensors().Next();  // the rig's clock: the stream's standing cycle is replaced
    ra::CycleInput fixed = sensors;
    if (balise) fixed.balise = ra::BaliseFix{balise_.position_mm};  // as the unit's track database has it
    const ra::OdometryOutput& od = shadow_.Step(fixed);
    const OnboardOutputs& o = rig_.StepWith(sensors);
    if (o.sent) rig_.Answer(messages::KeepAlive{});
    const ra::OdometryOutput& uo = rig_.Unit().Odometry();

    // the stream's bookkeeping: the history restarts after a rejected cycle
    if (od.input_error == ra::InputError::kNone) {
      samples_.push_back(x_nano);
      prev_x_ = ax;
      prev_q_ = od.ax_avg - od.ap_avg;
      for (std::size_t c = 0; c < 2; ++c) theta_[c] += wy * kDt;
      if (plan.detection && static_cast<std::int64_t>(k) == plan.s1) theta_[1] = std::asin(prev_q_ / kG);
      if (plan.detection && static_cast<std::int64_t>(k) == plan.s0) theta_[0] = std::asin(prev_q_ / kG);
      if (od.detected) {
        start_index_[0] = index_ - od.start_age_cycles;
        start_index_[1] = std::max(start_index_[0] - kSpacing, kUsable);
      }
      for (std::size_t c = 0; c < 2; ++c) a_prev_[c] = ax - kG * std::sin(theta_[c]);
      index_ += 1;
    } else {
      samples_.clear();
      index_ = 0;
    }

    // the unit's odometry is the shadow (same stream): its machine state is the unit's
    chk.Expect("unit odometry mode", ra::ToString(od.mode), ra::ToString(uo.mode));
    chk.Expect("unit odometry front", std::to_string(od.front_mm), std::to_string(uo.front_mm));
    chk.Expect("unit odometry speed", std::to_string(od.speed_mm_s), std::to_string(uo.speed_mm_s));
    chk.Expect("unit detected", rc::Bool(od.detected), rc::Bool(uo.detected));
    chk.Expect("unit adopted", std::to_string(od.adopted), std::to_string(uo.adopted));
    // the predicates the stream made, where the machine reads them
    const ra::Predicates& pr = od.predicates;
    chk.Expect("imu_ok", rc::Bool(in.at("imu_ok").get<bool>()), rc::Bool(pr.imu_ok));
    if (pr.imu_ok) chk.Expect("tg_ok", rc::Bool(in.at("tg_ok").get<bool>()), rc::Bool(pr.tg_ok));
    if (w.healthy) {
      chk.Expect("balise", rc::Bool(balise), rc::Bool(pr.balise));
      if (w.mv) chk.Expect("tg_moving", rc::Bool(*w.mv), rc::Bool(pr.tg_moving));
      if (w.dev) chk.Expect("deviation", rc::Bool(*w.dev), rc::Bool(pr.deviation));
      for (std::size_t c = 0; c < 2; ++c) {
        if (w.sa[c]) chk.Expect("speed_agrees[" + std::to_string(c) + "]", rc::Bool(*w.sa[c]), rc::Bool(pr.speed_agrees[c]));
      }
    }
    chk.Expect("section time", std::to_string(in.at("section").at("max_compensation_cycles").get<int>()),
               std::to_string(pr.section.max_compensation_cycles));
    // the machine's state and the unit's outputs
    const ra::MachineState& st = shadow_.machine().state();
    chk.Expect("mode", out.at("mode").get<std::string>(), ra::ToString(st.mode));
    chk.Expect("stop_reason", out.at("stop_reason").get<std::string>(), ra::ToString(st.stop_reason));
    chk.Expect("deviation_count", std::to_string(out.at("deviation_count").get<int>()), std::to_string(st.deviation_count));
    for (std::size_t c = 0; c < 2; ++c) {
      const json& e = out.at("candidates")[c];
      const std::string n = "candidate " + std::to_string(c) + " ";
      chk.Expect(n + "active", rc::Bool(e.at("active").get<bool>()), rc::Bool(st.candidates[c].active));
      chk.Expect(n + "age", std::to_string(e.at("age_cycles").get<int>()), std::to_string(st.candidates[c].age_cycles));
      chk.Expect(n + "confirm", std::to_string(e.at("confirm").get<int>()), std::to_string(st.candidates[c].confirm));
    }
    chk.Expect("max_compensation_cycles", std::to_string(out.at("max_compensation_cycles").get<int>()),
               std::to_string(st.max_compensation_cycles));
    chk.Expect("trusted", rc::Bool(out.at("trusted").get<bool>()), rc::Bool(st.trusted));
    chk.Expect("rest_cycles", std::to_string(out.at("rest_cycles").get<int>()), std::to_string(st.rest_cycles));
    chk.Expect("balise_reset", rc::Bool(out.at("balise_reset").get<bool>()), rc::Bool(st.balise_reset));
    chk.Expect("detected", rc::Bool(out.at("detected").get<bool>()), rc::Bool(uo.detected));
    if (uo.detected) {
      chk.Expect("start-point age", std::to_string(in.at("start_age_cycles").get<int>()),
                 std::to_string(uo.start_age_cycles));
    }
    const json& adopted = out.at("adopted");
    chk.Expect("adopted", adopted.is_null() ? "-1" : std::to_string(adopted.get<int>()), std::to_string(uo.adopted));
    chk.Expect("position_valid", rc::Bool(out.at("position_valid").get<bool>()), rc::Bool(o.position_valid));
    // the brake reason is the odometry's stop once the radio link is up (its first telegrams
    // take a few cycles at the start, when the start-up stop demands a stop anyway)
    link_up_ = link_up_ || o.link == tg::LinkState::kUp;
    if (link_up_) {
      chk.Expect("link", ToString(tg::LinkState::kUp), ToString(o.link));
      chk.Expect("stop_demand (" + std::string(ToString(o.reason)) + ")", rc::Bool(out.at("stop_demand").get<bool>()),
                 rc::Bool(o.reason == BrakeReason::kOdometryStop));
    } else {
      chk.Expect("stop_demand (odometry)", rc::Bool(out.at("stop_demand").get<bool>()), rc::Bool(uo.stop_demand));
      chk.Expect("braking before the link is up", "true", rc::Bool(o.reason != BrakeReason::kNone));
    }
  }

  // A compensating cycle: the candidates' speed change (their compensated acceleration A, a
  // trapezoid over the cycle) is chosen on a grid so that each candidate whose agreement is
  // read lands inside (or outside) its tolerance, else near the border of the primary's; the
  // a_x sample then lies in the deviation band as close as it can to A plus the current
  // gravity term, and the pitch rate makes up the rest.
  bool Compensate(const Want& w, double ap, double thr, double v_tg, double& ax, double& wy, rc::Checker& chk) {
    const ra::OdometryOutput& now = shadow_.output();
    std::array<double, 2> tol{};
    for (std::size_t c = 0; c < 2; ++c) tol[c] = Tolerance(CandidateCycles(c), Resolution(v_tg));
    // the a_x interval of the deviation band
    const Window win = Coming();
    const double nn = static_cast<double>(win.n), s = static_cast<double>(win.sum) * 1e-9;
    // q intervals of the step's deviation: a narrow band near the threshold, which keeps the
    // samples calm (the pitch then sets the acceleration; preferred), and the whole band
    const bool dev = w.dev.value_or(false);
    const std::array<std::vector<std::pair<double, double>>, 2> band_sets = {
        dev ? std::vector<std::pair<double, double>>{{thr + kBand, thr + 0.025}}
            : std::vector<std::pair<double, double>>{{thr - 0.025, thr - kBand}},
        dev ? std::vector<std::pair<double, double>>{{thr + kBand, thr + 2.0}, {-thr - 2.0, -thr - kBand}}
            : std::vector<std::pair<double, double>>{{-(thr - kBand), thr - kBand}}};
    const double pref = 0.5 * (tol[0] + tol[1]);  // between the two candidates' tolerances
    const bool required = w.sa[0].has_value() || w.sa[1].has_value();
    double best_cost = 1e300;
    const int grid = static_cast<int>(kMaxA / 0.02);
    for (std::size_t set = 0; set < band_sets.size(); ++set) {
      const auto& bands = band_sets[set];
      for (int g = -grid; g <= grid; ++g) {
        const double a0 = 0.02 * g;
        const double free_x = a0 + kG * std::sin(theta_[0]);  // the pitch unchanged
        double x = std::nan("");
        for (const auto& [qlo, qhi] : bands) {
          const double c = std::clamp(free_x, nn * (qlo + ap) - s, nn * (qhi + ap) - s);
          if (std::isnan(x) || std::fabs(c - free_x) < std::fabs(x - free_x)) x = c;
        }
        const double sin0 = (x - a0) / kG;  // the pitch gravity must take for that acceleration
        if (std::fabs(sin0) > 0.95) continue;
        const double th0 = std::asin(sin0);
        const double rate = (th0 - theta_[0]) / kDt;
        if (std::fabs(rate) > kRateLimit || std::fabs(x) > kSampleLimit) continue;
        bool ok = true;
        double v0 = 0;
        for (std::size_t c = 0; c < 2; ++c) {
          const double a = x - kG * std::sin(theta_[c] + rate * kDt);
          const double v = now.v_comp[c] + 0.5 * (a_prev_[c] + a) * kDt;
          if (c == 0) v0 = v;
          if (!w.sa[c]) continue;
          const double d = std::fabs(v_tg - v);
          ok = ok && (*w.sa[c] ? d <= tol[c] - kSpeedMargin : d >= tol[c] + kSpeedMargin);
        }
        if (!ok) continue;
        // Keep the next cycle free to reach every agreement: the pitch rate lets the acceleration
        // change by 3 m/s^2 or more in a cycle (within +-kMaxA), so the next speed lies in a window
        // (the trapezoid); it must hold the border between the tolerances with room for either
        // side of it (on either sign of the speed difference).
        const double a_lo = std::max(-kMaxA, a0 - 3.0), a_hi = std::min(kMaxA, a0 + 3.0);
        const double w_lo = v0 - v_tg + 0.5 * (a0 + a_lo) * kDt, w_hi = v0 - v_tg + 0.5 * (a0 + a_hi) * kDt;
        const double border = pref + kRate * kDt, room = 0.5 * (tol[1] - tol[0]) + 0.01;
        const bool free_next = (w_lo <= border - room && w_hi >= border + room) ||
                               (w_lo <= -border - room && w_hi >= -border + room);
        const double cost = (required ? 0.2 : 1.0) * std::fabs(std::fabs(v0 - v_tg) - pref) + 0.3 * std::fabs(a0) +
                            0.5 * std::fabs(th0) + (free_next ? 0.0 : 10.0) +
                            (std::fabs(th0) > 0.6 ? 10.0 : 0.0) + (set == 0 ? 0.0 : 0.05) +
                            3.0 * std::fabs((s + x) / nn - ap - (dev ? thr + 0.015 : thr - 0.015));
        if (cost < best_cost) {
          best_cost = cost;
          ax = x;
          wy = rate;
        }
      }
    }
    if (best_cost == 1e300) {
      chk.Fail("no a_x and pitch rate give this step's deviation and speed agreement (candidate speeds " +
               std::to_string(now.v_comp[0]) + ", " + std::to_string(now.v_comp[1]) + " m/s)");
      return false;
    }
    return true;
  }

  OnboardConfig cfg_;
  Rig rig_;
  BaliseEntry balise_;  // the balise the steps read (the line's first)
  ra::Odometry shadow_;
  double ta_ = 0;
  std::int64_t pulses_ = 0, edge_us_ = 0;
  std::vector<std::int64_t> samples_;  // a_x samples since the history's restart (1e-9 m/s^2)
  std::int64_t index_ = 0;             // history index of the coming cycle
  double prev_x_ = 0, prev_q_ = 0;
  std::array<double, 2> theta_{};      // the candidates' pitch as the odometry integrates it
  std::array<double, 2> a_prev_{};     // their compensated acceleration of the last cycle
  std::array<std::int64_t, 2> start_index_{};
  bool link_up_ = false;
};

// @verifies REQ-RA-003 REQ-RA-004 REQ-RA-006 REQ-RA-007 REQ-RA-010 REQ-RA-012 REQ-RA-013 REQ-RA-015
TEST(OnboardReplay, OdometryVectorsOfTheUnitEnvironment) {
  const Loaded l = Load("ra", rc::RaVectorKeys());
  ASSERT_TRUE(l.headers.count("ra.unit.jsonl")) << "ra.unit.jsonl missing from " << kVectors;
  const json& header = l.headers.at("ra.unit.jsonl");
  ASSERT_EQ(header.at("configuration").get<std::string>(), "UNIT");
  std::size_t replayed = 0, detecting = 0, adopted = 0, timed_out = 0;
  for (const auto& [file, v] : l.vectors) {
    if (file != "ra.unit.jsonl") continue;
    SCOPED_TRACE(file + ": " + v.at("id").get<std::string>());
    const json& steps = v.at("steps");
    // the train stands on one section: the line is that section throughout
    const json& sec = steps.at(0).at("in").at("section");
    Line line;
    line.sections = {ra::OdometrySection{0, 100'000'000, 0,
                                         sec.at("max_compensation_cycles").get<std::int64_t>() * p::cycle_ms, 0}};
    std::vector<std::string> problems;
    const StartPlan plan = Plan(steps, problems);
    if (problems.empty()) {
      SlipReplay replay(line);
      replay.Run(steps, plan, problems);
    }
    for (const std::string& pr : problems) ADD_FAILURE() << pr;
    ++replayed;
    detecting += plan.detection.has_value();
    for (const json& s : steps) {
      adopted += !s.at("out").at("adopted").is_null();
      timed_out += s.at("out").at("stop_reason").get<std::string>() == "MAX_COMPENSATION_TIME" &&
                   s.at("out").at("detected").get<bool>();
    }
  }
  EXPECT_EQ(replayed, 50U);
  EXPECT_GT(detecting, 25U);
  EXPECT_GT(adopted, 10U);
  EXPECT_GT(timed_out, 5U);  // stopped in the detection cycle: every start point older than t_max
  RecordProperty("replayed", std::to_string(replayed));
  RecordProperty("detecting", std::to_string(detecting));
  RecordProperty("adoptions", std::to_string(adopted));
}

}  // namespace
}  // namespace railproof::units::test
