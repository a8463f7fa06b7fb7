// Warning-time study: kinematics, the schedule, and the warning start of every method
// (warning_study.hpp). The on-board variants without and with the contract's dwell awareness
// run the runtime lc::onboard::CrossingProtection in the loop; the braking check runs the runtime
// br::PatternCalculator and br::Supervisor.
#include "railproof/lc/analysis/warning_study.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <string>
#include <utility>

#include "railproof/br/supervisor.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/offline/dynamics.hpp"

namespace railproof::lc::analysis {

using offline::InputError;
namespace lcp = railproof::params::lc;

// ============================================================================ kinematics

// @implements REQ-LC-017
std::int64_t TreadleDistanceMm(std::span<const br::RestrictionSegment> profile, std::int64_t near_mm,
                               std::int64_t warning_ms) {
  // Walk back from near piece by piece; remaining time in ns (piece times rounded down, so the
  // remaining time and the distance are never understated).
  if (warning_ms < 0 || warning_ms > 3'600'000) {
    throw InputError("treadle distance: warning time " + std::to_string(warning_ms) + " ms outside [0, 1 h]");
  }
  std::int64_t rem_ns = warning_ms * 1'000'000;
  std::int64_t pos = near_mm;
  std::int64_t dist = 0;
  while (rem_ns > 0 && pos > 0) {
    // the piece just before pos: its limit and its begin
    std::int64_t v = 0;
    std::int64_t begin = 0;
    for (const auto& seg : profile) {
      if (seg.begin_mm < pos && pos <= seg.end_mm) {
        v = seg.limit_mm_s;
        begin = seg.begin_mm;
      }
    }
    if (v <= 0) {
      // no limit known before pos (off the profile): the treadle stays where it is reached
      break;
    }
    const std::int64_t len = pos - begin;
    if (len > 1'000'000'000 || v > br::kMaxLimitMmS) {
      throw InputError("treadle distance: piece of " + std::to_string(len) + " mm at " + std::to_string(v) +
                       " mm/s out of range (at most 1000 km, br::kMaxLimitMmS)");
    }
    const std::int64_t piece_ns = len * 1'000'000'000 / v;  // < 1e18
    if (piece_ns >= rem_ns) {
      // v * rem / 1e9 mm with the remaining time rounded up to the microsecond, rounded up
      const std::int64_t rem_us = (rem_ns + 999) / 1000;  // <= 3.6e9 for a warning of 1 h
      const std::int64_t d = (v * rem_us + 999'999) / 1'000'000;
      dist += std::min(d, len);
      rem_ns = 0;
      break;
    }
    rem_ns -= piece_ns;
    dist += len;
    pos = begin;
  }
  return std::min(dist, near_mm);
}

namespace {

// Lowest line limit (mm/s) over the train [x - length, x], capped at the train's maximum speed.
double PermittedRear(const offline::RunningLine& rl, double x, const SectionDriving& d) {
  std::int64_t v = d.max_speed_mm_s > 0 ? d.max_speed_mm_s : std::numeric_limits<std::int64_t>::max();
  double c = std::numeric_limits<double>::infinity();
  rl.ForEachLimitActing(x - static_cast<double>(d.train_length_mm), x, [&](std::size_t i) {
    v = std::min(v, SpeedKmhToMmS(rl.speed_limits[i].kmh));
    if (d.ceiling_mm_s != nullptr && i < d.ceiling_mm_s->size()) {
      c = std::min(c, (*d.ceiling_mm_s)[i]);
    }
  });
  return std::min(static_cast<double>(v), c);
}

constexpr std::int64_t kGridMm = 1000;  // position grid of the kinematic model (1 m)

// The constant acceleration (mm/s^2) between two samples of a run.
double Acceleration(const RunSample& a, const RunSample& b) { return (b.v_mm_s - a.v_mm_s) / ((b.t_ms - a.t_ms) / 1000.0); }

}  // namespace

double RunSection(const offline::RunningLine& rl, std::int64_t from_mm, std::int64_t to_mm, const SectionDriving& d,
                  double t0_ms, std::vector<RunSample>* out) {
  if (to_mm <= from_mm) {
    throw InputError("warning study: empty section [" + std::to_string(from_mm) + ", " + std::to_string(to_mm) + ") mm");
  }
  if (d.accel_mm_s2 <= 0.0 || d.decel_mm_s2 <= 0.0 || d.cruise_factor <= 0.0) {
    throw InputError("warning study: acceleration, deceleration and cruise factor must be positive");
  }
  std::vector<double> x;
  for (std::int64_t p = from_mm; p < to_mm; p += kGridMm) {
    x.push_back(static_cast<double>(p));
  }
  x.push_back(static_cast<double>(to_mm));
  const std::size_t n = x.size();
  std::vector<double> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i] = d.cruise_factor * PermittedRear(rl, x[i], d);
  }
  v[0] = 0.0;
  for (std::size_t i = 0; i + 1 < n; ++i) {  // accelerate at accel_max
    v[i + 1] = std::min(v[i + 1], SpeedAfter(v[i], d.accel_mm_s2, x[i + 1] - x[i]));
  }
  v[n - 1] = 0.0;
  for (std::size_t i = n - 1; i > 0; --i) {  // brake at the service deceleration (backwards)
    v[i - 1] = std::min(v[i - 1], SpeedAfter(v[i], d.decel_mm_s2, x[i] - x[i - 1]));
  }
  double t = 0.0;
  if (out != nullptr) {
    out->push_back({t0_ms, x[0], 0.0});
  }
  for (std::size_t i = 0; i + 1 < n; ++i) {
    t += TimeOver(1000.0 * (x[i + 1] - x[i]), v[i], v[i + 1]);  // ms: 1000 x mm / (mm/s)
    if (out != nullptr) {
      out->push_back({t0_ms + t, x[i + 1], v[i + 1]});
    }
  }
  return t;
}

std::optional<double> Run::TimeAt(double x_mm) const {
  if (samples.empty() || samples.back().x_mm < x_mm) {
    return std::nullopt;
  }
  const auto it = std::lower_bound(samples.begin(), samples.end(), x_mm,
                                   [](const RunSample& s, double x) { return s.x_mm < x; });
  if (it == samples.begin()) {
    return it->t_ms;
  }
  const RunSample& b = *it;
  const RunSample& a = *(it - 1);
  if (b.x_mm <= a.x_mm) {
    return b.t_ms;
  }
  // constant acceleration between the grid points
  const double dt = b.t_ms - a.t_ms;
  const double tau_ms = 1000.0 * TimeToCover(a.v_mm_s, Acceleration(a, b), x_mm - a.x_mm);
  return a.t_ms + std::clamp(tau_ms, 0.0, dt);
}

RunSample Run::StateAt(double t_ms) const {
  if (samples.empty()) {
    return {};
  }
  if (t_ms <= samples.front().t_ms) {
    return {t_ms, samples.front().x_mm, samples.front().v_mm_s};
  }
  if (t_ms >= samples.back().t_ms) {
    return {t_ms, samples.back().x_mm, samples.back().v_mm_s};
  }
  const auto it = std::upper_bound(samples.begin(), samples.end(), t_ms,
                                   [](double t, const RunSample& s) { return t < s.t_ms; });
  const RunSample& b = *it;
  const RunSample& a = *(it - 1);
  const double dt = b.t_ms - a.t_ms;
  if (dt <= 0.0 || b.x_mm <= a.x_mm) {
    return {t_ms, a.x_mm, 0.0};
  }
  const Motion m = Advance({a.x_mm, a.v_mm_s}, Acceleration(a, b), (t_ms - a.t_ms) / 1000.0);
  return {t_ms, std::min(m.position, b.x_mm), m.speed};
}

std::optional<std::size_t> Run::StandingAt(double t_ms) const {
  for (std::size_t k = 0; k < stops.size(); ++k) {
    const RunStop& s = stops[k];
    const double from = s.origin ? -std::numeric_limits<double>::infinity() : s.arrival_ms;
    const double to = s.destination ? std::numeric_limits<double>::infinity() : s.departure_ms;
    if (t_ms >= from && t_ms < to) {
      return k;
    }
  }
  return std::nullopt;
}

// ============================================================================ methods

namespace {

// The name (JSON key, plot file) and the description of every method, in the order of Method.
struct MethodText {
  Method method;
  const char* name;
  const char* description;
};
constexpr std::array<MethodText, kMethodCount> kMethodTexts{{
    {Method::kTreadle, "fixed_treadles",
     "(a) fixed treadles at the distance giving the design warning time to the fastest train at the permitted speed"},
    {Method::kOnboard, "onboard", "(b) on-board request (lc::onboard::CrossingProtection), no dwell awareness"},
    {Method::kOnboardDwell, "onboard_dwell_aware",
     "(b) on-board request, dwell-aware while standing at the stop (design note §2-§3, REQ-LC-005)"},
    {Method::kOnboardApproach, "onboard_dwell_aware_approach",
     "(b) on-board request, dwell-aware from the approach to the stop on (proposed extension of REQ-LC-005)"},
    {Method::kGnss, "gnss_time",
     "(c) GNSS-time pre-arming: start times from the planned departure, updates from position reports (report time "
     "stamp)"},
    {Method::kGnssReceiveTime, "gnss_time_receive_time_basis",
     "(c) sensitivity: as (c) with updates computed from the centre's receive time (design note §5 item 4 read "
     "literally)"},
}};

const MethodText* TextOf(Method m) {
  const auto it = std::find_if(kMethodTexts.begin(), kMethodTexts.end(), [m](const MethodText& t) { return t.method == m; });
  return it == kMethodTexts.end() ? nullptr : &*it;
}

}  // namespace

const char* ToString(Method m) {
  const MethodText* t = TextOf(m);
  return t != nullptr ? t->name : "invalid";
}

const char* Describe(Method m) {
  const MethodText* t = TextOf(m);
  return t != nullptr ? t->description : "invalid";
}

bool MustMeetDesignTime(Method m) {
  return m == Method::kOnboard || m == Method::kOnboardDwell || m == Method::kOnboardApproach || m == Method::kGnss;
}

bool IsOnboard(Method m) {
  return m == Method::kOnboard || m == Method::kOnboardDwell || m == Method::kOnboardApproach;
}

namespace {

// Deterministic random numbers (SplitMix64): the same seed gives the same study on every
// platform (std::uniform_*_distribution is implementation-defined).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  }
  double Uniform() { return static_cast<double>(Next() >> 11) * (1.0 / 9007199254740992.0); }
  double Uniform(double lo, double hi) { return lo + (hi - lo) * Uniform(); }
  std::int64_t UniformMs(const RangeMs& r) {
    return r.min + static_cast<std::int64_t>(std::floor(Uniform() * static_cast<double>(r.max - r.min + 1)));
  }
  std::int64_t Symmetric(std::int64_t e) { return UniformMs({-e, e}); }

 private:
  std::uint64_t state_;
};

std::uint64_t Mix(std::uint64_t a, std::uint64_t b) {
  Rng r(a * 0x100000001B3ULL ^ (b + 0x632BE59BD9B4E019ULL));
  return r.Next();
}

std::int64_t CeilTo(std::int64_t v, std::int64_t step) {
  const std::int64_t q = v / step;
  return (q * step >= v ? q : q + 1) * step;
}

// One crossing of a run.
struct CrossingOfRun {
  std::size_t line_index = 0;  // into rl.level_crossings
  lc::CrossingData data;
  std::string id;
  double arrival_ms = 0.0;
  // draws shared by the on-board variants (fair comparison)
  std::int64_t uplink_ms = 0, downlink_ms = 0, travel_ms = 0;
  std::int64_t onboard_clock_ms = 0;  // controller clock error (on-board variant)
  std::int64_t gnss_clock_ms = 0;     // controller clock error (GNSS variant)
};

// Everything the runtime pattern check needs for one train on one running line.
struct PatternCheck {
  std::optional<br::PatternCalculator> calc;
  std::int64_t baseline_limit_mm = 0;
  std::vector<double> ceiling_mm_s;  // per speed-limit segment (SectionDriving::ceiling_mm_s)

  // Highest measured speed (mm/s) at `front_mm` for which the supervision commands no brake
  // on the line profile alone (bisection; the brake command is monotone in the speed).
  [[nodiscard]] double Ceiling(std::int64_t front_mm, std::int64_t hi_mm_s) const {
    std::int64_t lo = 0, hi = hi_mm_s;
    auto quiet = [&](std::int64_t v) {
      const br::Evaluation e = calc->Evaluate({front_mm, 0, 0, v, v == 0}, baseline_limit_mm);
      br::Supervisor s;
      return e.status == br::EvalStatus::kOk && s.Step(e.speeds, {v == 0, false, false}).level == br::BrakeLevel::kNone;
    };
    if (quiet(hi)) {
      return static_cast<double>(hi);
    }
    while (hi - lo > 1) {
      const std::int64_t mid = lo + (hi - lo) / 2;
      (quiet(mid) ? lo : hi) = mid;
    }
    return static_cast<double>(lo);
  }

  // True if the protection limit at `limit_mm` makes the supervision brake the train at
  // (front, speed) and the line profile alone does not.
  bool CrossingBrakes(std::int64_t front_mm, std::int64_t speed_mm_s, bool standstill, std::int64_t limit_mm,
                      std::size_t& evaluations) const {
    const br::PositionEstimate pos{front_mm, 0, 0, speed_mm_s, standstill};
    const br::Evaluation e = calc->Evaluate(pos, limit_mm);
    ++evaluations;
    br::Supervisor s1;
    if (e.status != br::EvalStatus::kOk || s1.Step(e.speeds, {standstill, false, false}).level == br::BrakeLevel::kNone) {
      return false;
    }
    const br::Evaluation b = calc->Evaluate(pos, baseline_limit_mm);
    ++evaluations;
    br::Supervisor s2;
    return b.status == br::EvalStatus::kOk && s2.Step(b.speeds, {standstill, false, false}).level == br::BrakeLevel::kNone;
  }

  // Distance to the limit beyond which the pattern cannot brake (saves evaluations).
  [[nodiscard]] double Reach(double v_mm_s) const {
    const auto& p = calc->params();
    const double beta = static_cast<double>(calc->train().beta_n7_mm_s2);
    const double t_s = static_cast<double>(calc->RunUpTimeMs(br::Pattern::kService) + p.release_lead_ms + 1000) / 1000.0;
    return v_mm_s * v_mm_s / (2.0 * beta) + v_mm_s * t_s + static_cast<double>(p.service_offset_mm) + 200'000.0;
  }
};

// The controller's reports for one request (design note §4): WARNING from the warning start,
// CLOSED with the warning start once the barriers are detected down; one per ground cycle.
// The one train of a passage (the study runs each passage alone).
constexpr std::uint32_t kStudyTrainId = 1;

struct Report {
  double delivered_ms = 0.0;  // true time at the train
  messages::CrossingReport msg;
};

struct Controller {
  bool requested = false;
  double request_ms = 0.0;   // true time the train first requested
  double ws_true_ms = 0.0;   // true warning start
  std::int64_t ws_reading = 0;  // controller clock
  std::deque<Report> reports;
};

void StartController(Controller& c, const CrossingOfRun& cr, const CommsModel& comms, double t_true, double until_ms) {
  c.requested = true;
  c.request_ms = t_true;
  const std::int64_t e_x = cr.onboard_clock_ms;
  const auto rx_reading = static_cast<std::int64_t>(std::ceil(t_true + static_cast<double>(cr.uplink_ms + e_x)));
  c.ws_reading = CeilTo(rx_reading, comms.ground_cycle_ms);
  c.ws_true_ms = static_cast<double>(c.ws_reading - e_x);
  const std::int64_t closed_reading = CeilTo(c.ws_reading + lcp::barrier_lowering_ms + cr.travel_ms, comms.ground_cycle_ms);
  double last = -1.0;
  for (std::int64_t r = c.ws_reading; static_cast<double>(r - e_x) <= until_ms; r += comms.ground_cycle_ms) {
    Report rep;
    rep.msg.crossing_id = cr.data.id;
    rep.msg.status = r >= closed_reading ? messages::CrossingStatus::kClosed : messages::CrossingStatus::kWarning;
    rep.msg.warning_start_ms = c.ws_reading;
    rep.msg.issued_ms = r;
    rep.msg.requesters[0] = kStudyTrainId;  // the controller holds this train's request
    rep.msg.requester_count = 1;
    rep.delivered_ms = std::max(last, static_cast<double>(r - e_x + cr.downlink_ms));
    last = rep.delivered_ms;
    c.reports.push_back(rep);
  }
}

struct ServiceSetup {
  const Service* service = nullptr;
  const TrainType* train = nullptr;
  const offline::RunningLine* rl = nullptr;
  std::vector<br::RestrictionSegment> profile;  // permitted speed for the ETA
  PatternCheck* pattern = nullptr;
};

// The run (schedule and simulated trajectory) of one service.
Run SimulateService(const ServiceSetup& s, const Timetable& tt, Rng& rng, std::int64_t centre_clock_ms) {
  const offline::RunningLine& rl = *s.rl;
  const Service& sv = *s.service;
  const TrainType& t = *s.train;
  Run run;
  auto station = [&](const std::string& name) -> const offline::Station& {
    const offline::Station* st = rl.FindStation(name);
    if (st == nullptr) {
      throw InputError(tt.file + ": services (" + sv.id + "): station '" + name + "' has no stop on " + rl.id);
    }
    return *st;
  };
  const offline::Station& origin = sv.from.empty() ? rl.stations.front() : station(sv.from);
  const offline::Station& dest = sv.to.empty() ? rl.stations.back() : station(sv.to);
  run.stops.push_back({origin.name, origin.stop_mm, sv.depart_ms, sv.depart_ms, 0, 0, true, false});
  for (const auto& st : sv.stops) {
    const offline::Station& x = station(st.station);
    run.stops.push_back({x.name, x.stop_mm, 0, st.dwell_ms, 0, 0, false, false});  // dwell kept in planned_departure for now
  }
  run.stops.push_back({dest.name, dest.stop_mm, 0, 0, 0, 0, false, true});

  SectionDriving d;
  d.accel_mm_s2 = static_cast<double>(t.accel_max_mm_s2);
  d.decel_mm_s2 = static_cast<double>(t.service_deceleration_mm_s2.min);
  d.train_length_mm = t.length_mm;
  d.max_speed_mm_s = t.MaxSpeedMmS();
  d.ceiling_mm_s = &s.pattern->ceiling_mm_s;
  // planned times: technical running time (cruise 100 %) + allowance, rounded up
  for (std::size_t k = 0; k + 1 < run.stops.size(); ++k) {
    SectionDriving tech = d;
    tech.cruise_factor = 1.0;
    const double rt = RunSection(rl, run.stops[k].front_mm, run.stops[k + 1].front_mm, tech, 0.0, nullptr);
    const auto planned = CeilTo(static_cast<std::int64_t>(std::ceil(rt * (100.0 + static_cast<double>(tt.running_time_allowance_percent)) / 100.0)),
                                tt.planned_time_step_ms);
    RunStop& next = run.stops[k + 1];
    next.planned_arrival_ms = run.stops[k].planned_departure_ms + planned;
    next.planned_departure_ms = next.destination ? next.planned_arrival_ms : next.planned_arrival_ms + next.planned_departure_ms;
  }
  // the simulated run: the departure signal clears at the planned departure by the centre's
  // clock (true time t_dep - centre_clock_ms); the driver starts after the minimum dwell and
  // a reaction delay; cruise factor per section
  double t_arr = 0.0;
  for (std::size_t k = 0; k + 1 < run.stops.size(); ++k) {
    RunStop& st = run.stops[k];
    const double signal = static_cast<double>(st.planned_departure_ms - centre_clock_ms);
    const double earliest = st.origin ? signal : std::max(signal, t_arr + static_cast<double>(tt.driver.min_dwell_ms));
    st.departure_ms = earliest + static_cast<double>(rng.UniformMs(tt.driver.start_delay_ms));
    if (st.origin) {
      st.arrival_ms = st.departure_ms;
    }
    SectionDriving dk = d;
    dk.cruise_factor = rng.Uniform(static_cast<double>(tt.driver.cruise_min_percent), static_cast<double>(tt.driver.cruise_max_percent)) / 100.0;
    // (the section's first sample at the departure and the previous arrival sample at the same
    // position form the dwell)
    std::vector<RunSample> sec;
    const double rt = RunSection(rl, st.front_mm, run.stops[k + 1].front_mm, dk, st.departure_ms, &sec);
    run.samples.insert(run.samples.end(), sec.begin(), sec.end());
    t_arr = st.departure_ms + rt;
    run.stops[k + 1].arrival_ms = t_arr;
    if (run.stops[k + 1].destination) {
      run.stops[k + 1].departure_ms = t_arr;
    }
  }
  return run;
}

// Front (mm, rounded down) and speed (mm/s, rounded up) of the run at time t.
struct CycleState {
  std::int64_t front_mm = 0;
  std::int64_t speed_mm_s = 0;
  std::optional<std::size_t> standing;
};

CycleState StateFor(const Run& run, double t) {
  const RunSample s = run.StateAt(t);
  CycleState c;
  c.standing = run.StandingAt(t);
  c.front_mm = static_cast<std::int64_t>(std::floor(s.x_mm));
  c.speed_mm_s = c.standing ? 0 : static_cast<std::int64_t>(std::ceil(s.v_mm_s));
  return c;
}

// The stop the train stands at or runs to next (not yet departed), if it is before `near`
// and is not the destination (for the approach-aware ETA).
std::optional<std::size_t> NextStopBefore(const Run& run, double t, std::int64_t front_mm, std::int64_t near_mm) {
  for (std::size_t k = 0; k < run.stops.size(); ++k) {
    const RunStop& s = run.stops[k];
    if (s.destination) {
      return std::nullopt;
    }
    if (t < s.departure_ms && s.front_mm >= front_mm - 1000) {
      return s.front_mm < near_mm ? std::optional<std::size_t>(k) : std::nullopt;
    }
  }
  return std::nullopt;
}

// On-board variants: the runtime CrossingProtection (kOnboard, kOnboardDwell) or the
// approach-aware rule (kOnboardApproach), with the controller model and the pattern check.
void RunOnboard(Method m, const ServiceSetup& s, const Timetable& tt, const Run& run, std::vector<CrossingOfRun>& crs,
                std::int64_t train_clock_ms, std::int64_t lead, std::vector<Passage>& out, std::size_t first_passage,
                StudyResult& stats) {
  const TrainType& t = *s.train;
  const std::size_t mi = static_cast<std::size_t>(m);
  std::optional<lc::onboard::CrossingProtection> prot;
  if (m != Method::kOnboardApproach) {
    lc::onboard::ProtectionConfig cfg = lc::onboard::DefaultProtectionConfig(kStudyTrainId, t.length_mm, t.accel_max_mm_s2);
    cfg.request_lead_ms = lead;
    auto created = lc::onboard::CrossingProtection::Create(cfg);
    if (created.error != lc::onboard::ProtectionError::kNone) {
      throw InputError(t.file + ": on-board crossing function refused the train: " + onboard::ToString(created.error));
    }
    prot.emplace(std::move(*created.protection));
    std::vector<lc::CrossingData> data;
    for (const auto& c : crs) {
      data.push_back(c.data);
    }
    const auto e = prot->LoadCrossings(data);
    if (e != lc::onboard::ProtectionError::kNone) {
      throw InputError(s.rl->id + ": crossings refused by the on-board function: " + onboard::ToString(e));
    }
  }
  std::vector<Controller> ctl(crs.size());
  std::vector<bool> cleared(crs.size(), false);
  std::vector<double> brake_at(crs.size(), -1.0);
  enum class St { kApproaching, kRequested, kCleared };
  std::vector<St> rep_state(crs.size(), St::kApproaching);  // approach-aware replica
  const double end_ms = run.stops.back().arrival_ms;
  const double start_ms = std::min(run.stops.front().departure_ms, static_cast<double>(run.stops.front().planned_departure_ms)) - 120'000.0;
  const std::int64_t step = tt.comms.onboard_cycle_ms;
  std::vector<double> cleared_at(crs.size(), -1.0);
  std::vector<messages::CrossingReport> inbox;
  for (double tc = start_ms; tc <= end_ms; tc += static_cast<double>(step)) {
    const CycleState cs = StateFor(run, tc);
    const std::int64_t now = static_cast<std::int64_t>(std::llround(tc)) + train_clock_ms;
    // reports delivered since the last cycle
    inbox.clear();
    for (std::size_t i = 0; i < crs.size(); ++i) {
      auto& q = ctl[i].reports;
      while (!q.empty() && q.front().delivered_ms <= tc) {
        if (inbox.size() < lc::onboard::kMaxMessagesPerCycle) {
          inbox.push_back(q.front().msg);
        }
        q.pop_front();
      }
    }
    std::sort(inbox.begin(), inbox.end(), [](const auto& a, const auto& b) { return a.issued_ms < b.issued_ms; });
    if (prot) {
      lc::onboard::ProtectionInput in;
      in.now_ms = now;
      in.front_mm = cs.front_mm;
      in.speed_mm_s = cs.speed_mm_s;
      in.dwell = m == Method::kOnboardDwell && cs.standing.has_value() && !run.stops[*cs.standing].destination;
      in.departure_ms = in.dwell ? run.stops[*cs.standing].planned_departure_ms : 0;
      in.restrictions = s.profile;
      in.reports = inbox;
      const auto e = prot->Cycle(in);
      if (e != lc::onboard::ProtectionError::kNone) {
        throw InputError(std::string("on-board crossing function refused a cycle of service ") + s.service->id + ": " +
                         onboard::ToString(e));
      }
      ++stats.onboard_cycles;
      for (std::size_t i = 0; i < crs.size(); ++i) {
        const lc::onboard::CrossingEntry* en = prot->Find(crs[i].data.id);
        const bool req = en->state == lc::onboard::CrossingState::kRequested || en->state == lc::onboard::CrossingState::kCleared;
        if (req && !ctl[i].requested && tc < crs[i].arrival_ms) {
          StartController(ctl[i], crs[i], tt.comms, tc, crs[i].arrival_ms + 60'000.0);
        }
        cleared[i] = en->state == lc::onboard::CrossingState::kCleared || en->state == lc::onboard::CrossingState::kPassed ||
                     en->state == lc::onboard::CrossingState::kDone;
      }
    } else {
      ++stats.onboard_cycles;
      for (std::size_t i = 0; i < crs.size(); ++i) {
        if (rep_state[i] == St::kCleared || tc >= crs[i].arrival_ms) {
          continue;
        }
        const auto& cd = crs[i].data;
        if (cd.near_mm - cs.front_mm > lcp::crossing_lookahead_mm) {
          continue;
        }
        lc::EtaResult eta = lc::EarliestArrivalMs(cs.front_mm, cd.near_mm, cs.speed_mm_s, t.accel_max_mm_s2, s.profile);
        if (const auto k = NextStopBefore(run, tc, cs.front_mm, cd.near_mm)) {
          const auto dw = lc::EarliestArrivalAfterDwellMs(now, run.stops[*k].planned_departure_ms, run.stops[*k].front_mm,
                                                               cd.near_mm, t.accel_max_mm_s2, s.profile);
          if (dw.error == lc::EtaError::kNone && dw.eta_ms > eta.eta_ms) {
            eta = dw;
          }
        }
        if (eta.error != lc::EtaError::kNone) {
          throw InputError(std::string("earliest arrival refused: ") + lc::ToString(eta.error));
        }
        if (rep_state[i] == St::kApproaching && eta.eta_ms <= lc::SaturatingAddMs(cd.warning_time_ms, lead)) {
          rep_state[i] = St::kRequested;
          StartController(ctl[i], crs[i], tt.comms, tc, crs[i].arrival_ms + 60'000.0);
        }
        if (rep_state[i] == St::kRequested) {
          for (const auto& r : inbox) {
            if (r.crossing_id == cd.id && r.status == messages::CrossingStatus::kClosed &&
                now - r.issued_ms <= lcp::confirmation_max_age_ms &&
                r.warning_start_ms + cd.warning_time_ms <= lc::SaturatingAddMs(now, eta.eta_ms)) {
              rep_state[i] = St::kCleared;
            }
          }
        }
        cleared[i] = rep_state[i] == St::kCleared;
      }
    }
    for (std::size_t i = 0; i < crs.size(); ++i) {
      if (cleared[i] && cleared_at[i] < 0.0) {
        cleared_at[i] = tc;
      }
    }
    // the protection pattern of every crossing not yet cleared (REQ-LC-003, REQ-LC-015)
    for (std::size_t i = 0; i < crs.size(); ++i) {
      if (cleared[i] || brake_at[i] >= 0.0 || tc >= crs[i].arrival_ms) {
        continue;
      }
      const std::int64_t limit = crs[i].data.near_mm - lcp::protection_offset_mm;
      const double dist = static_cast<double>(limit - cs.front_mm);
      if (dist > s.pattern->Reach(static_cast<double>(cs.speed_mm_s))) {
        continue;
      }
      if (s.pattern->CrossingBrakes(cs.front_mm, cs.speed_mm_s, cs.standing.has_value(), limit, stats.pattern_evaluations)) {
        brake_at[i] = tc;
      }
    }
  }
  for (std::size_t i = 0; i < crs.size(); ++i) {
    Passage& p = out[first_passage + i];
    if (ctl[i].requested && ctl[i].ws_true_ms <= crs[i].arrival_ms) {
      p.warning_ms[mi] = crs[i].arrival_ms - ctl[i].ws_true_ms;
    } else {
      p.warning_ms[mi] = 0.0;  // never warned before the arrival (the pattern would have stopped the train)
      if (brake_at[i] < 0.0) {
        brake_at[i] = crs[i].arrival_ms;
      }
    }
    p.braked[mi] = brake_at[i] >= 0.0;
    p.brake_at_ms[mi] = brake_at[i];
    p.request_ms[mi] = ctl[i].requested ? ctl[i].request_ms : -1.0;
    p.cleared_ms[mi] = cleared_at[i];
  }
}

// GNSS-time pre-arming (design note §5): per departure, start times for the crossings up to the
// next stop; updates from position reports accepted while the crossing has not started.
void RunGnss(const ServiceSetup& s, const Timetable& tt, const Run& run, const std::vector<CrossingOfRun>& crs, Rng& rng,
             std::int64_t centre_clock_ms, std::int64_t train_clock_ms, std::vector<Passage>& out, std::size_t first_passage) {
  const TrainType& t = *s.train;
  const std::int64_t allowance = lcp::clock_allowance_ms;
  for (std::size_t k = 0; k + 1 < run.stops.size(); ++k) {
    const RunStop& a = run.stops[k];
    const RunStop& b = run.stops[k + 1];
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < crs.size(); ++i) {
      if (crs[i].data.near_mm > a.front_mm && crs[i].data.near_mm < b.front_mm) {
        idx.push_back(i);
      }
    }
    if (idx.empty()) {
      continue;
    }
    // stored start times (crossing clock readings), per basis
    std::vector<std::int64_t> st_ts(idx.size()), st_rx(idx.size());
    for (std::size_t j = 0; j < idx.size(); ++j) {
      const auto& cd = crs[idx[j]].data;
      const auto eta = lc::EarliestArrivalMs(a.front_mm, cd.near_mm, 0, t.accel_max_mm_s2, s.profile);
      if (eta.error != lc::EtaError::kNone || eta.eta_ms == lc::kEtaNeverMs) {
        throw InputError("GNSS start time: no earliest arrival for crossing " + crs[idx[j]].id);
      }
      st_ts[j] = st_rx[j] = a.planned_departure_ms + eta.eta_ms - cd.warning_time_ms - allowance;
    }
    // position reports every position_report_ms while running to b
    double tr = a.departure_ms + rng.Uniform(0.0, static_cast<double>(lcp::position_report_ms));
    for (; tr < b.arrival_ms; tr += static_cast<double>(lcp::position_report_ms)) {
      const CycleState cs = StateFor(run, tr);
      const double latency = static_cast<double>(rng.UniformMs(tt.comms.report_latency_ms));
      for (std::size_t j = 0; j < idx.size(); ++j) {
        const CrossingOfRun& c = crs[idx[j]];
        if (cs.front_mm >= c.data.near_mm) {
          continue;
        }
        const auto eta = lc::EarliestArrivalMs(cs.front_mm, c.data.near_mm, cs.speed_mm_s, t.accel_max_mm_s2, s.profile);
        if (eta.error != lc::EtaError::kNone || eta.eta_ms == lc::kEtaNeverMs) {
          continue;
        }
        const double delivered = tr + latency;
        // report time stamp (train's GNSS clock)
        const std::int64_t cand_ts = static_cast<std::int64_t>(std::floor(tr)) + train_clock_ms + eta.eta_ms - c.data.warning_time_ms - allowance;
        if (cand_ts > st_ts[j] && delivered < static_cast<double>(st_ts[j] - c.gnss_clock_ms)) {
          st_ts[j] = cand_ts;
        }
        // the centre's receive time
        const std::int64_t cand_rx = static_cast<std::int64_t>(std::floor(delivered)) + centre_clock_ms + eta.eta_ms - c.data.warning_time_ms - allowance;
        if (cand_rx > st_rx[j] && delivered < static_cast<double>(st_rx[j] - c.gnss_clock_ms)) {
          st_rx[j] = cand_rx;
        }
      }
    }
    for (std::size_t j = 0; j < idx.size(); ++j) {
      const CrossingOfRun& c = crs[idx[j]];
      Passage& p = out[first_passage + idx[j]];
      p.warning_ms[static_cast<std::size_t>(Method::kGnss)] = c.arrival_ms - static_cast<double>(st_ts[j] - c.gnss_clock_ms);
      p.warning_ms[static_cast<std::size_t>(Method::kGnssReceiveTime)] = c.arrival_ms - static_cast<double>(st_rx[j] - c.gnss_clock_ms);
    }
  }
}

}  // namespace

// @implements REQ-LC-017
StudyResult RunStudy(const StudyInputs& in, const std::function<void(std::size_t, std::size_t)>& progress) {
  const offline::Line& line = *in.line;
  const Timetable& tt = *in.timetable;
  const auto& trains = *in.trains;
  CheckTimetable(tt, line, trains);
  StudyResult r;
  // the fastest train of the timetable sets the treadle distances
  std::int64_t fastest = 0;
  for (const auto& sv : tt.services) {
    fastest = std::max(fastest, trains.at(sv.train).MaxSpeedMmS());
  }
  std::map<std::pair<std::string, std::string>, std::unique_ptr<PatternCheck>> patterns;
  for (std::size_t si = 0; si < tt.services.size(); ++si) {
    const Service& sv = tt.services[si];
    ServiceSetup s;
    s.service = &sv;
    s.train = &trains.at(sv.train);
    s.rl = &line.Running(sv.running_line);
    s.profile = PermittedProfile(*s.rl, s.train->MaxSpeedMmS());
    auto& pc = patterns[{sv.train, sv.running_line}];
    if (!pc) {
      pc = std::make_unique<PatternCheck>();
      auto created = br::PatternCalculator::Create(ToTrainData(*s.train), br::DefaultSupervisionParams());
      if (created.error != br::CreateError::kNone) {
        throw InputError(s.train->file + ": braking patterns refused the train: " + br::ToString(created.error));
      }
      pc->calc.emplace(std::move(*created.calculator));
      const auto pr = pc->calc->SetProfile(GradientProfile(*s.rl), PermittedProfile(*s.rl, 0));
      if (pr.verdict != br::ProfileVerdict::kAccept) {
        throw InputError(line.file + ": running line " + s.rl->id + ": braking profile refused: " + br::ToString(pr.verdict));
      }
      pc->baseline_limit_mm = s.rl->length_mm + 1'000'000;
      for (const auto& sl : s.rl->speed_limits) {
        const std::int64_t mid = (sl.section.begin_mm + sl.section.end_mm) / 2;
        pc->ceiling_mm_s.push_back(pc->Ceiling(mid, std::min(SpeedKmhToMmS(sl.kmh), s.train->MaxSpeedMmS())));
      }
    }
    s.pattern = pc.get();

    Rng rng(Mix(tt.seed, si));
    const CommsModel& cm = tt.comms;
    const std::int64_t centre_clock = rng.Symmetric(cm.gnss_clock_error_ms);
    const std::int64_t train_gnss_clock = rng.Symmetric(cm.gnss_clock_error_ms);
    const std::int64_t train_onboard_clock = rng.Symmetric(cm.onboard_clock_error_ms);
    Run run = SimulateService(s, tt, rng, centre_clock);
    // kind: calls at every station between origin and destination?
    std::size_t between = 0;
    for (const auto& st : s.rl->stations) {
      if (st.stop_mm > run.stops.front().front_mm && st.stop_mm < run.stops.back().front_mm) {
        ++between;
      }
    }
    const std::string kind = sv.stops.size() == between ? "stopping" : "fast";

    // crossings between origin and destination
    std::vector<CrossingOfRun> crs;
    const std::size_t first = r.passages.size();
    for (std::size_t li = 0; li < s.rl->level_crossings.size(); ++li) {
      const offline::LevelCrossing& lc = s.rl->level_crossings[li];
      if (lc.NearMm() <= run.stops.front().front_mm || lc.NearMm() >= run.stops.back().front_mm) {
        continue;
      }
      CrossingOfRun c;
      c.line_index = li;
      c.id = lc.id;
      c.data = lc::CrossingData{static_cast<std::uint32_t>(li + 1), lc.NearMm(), lc.FarMm(), lc.warning_time_ms};
      const auto arr = run.TimeAt(static_cast<double>(lc.NearMm()));
      if (!arr) {
        throw InputError("warning study: service " + sv.id + " never reaches crossing " + lc.id);
      }
      c.arrival_ms = *arr;
      c.uplink_ms = rng.UniformMs(cm.uplink_ms);
      c.downlink_ms = rng.UniformMs(cm.downlink_ms);
      c.travel_ms = rng.UniformMs(cm.barrier_travel_ms);
      c.onboard_clock_ms = rng.Symmetric(cm.onboard_clock_error_ms);
      c.gnss_clock_ms = rng.Symmetric(cm.gnss_clock_error_ms);
      crs.push_back(c);

      Passage p;
      p.service = sv.id;
      p.train = sv.train;
      p.kind = kind;
      p.running_line = sv.running_line;
      p.crossing = lc.id;
      p.near_mm = lc.NearMm();
      p.design_ms = lc.warning_time_ms;
      p.arrival_ms = c.arrival_ms;
      p.speed_kmh = run.StateAt(c.arrival_ms).v_mm_s * 0.0036;
      for (std::size_t k = 1; k + 1 < run.stops.size(); ++k) {
        if (run.stops[k].front_mm < lc.NearMm() && run.stops[k].front_mm >= lc.NearMm() - 1'000'000) {
          p.stop_in_approach = true;
        }
      }
      // (a) fixed treadles
      const auto fast_profile = PermittedProfile(*s.rl, fastest);
      p.treadle_distance_mm = TreadleDistanceMm(fast_profile, lc.NearMm(), lc.warning_time_ms);
      const std::int64_t treadle = lc.NearMm() - p.treadle_distance_mm;
      const double t_start =
          treadle <= run.stops.front().front_mm ? run.stops.front().departure_ms : run.TimeAt(static_cast<double>(treadle)).value();
      p.warning_ms[static_cast<std::size_t>(Method::kTreadle)] = c.arrival_ms - t_start;
      r.passages.push_back(p);
    }
    if (crs.size() > lc::kMaxCrossings) {
      throw InputError("warning study: service " + sv.id + " passes more than " + std::to_string(lc::kMaxCrossings) + " crossings");
    }
    // (b) on-board
    for (Method m : {Method::kOnboard, Method::kOnboardDwell, Method::kOnboardApproach}) {
      RunOnboard(m, s, tt, run, crs, train_onboard_clock, in.request_lead_ms >= 0 ? in.request_lead_ms : lcp::request_lead_ms,
                 r.passages, first, r);
    }
    // (c) GNSS time
    RunGnss(s, tt, run, crs, rng, centre_clock, train_gnss_clock, r.passages, first);
    r.runs.push_back(std::move(run));
    if (progress) {
      progress(si + 1, tt.services.size());
    }
  }
  return r;
}

}  // namespace railproof::lc::analysis
