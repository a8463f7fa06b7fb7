// The line simulation's state and its steps (private to cpp/offline/sim/src). One step of
// simulation.hpp is carried out by these files, one job each:
//   simulation.cpp              setup, the step, the event log and violation records
//   simulation_schedule.cpp     scheduled commands and fault windows
//   simulation_radio.cpp        telegrams between the trains and the ground, the ground cycle
//   simulation_trains.cpp       entry and exit, driving, dynamics and odometry
//   simulation_invariants.cpp   the safety invariants
//   simulation_summary.cpp      measurements, the gap and the summary (Simulation::Gap, ::Summary)
//   simulation_diagram.cpp      the time-distance diagram (Simulation::Svg)
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/generated/mb_params.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/mb/onboard/authority.hpp"
#include "railproof/mb/wayside/ground.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/sim/channel.hpp"
#include "railproof/sim/ground_line.hpp"
#include "railproof/sim/simulation.hpp"
#include "railproof/tg/endpoint.hpp"

namespace railproof::sim {

namespace mbp = params::mb;
using Json = nlohmann::ordered_json;

namespace internal {

constexpr auto kGroundId = static_cast<std::uint16_t>(params::tg::ground_id);
// Station stops: comfortable deceleration as a share of the service deceleration, and
// the creep speed / stop window of the stopping controller.
constexpr double kStationDecelShare = 0.7;
constexpr double kCreepMps = 0.5;
constexpr double kStopWindowM = 1.0;
// A train leaves the line (is removed from the ground) when it stands within this
// distance of an END_OF_TRACK limit's service-curve origin and has no stop left.
constexpr double kExitWindowM = 3.0;
// Odometry under-reads by up to this share of the correction rate (so the extended range
// always covers the true range, and the reported front never moves backwards).
constexpr double kOdometryErrorShare = 0.9;

inline double Round(double v, double unit) { return std::round(v / unit) * unit; }
inline double R2(double v) { return Round(v, 0.01); }
inline double R1(double v) { return Round(v, 0.1); }
inline std::int64_t ToMm(double m) { return static_cast<std::int64_t>(std::llround(m * 1000.0)); }
inline double ToM(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }
inline double ToS(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }
inline std::uint32_t Clock32(std::int64_t ms) { return static_cast<std::uint32_t>(static_cast<std::uint64_t>(ms) & 0xFFFFFFFFULL); }

inline const char* VerdictName(tg::RejectReason r) { return tg::ToString(r); }

enum class Phase : std::uint8_t { kPending, kStanding, kRunning, kDwelling, kExited };
inline const char* ToString(Phase p) {
  switch (p) {
    case Phase::kPending: return "pending";
    case Phase::kStanding: return "standing";
    case Phase::kRunning: return "running";
    case Phase::kDwelling: return "dwelling";
    case Phase::kExited: return "exited";
  }
  return "invalid";
}

struct Sample {
  std::int64_t t_ms;
  double front_m;
  double rear_m;
  double limit_m;  // NaN: no usable authority
};

struct TrainRt {
  TrainSpec spec;
  std::int64_t length_mm = 0;
  Phase phase = Phase::kPending;
  Motion motion;
  // on-board odometry
  double est_front_m = 0.0;
  double balise_est_m = 0.0;     // estimated position at the last fix
  double balise_true_m = 0.0;    // true position at the last fix
  double odo_error = 0.0;        // relative (<= 0) in the current balise segment
  std::int64_t last_balise_mm = 0;
  std::size_t next_balise = 0;
  // radio
  std::unique_ptr<tg::LinkKey> key;
  tg::Endpoint train_ep;
  tg::Endpoint ground_ep;
  bool link_up = false;
  // on board
  mb::onboard::AuthorityReceiver auth{mb::onboard::DefaultAuthorityConfig()};
  mb::onboard::SpeedRestrictionStore tsr;
  messages::Obstruction limit_kind = messages::Obstruction::kNone;
  bool eb = false;  // emergency brake applied, held until standstill and a usable authority
  std::size_t next_stop = 0;
  std::int64_t dwell_until_ms = 0;
  std::int64_t next_report_ms = 0;
  bool radio_blocked = false;
  bool position_lost = false;
  // ground view
  bool abnormal = false;
  std::optional<std::int64_t> ground_limit;
  messages::Obstruction ground_kind = messages::Obstruction::kNone;
  // statistics
  std::int64_t entered_ms = -1;
  std::int64_t exited_ms = -1;
  double start_m = 0.0;
  double max_speed = 0.0;
  std::uint32_t emergency_brakes = 0;
  std::size_t stops_made = 0;
  std::int64_t standstill_no_authority_ms = 0;
  std::uint64_t reports_sent = 0;
  std::uint64_t reports_accepted = 0;
  bool deferral_logged = false;
  std::vector<Sample> samples;

  [[nodiscard]] bool OnLine() const { return phase != Phase::kPending && phase != Phase::kExited; }
  [[nodiscard]] double Rear() const { return motion.position - spec.performance.length_m; }
  [[nodiscard]] std::int64_t FrontMm() const { return ToMm(motion.position); }
  [[nodiscard]] std::int64_t RearMm() const { return FrontMm() - length_mm; }
};

struct CheckCount {
  std::uint64_t checks = 0;
  std::uint64_t violations = 0;       // episodes
  std::uint64_t violation_steps = 0;  // steps during which a violation persisted
};

inline std::string Fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

struct FaultRt {
  FaultSpec spec;
  bool started = false;
  bool ended = false;
  std::uint32_t possession_id = 0;
  std::uint32_t restriction_id = 0;
  bool free_pending = false;
  // measured
  std::optional<std::int64_t> abnormal_at;
  std::optional<std::int64_t> standstill_at;
  std::optional<std::int64_t> tracked_again_at;
  std::optional<std::int64_t> moving_again_at;
  std::optional<std::int64_t> active_at;
  std::optional<std::int64_t> freed_at;
  std::string status;
};

struct DirStats {
  std::uint64_t accepted = 0;
  std::map<std::string, std::uint64_t> rejected;
  std::uint64_t malformed = 0;
};

}  // namespace internal

using namespace internal;  // NOLINT(google-build-using-namespace): the private header of this module

struct Simulation::Impl {
  Scenario sc;
  Line line;
  const RunningLine* rl = nullptr;
  GroundLine gl;
  std::unique_ptr<mb::wayside::Ground> ground;
  Channel channel;
  Prng odo_prng;
  std::vector<std::unique_ptr<TrainRt>> trains;
  std::vector<FaultRt> faults;
  std::vector<bool> points_running_reverse;  // position of the running line's route
  std::vector<bool> points_reverse;
  std::int64_t now = 0;
  std::vector<Violation> violations;
  std::map<std::string, CheckCount> checks;
  std::set<std::string> active_prev;  // violation keys of the previous check
  std::set<std::string> active_now;
  std::set<std::string> exercised;
  DirStats up;
  DirStats down;
  std::map<std::string, std::uint64_t> report_status;
  std::map<std::string, std::uint64_t> verdicts;
  std::uint64_t ground_cycles = 0;
  std::uint64_t telegrams_issued = 0;
  std::uint64_t events = 0;
  std::uint64_t abnormal_events = 0;
  std::map<std::uint32_t, mb::wayside::PossessionState> possession_state;
  // gap measurement
  std::size_t gap_n = 0;
  double gap_sum = 0.0;
  double gap_min = std::numeric_limits<double>::infinity();
  double gap_max = -std::numeric_limits<double>::infinity();
  double gap_vl = 0.0;
  double gap_vf = 0.0;
  // log
  const RunOptions* opts = nullptr;
  bool first_event = true;

  Impl(Scenario s, Line l)
      : sc(std::move(s)), line(std::move(l)), channel(ChannelConfig{}, 0), odo_prng(0) {}

  // ---- setup, the step, the event log and violation records (simulation.cpp)
  void Setup();
  // Writes one event to the log (if any), stamped with the time.
  void Emit(Json ev);
  // The log takes every accepted report and stop-limit telegram too.
  [[nodiscard]] bool Full() const { return opts != nullptr && opts->log != nullptr && opts->log_full; }
  // Records a violation of `req`. A condition that persists over several steps (same
  // `key`) is one violation episode: recorded at its onset, counted once; its steps are
  // counted in violation_steps.
  void Violate(const std::string& req, const std::string& key, const std::string& detail);
  TrainRt* Find(std::uint16_t id);
  [[nodiscard]] const TrainRt* Find(std::uint16_t id) const;
  // The trains on the line (entered and not left), in the scenario's order.
  [[nodiscard]] std::vector<TrainRt*> TrainsOnLine() const;
  bool Step();

  // ---- scheduled commands and fault windows (simulation_schedule.cpp)
  void ApplySchedule();
  [[nodiscard]] std::int64_t SidingRoute(const FaultSpec& s) const;

  // ---- telegrams between the trains and the ground, the ground cycle (simulation_radio.cpp)
  // Frames due now: a position report to the ground, a stop-limit telegram to the train.
  void DeliverFrames();
  // The payload of a frame its endpoint accepts (counted per direction); a rejected frame is
  // counted and logged (nullopt). A train's endpoint also updates the train's link state.
  std::optional<std::span<const std::uint8_t>> Accept(tg::Endpoint& ep, TrainRt& t, const Frame& f, bool uplink,
                                                      std::span<std::uint8_t> buffer);
  void OnPositionReport(TrainRt& t, const Frame& f, std::span<const std::uint8_t> payload);
  void OnStopLimit(TrainRt& t, std::span<const std::uint8_t> payload);
  [[nodiscard]] std::int64_t ToFront(const messages::PositionReport& r) const;
  // Canonical block + offset: the block holding front - 1 (block 0 for front 0).
  [[nodiscard]] std::pair<std::uint32_t, std::int64_t> Locate(std::int64_t front_mm) const;
  void GroundCycle();
  void SendReports();

  // ---- entry and exit, driving, dynamics and odometry (simulation_trains.cpp)
  // Length-weighted mean gradient (per mille) under the train [rear, front] (its physics).
  [[nodiscard]] double MeanGradient(double rear_m, double front_m) const;
  // Steepest falling gradient (per mille, >= 0) over [a, b].
  [[nodiscard]] double SteepestFall(double a_m, double b_m) const;
  [[nodiscard]] std::int64_t CorrectionMm(const TrainRt& t) const;
  bool EntryClear(const TrainRt& n) const;
  void Enter(TrainRt& t);
  void Exit(TrainRt& t, const std::string& why);
  // Highest speed the line's speed limits and the held speed restrictions allow at the
  // next step (braking curves to lower limits ahead with deceleration b).
  [[nodiscard]] double LineSpeed(const TrainRt& t, double safe_front, double rear, double b, double look) const;
  Control Drive(TrainRt& t, double dt);
  void EnterTrains();
  void MoveTrains();

  // ---- the safety invariants (simulation_invariants.cpp)
  void CheckInvariants();

  // ---- measurements (simulation_summary.cpp)
  void Measure();
};

}  // namespace railproof::sim
