// The line simulation's state and its steps (private to cpp/offline/sim/src). One step of
// simulation.hpp is carried out by these files, one job each:
//   simulation.cpp              setup (the units' configurations), the step, the event log and
//                               violation records
//   simulation_schedule.cpp     scheduled commands (through the wayside unit) and fault windows
//   simulation_radio.cpp        frames between the units through the channel, the ground cycle,
//                               the crossings' equipment
//   simulation_trains.cpp       entry and exit, the on-board unit's cycle, the driver, the true
//                               motion and the sensors
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

#include "railproof/generated/br_params.hpp"
#include "railproof/generated/mb_params.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/sim/channel.hpp"
#include "railproof/sim/ground_line.hpp"
#include "railproof/sim/sensors.hpp"
#include "railproof/sim/simulation.hpp"
#include "railproof/sim/wheel_rail_train.hpp"
#include "railproof/units/onboard_unit.hpp"
#include "railproof/units/wayside_unit.hpp"

namespace railproof::sim {

namespace mbp = params::mb;
using Json = nlohmann::ordered_json;

namespace internal {

constexpr auto kGroundId = static_cast<std::uint16_t>(params::tg::ground_id);
// The driver: aims this far below the indicated permitted speed, and brakes for a station
// stop with this share of the train's service deceleration, creeping the last metres.
constexpr double kDrivingMarginMps = 2.0 / 3.6;
constexpr double kStationDecelShare = 0.7;
constexpr double kDriverResponseS = 1.0;  // closes a speed difference at (difference / this)
// Traction and brakes change the applied acceleration at most this fast (m/s^3): a brake
// builds up within the free-running times of the train types' patterns (0.5 s and more).
constexpr double kApplyRateMps3 = 1.5;
constexpr double kCreepMps = 0.5;
constexpr double kStopWindowM = 2.0;
// A train leaves the line when it stands with no stop left before an END_OF_TRACK limit (or
// a system boundary no neighbour accepts) within this distance of its supervised front.
constexpr double kExitWindowM = 60.0;
// A train standing this long with its odometry stopped is re-fixed (the unit restarted).
constexpr std::int64_t kRefixAfterMs = 30000;
// The barriers of a level crossing take this long from the command to the "down" detection
// (below the controller's barrier_timeout_ms, params::lc).
constexpr std::int64_t kBarrierTravelMs = 6000;

inline double Round(double v, double unit) { return std::round(v / unit) * unit; }
inline double R2(double v) { return Round(v, 0.01); }
inline double R1(double v) { return Round(v, 0.1); }
inline std::int64_t ToMm(double m) { return static_cast<std::int64_t>(std::llround(m * 1000.0)); }
inline double ToM(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }
inline double ToS(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }

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

// The line as the on-board unit's track database holds it (spans of units::LineData).
struct OnboardLine {
  std::vector<std::int64_t> blocks_mm;
  std::vector<core::GradientSegment> gradients;
  std::vector<units::BaliseEntry> balises;             // id = index + 1 in the running line
  std::vector<lc::CrossingData> crossings;             // id = index + 1 in the running line
  std::vector<ra::OdometrySection> sections;
};

// One wayside unit of the running line (several with the scenario's wayside_splits): the part
// of the line it holds in its own chainage (from origin_mm), its crossings (indices into
// Impl::crossings) and the neighbour messages of its last ground cycle.
struct WaysideRt {
  RunningLine line;
  GroundLine gl;
  std::unique_ptr<units::WaysideUnit> unit;
  std::int64_t origin_mm = 0;
  std::uint16_t radio_id = 0;
  std::vector<lc::CrossingData> crossings;
  std::vector<std::size_t> crossing_index;
  std::vector<units::HandoverRequest> requests;    // to the next unit
  std::vector<units::HandoverResponse> responses;  // to the previous unit
};

// The brake the train's equipment applies (from the unit's demand and the driver).
enum class Brake : std::uint8_t { kNone, kDriver, kService, kEmergency };

struct TrainRt {
  TrainSpec spec;
  const TrainType* type = nullptr;
  std::int64_t length_mm = 0;
  Phase phase = Phase::kPending;
  Motion motion;  // the true front and speed
  // the true motion where it is not the point mass's: the wheel-rail vehicle (low adhesion)
  std::unique_ptr<WheelRailTrain> wheel_rail;
  AxleState axle_state = AxleState::kRolling;  // its measured axle's, as last logged
  double previous_front_m = 0.0;  // before the last step
  // the on-board unit, its track database (per train type) and its inputs of the next cycle
  std::unique_ptr<units::OnboardUnit> unit;
  std::unique_ptr<SensorModel> sensors;
  std::vector<core::RestrictionSegment> limits;  // the line's, capped at the type's maximum
  ra::CycleInput next_sensors{};
  std::optional<std::uint32_t> next_balise;
  std::vector<std::vector<std::uint8_t>> inbox;  // frames received for the next cycle
  std::vector<std::vector<std::uint8_t>> handover_inbox;  // those of the next wayside unit
  std::size_t next_balise_index = 0;             // the next balise the true front reaches
  std::array<std::uint8_t, tg::kKeyBytes> key{};
  // driver and brake equipment
  br::DriverInputs driver{};
  bool eb_hold = false;  // emergency brake applied: held until standstill
  double applied_mps2 = 0.0;  // traction minus brake as the equipment applies it
  Brake brake = Brake::kNone;
  std::size_t next_stop = 0;
  std::int64_t dwell_until_ms = 0;
  std::int64_t standing_at_end_ms = 0;
  bool radio_blocked = false;
  bool position_lost = false;
  bool was_position_lost = false;
  std::int64_t odometry_stopped_ms = 0;  // standing with the odometry stopped (not at start-up)
  // ground view
  bool abnormal = false;
  messages::Obstruction ground_kind = messages::Obstruction::kNone;
  // statistics
  std::int64_t entered_ms = -1;
  std::int64_t exited_ms = -1;
  double start_m = 0.0;
  double max_speed = 0.0;
  std::uint32_t emergency_brakes = 0;
  std::uint32_t service_brakes = 0;
  double max_lead_m = 0.0;     // most the unit's nominal front led the true front
  double max_outside_m = 0.0;  // most the true front lay outside the unit's envelope
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
  [[nodiscard]] const units::OnboardOutputs* Out() const { return unit ? &unit->Outputs() : nullptr; }
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

// A level crossing's equipment (lights and barriers) as the wayside unit drives it, and the
// true state the crossing invariants read.
struct CrossingRt {
  std::uint32_t id = 0;
  std::string name;
  std::int64_t near_mm = 0;
  std::int64_t far_mm = 0;
  std::int64_t warning_time_ms = 0;
  std::optional<std::int64_t> lights_since;    // lights on since
  std::optional<std::int64_t> command_since;   // barriers commanded down since
  bool down = false;                           // barriers detected down
  std::uint64_t warnings = 0;
  std::uint64_t passages = 0;
  double shortest_warning_s = std::numeric_limits<double>::infinity();
  std::set<std::uint16_t> occupying;
};

}  // namespace internal

using namespace internal;  // NOLINT(google-build-using-namespace): the private header of this module

struct Simulation::Impl {
  Scenario sc;
  Line line;
  std::vector<TrainType> types;
  const RunningLine* rl = nullptr;
  GroundLine gl;
  OnboardLine obl;
  // the wayside units along the running line, and the first (the only one without splits):
  // the one that takes the scenario's commands
  std::vector<WaysideRt> waysides;
  units::WaysideUnit* wayside = nullptr;
  std::vector<units::RadioArea> radio_areas;  // the on-board units' (none with one unit)
  std::uint64_t handovers = 0;                // trains released to the next unit
  Channel channel;
  std::vector<std::unique_ptr<TrainRt>> trains;
  std::vector<FaultRt> faults;
  std::vector<CrossingRt> crossings;
  std::vector<std::string> train_data_findings;
  std::vector<units::CrossingSensors> crossing_inputs;
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
  std::map<std::string, std::uint64_t> brake_reasons;  // on-board demands other than NONE, by reason
  std::uint64_t ground_cycles = 0;
  std::uint64_t telegrams_issued = 0;
  std::uint64_t events = 0;
  std::uint64_t abnormal_events = 0;
  std::map<std::uint32_t, mb::wayside::PossessionState> possession_state;
  // gap measurement
  std::size_t gap_n = 0;
  double gap_sum = 0.0;
  double gap_sq = 0.0;
  double gap_min = std::numeric_limits<double>::infinity();
  double gap_max = -std::numeric_limits<double>::infinity();
  double gap_vl = 0.0;
  double gap_vf = 0.0;
  // per sample: t s, gap m, the follower's speed km/h and permitted speed km/h, then the gap's
  // parts (m): its limit to its supervised front, the leader's rear to its limit, its supervised
  // front to its true front
  std::vector<std::array<double, 7>> gap_series;
  // log
  const RunOptions* opts = nullptr;
  bool first_event = true;

  Impl(Scenario s, Line l, std::vector<TrainType> t)
      : sc(std::move(s)), line(std::move(l)), types(std::move(t)), channel(ChannelConfig{}, 0) {}

  // ---- setup, the step, the event log and violation records (simulation.cpp)
  void Setup();
  // The train type a scenario train's on-board unit carries: the one it names (train_type),
  // else the one of its length; an input error if there is none, several, or the lengths differ.
  [[nodiscard]] const TrainType* TrainTypeOf(const TrainSpec& spec) const;
  void SetupOnboardLine();
  void SetupWayside();
  // The wayside units of the scenario's splits (one without): their lines, crossings, radio
  // areas; InputError naming the split entry.
  void SplitWayside();
  // The unit protecting a front (the last whose previous boundary lies at or before it), as the
  // on-board unit picks its first link; in a handover zone the unit before hands it over.
  [[nodiscard]] std::size_t WaysideAt(std::int64_t front_mm) const;
  // The largest authority a wayside unit holding the train protects for it (line chainage).
  [[nodiscard]] std::optional<std::int64_t> ProtectedAuthority(std::uint16_t train) const;
  [[nodiscard]] const mb::wayside::Ground& Ground() const { return wayside->Ground(); }
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

  // ---- frames between the units, the ground cycle, the crossings (simulation_radio.cpp)
  // Frames due now: a train's telegram to the wayside unit, the unit's to the train's inbox.
  void DeliverFrames();
  void GroundCycle();
  void WaysideOutput(std::size_t k, const units::CycleOutput& out, const std::vector<bool>& before, Json& cyc);
  void GroundState(const std::vector<bool>& before);
  void CrossingEquipment(const units::CycleOutput& out);

  // ---- entry and exit, the on-board unit, the driver, motion and sensors (simulation_trains.cpp)
  // Length-weighted mean gradient (per mille) under the train [rear, front]: gravity, which
  // the IMU also feels.
  [[nodiscard]] double MeanGradient(double rear_m, double front_m) const;
  // The gradient term of the motion: MeanGradient plus the mean curve resistance under the
  // train (dynamics.hpp, ASM-034).
  [[nodiscard]] double MotionGradient(double rear_m, double front_m) const;
  bool EntryClear(const TrainRt& n) const;
  void CreateUnit(TrainRt& t, std::int64_t front_mm);
  void Enter(TrainRt& t);
  void Exit(TrainRt& t, const std::string& why);
  // The sensor data of the cycle that ends at `end_ms` for a motion from `start` with `accel`
  // (and the measured axle's own motion on the wheel-rail vehicle).
  void Sense(TrainRt& t, std::int64_t end_ms, const Motion& start, double accel,
             const std::optional<AxleMotion>& axle = std::nullopt);
  // The true motion of one step under the equipment's applied acceleration `a` of the point
  // mass: the point mass's, or the wheel-rail vehicle's (its achieved acceleration returned).
  double Move(TrainRt& t, double a, double dt, std::optional<AxleMotion>& axle);
  void OnboardCycle(TrainRt& t);
  Control Drive(TrainRt& t, const units::OnboardOutputs& o, double dt);
  double Apply(TrainRt& t, const Control& c, double gradient, double dt) const;
  void EnterTrains();
  void MoveTrains();

  // ---- the safety invariants (simulation_invariants.cpp)
  void CheckInvariants();
  void CheckCrossings(const std::vector<const TrainRt*>& on);

  // ---- measurements (simulation_summary.cpp)
  void Measure();
};

}  // namespace railproof::sim
