// Wheel-rail simulator (offline): a Box2D vehicle in the vertical plane running on a rail
// profile, with a slip-dependent adhesion law per axle, traction and brake from a driver
// schedule, and the on-board sensor streams of the odometry (spec/design/ra.md §2):
// one ra::CycleInput per 100 ms cycle (TG sample, 10 IMU samples, balise fix), the
// truth per cycle and the slip/slide events found in the truth. Scenario format:
// spec/wheelrail/README.md (schema "railproof/wheelrail-scenario/1").
//
// Model (ASM-027; the simulator is a test input generator, not a validated vehicle model):
// - Box2D world in the vertical plane (x along the unrolled track, y up, gravity -G):
//   car body, two bogies, four wheelsets (circles); primary (bogie-wheelset) and secondary
//   (body-bogie) suspension are b2WheelJoints with stiffness and damping. The rail is a
//   chain shape following the vertical alignment (gradients up to +-35 permille joined by
//   circular vertical curves), built in pieces around the vehicle with a moving world
//   origin so that Box2D's single-precision coordinates stay small.
// - Contact friction is 0: per axle the creep force F = mu(creep, v, rail) * N is applied
//   tangent to the rail, N from the contact's normal impulse of the previous step. The
//   wheelset spin is integrated outside Box2D in double (linearly implicit Euler in
//   sub-steps, stable for the stiff creep slope); a braked wheelset at standstill is held by
//   static friction (Box2D contact friction switched on only in that state).
// - Horizontal curvature and cant are not in the 2-D world: they enter the IMU as yaw rate
//   v*kappa, centripetal acceleration v^2*kappa and roll (cant, with transition curves
//   giving the roll rate).
// - Sensors: IMU (10 ms, bias + white noise + drift, seeded std::mt19937_64), TG (90 teeth
//   on one axle, cumulative count and latest edge time), balise fixes, injected faults.
//
// Offline module: allocates, throws offline::InputError "<file>: <entry>: <reason>" on bad input.
// Deterministic: the same scenario (seed included) gives identical streams.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/ra/odometry.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::ra::analysis {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

inline constexpr std::string_view kWheelRailSchema = "railproof/wheelrail-scenario/1";
inline constexpr int kWheelRailAxles = 4;
inline constexpr double kWheelRailGravity = 9.80665;      // physics of the simulator (m/s^2)
inline constexpr double kMaxGradientPermille = 35.0;      // D1 §3 item 9
inline constexpr double kCantBaseMm = 1500.0;             // cant measured over the contact spacing

// ---- adhesion law (ASM-027) ---------------------------------------------------------------
struct AdhesionLaw {
  double wet_factor = 0.55;   // peak adhesion of wet rail / dry rail
  double peak_creep = 0.01;   // creep at the peak (linear rise from 0)
  double tail_creep = 0.20;   // creep at which the curve has fallen to tail_ratio of the peak
  double tail_ratio = 0.70;   // constant beyond tail_creep (a locked wheel slides at it)
  double creep_floor_mps = 0.5;  // creep = (omega r - v) / max(|v|, floor)
};

// Curtius-Kniffler adhesion limit of dry rail: 7.5 / (v_kmh + 44) + 0.161 (|v| in km/h).
[[nodiscard]] double CurtiusKnifflerMu(double v_kmh);
// Normalised creep curve mu/mu_peak, odd in creep: linear to 1 at peak_creep, linear down
// to tail_ratio at tail_creep, constant beyond.
[[nodiscard]] double CreepCurve(double creep, const AdhesionLaw& law);
// Creep of a wheel: (wheel_speed - v) / max(|v|, creep_floor_mps); wheel_speed = omega*r.
[[nodiscard]] double CreepOf(double wheel_speed_mps, double v_mps, const AdhesionLaw& law);
// Signed adhesion coefficient: CurtiusKnifflerMu(|v|) * rail_factor * CreepCurve(creep).
// rail_factor = wet_factor (wet) or 1 (dry), times the factor of an adhesion zone.
[[nodiscard]] double AdhesionCoefficient(double creep, double v_mps, double rail_factor,
                                         const AdhesionLaw& law);

// ---- scenario -------------------------------------------------------------------------------
// Vertical alignment: the gradient `permille` (+ rising in the running direction) holds from
// `from_m` to the next point; consecutive gradients are joined by a circular vertical curve
// of radius vertical_curve_radius_m centred on the change point (length R*|dg|/1000).
struct GradientPoint {
  double from_m = 0.0;
  double permille = 0.0;
  std::string entry;  // path in the file, for messages
};

struct VerticalAlignment {
  double begin_m = 0.0;  // line chainage covered by the scenario [begin, end)
  double end_m = 0.0;
  double vertical_curve_radius_m = 3000.0;
  std::vector<GradientPoint> gradients;  // sorted, first from_m == begin_m
};

// Horizontal curve from begin_m to end_m (including both transitions): curvature and cant
// ramp linearly over transition_m at each end. radius_m is signed: + curves to the left.
struct HorizontalCurve {
  double begin_m = 0.0;
  double end_m = 0.0;
  double radius_m = 0.0;
  double cant_mm = 0.0;       // >= 0, towards the inside of the curve
  double transition_m = 0.0;  // clothoid length at each end
  std::string entry;
};

// Reduced adhesion (leaves, contamination): factor on the rail's adhesion in [begin, end),
// optionally only in a time window [from_s, to_s).
struct AdhesionZone {
  double begin_m = 0.0;
  double end_m = 0.0;
  double factor = 1.0;
  std::optional<double> from_s;
  std::optional<double> to_s;
  std::string note;
  std::string entry;
};

struct RailCondition {
  bool wet = false;
  std::vector<AdhesionZone> zones;
};

struct BalisePoint {
  std::string id;
  double position_m = 0.0;
};

// One car: body, two bogies, four wheelsets (axle 0 leads). Defaults: a 35 t motor car
// (24 t body, 2 x 3 t bogie frames, 4 x 1.3 t wheelsets; rotating mass 4 J / r^2 = 3.2 t).
struct VehicleSpec {
  double length_m = 20.0;           // over couplers; front = leading axle + overhang
  double bogie_centres_m = 14.0;    // distance between bogie pivots
  double axle_spacing_m = 2.5;      // wheelbase of a bogie
  double wheel_diameter_m = 0.86;
  double body_mass_kg = 24000.0;
  double bogie_mass_kg = 3000.0;      // frame, without wheelsets
  double wheelset_mass_kg = 1300.0;
  double wheelset_inertia_kgm2 = 150.0;  // incl. gear and motor rotor reflected to the axle
  double body_cog_height_m = 1.8;        // above rail top
  double primary_hz = 5.0;               // vertical natural frequencies and damping ratios
  double primary_damping = 0.1;
  double secondary_hz = 1.0;
  double secondary_damping = 0.2;
  double roll_coefficient = 0.1;         // body roll per unit uncompensated lateral accel / G
  // Defaults: the leading bogie motored; full notch gives about 0.88 m/s^2 and the full
  // service brake about 1.35 m/s^2 (D1 §3 item 9: 0.58-0.92 and 0.97-1.4 m/s^2).
  std::array<bool, kWheelRailAxles> motored{{true, true, false, false}};
  double max_traction_force_n = 17000.0;  // per motored axle at the rail, full notch
  double max_power_w = 350000.0;          // per motored axle
  double max_brake_force_n = 13000.0;     // per axle at the rail, full service brake
  double resistance_a_n = 600.0;          // running resistance a + b v + c v^2 (v in m/s)
  double resistance_b_ns_m = 20.0;
  double resistance_c_ns2_m2 = 5.0;
  double max_speed_kmh = 120.0;           // traction cuts off above it
};

// Driver/controller schedule: from t_s the demands move linearly to the given values over
// ramp_s. hold_kmh: from t_s a speed controller on the true speed chooses traction/brake
// within the given values (traction and brake are then upper limits).
struct DriverCommand {
  double t_s = 0.0;
  double traction = 0.0;  // notch fraction 0..1
  double brake = 0.0;     // service brake demand 0..1
  double ramp_s = 1.0;
  std::optional<double> hold_kmh;
  std::string entry;
};

// Wheel-slip/slide protection and traction anti-slip (optional, off by default so slips and
// slides can develop): per axle the torque is reduced while |creep| > creep_threshold.
struct SlipControlSpec {
  bool enabled = false;
  double creep_threshold = 0.05;
  double reduce_per_s = 3.0;   // torque factor decrease rate while above the threshold
  double recover_per_s = 0.5;  // increase rate below half the threshold
  double min_factor = 0.2;
};

// IMU error model (D1 §3 item 6). Per axis: constant bias uniform in +-bias, white noise
// (standard deviation per 10 ms sample), random-walk drift (standard deviation growth per
// sqrt(s)). Defaults split the D1 error budget: accel 0.015 m/s^2 after 3 s averaging,
// rate 0.0025 deg/s (one tenth of 0.025 deg/s; ASM-024 reference configuration).
struct ImuErrorSpec {
  double accel_bias_mps2 = 0.007;
  double accel_noise_mps2 = 0.04;
  double accel_drift_mps2_per_sqrt_s = 0.00004;
  double rate_bias_deg_s = 0.00125;
  double rate_noise_deg_s = 0.012;
  double rate_drift_deg_s_per_sqrt_s = 0.000005;
  bool enabled = true;  // false: ideal IMU (tests)
};

struct TgSpec {
  int axle = 1;                 // 0-based axle carrying the TG (default: trailing axle of bogie 1)
  int teeth = 90;
  double calibration_error_ppm = 0.0;  // odometry's nominal diameter = true * (1 + e)
};

enum class SensorFaultKind : std::uint8_t {
  kTgDropout,      // TG power loss: count reset to 0 at from_s, no pulses until to_s, then counts from 0
  kTgStuck,        // count frozen in [from, to) (pulses lost), not visible to the validation
  kTgBurst,        // interference: `pulses` extra pulses in the cycle at from_s (implausible rate)
  kTgEdgeInvalid,  // latest edge time reported after the sample time in [from, to)
  kImuNan,         // NaN in the IMU samples of [from, to)
  kImuGap,         // only `samples` IMU samples delivered per cycle in [from, to)
  kImuTimestamps,  // two IMU samples swapped in time (non-monotonic) in [from, to)
  kImuOutOfRange,  // a shock sample of `value` m/s^2 on ax in [from, to)
  kCycleTime,      // cycle time stamp repeated (non-monotonic) in [from, to)
};
const char* ToString(SensorFaultKind k);

struct SensorFault {
  SensorFaultKind kind = SensorFaultKind::kImuNan;
  double from_s = 0.0;
  double to_s = 0.0;
  int samples = 7;        // imu_gap: delivered samples per cycle (0..9)
  std::int64_t pulses = 5000;  // tg_burst: extra pulses
  double value = 80.0;    // imu_out_of_range: shock value (m/s^2)
  std::string note;
  std::string entry;
};

// Slip/slide events from the truth: |creep| > event_creep for at least event_min_s.
struct TruthSpec {
  double event_creep = 0.02;
  double event_min_s = 0.2;
};

// Optional odometry configuration of the scenario (used by the study / OdometryConfigOf).
struct ScenarioOdometry {
  std::optional<std::int64_t> detect_threshold_mm_s2;  // Ta of the line (default parameter 340)
  std::optional<std::int64_t> max_compensation_ms;     // per section default (parameter 20 s)
  std::optional<int> start_points;                     // 1 or 2 (parameter 2)
  std::optional<std::int64_t> rate_error_udeg_s;       // error model's IMU rate error (parameter 2500)
};

// How a scenario begins for the odometry (REQ-RA-015: the odometry trusts its TG history
// only after a warm-up at standstill):
//   kAtRest   the train stands at t = 0 (initial speed 0); the odometry starts with the run
//   kLeadIn   the train runs at the initial speed at t = 0; the simulator first runs a lead-in
//             from rest (LeadInSpec), so that the odometry has warmed up at standstill and
//             run with the train up to the scenario's start
//   kInMotion the odometry starts with the run, in motion: the start-up case, which the
//             odometry must treat as a start in motion (no valid position)
enum class ScenarioStart : std::uint8_t { kAtRest, kLeadIn, kInMotion };
const char* ToString(ScenarioStart s);  // "at_rest", "lead_in", "in_motion"

// The lead-in of a kLeadIn scenario: standstill (brake applied) for standstill_s, then a
// speed ramp at accel_mps2 up to the initial speed, held for hold_s; the train starts at
// rest so far back that the front reaches initial_front_m at the end, where the scenario's
// t = 0 begins (the first cycle boundary at or after it). The first gradient of the
// alignment is extended backwards over the lead-in; its rail has no adhesion zone.
struct LeadInSpec {
  double standstill_s = 5.0;  // longer than the odometry's warm-up (4 s)
  double accel_mps2 = 0.3;
  double hold_s = 15.0;
  double traction_cap = 0.6;  // notch fractions of the speed controller
  double brake_cap = 0.6;
};
[[nodiscard]] double LeadInDistanceM(const LeadInSpec& lead, double speed_mps);

struct WheelRailScenario {
  std::string file;
  std::string name;
  std::string description;
  std::vector<std::string> requirements;  // REQ-RA-... exercised
  bool expect_safe_reaction = false;      // the odometry must demand a stop (timeout)
  double duration_s = 60.0;
  std::int64_t step_us = 1000;            // Box2D fixed step (divides 10 ms)
  std::uint64_t seed = 1;
  double initial_front_m = 0.0;           // line chainage of the front at t = 0
  double initial_speed_kmh = 0.0;
  ScenarioStart start = ScenarioStart::kAtRest;
  LeadInSpec lead_in;                     // kLeadIn only
  VerticalAlignment vertical;
  std::vector<HorizontalCurve> curves;
  RailCondition rail;
  AdhesionLaw adhesion;
  std::vector<BalisePoint> balises;
  VehicleSpec vehicle;
  std::vector<DriverCommand> driver;
  SlipControlSpec slip_control;
  ImuErrorSpec imu;
  TgSpec tg;
  std::vector<SensorFault> faults;
  TruthSpec truth;
  ScenarioOdometry odometry;
};

// Parses and validates a scenario text (unknown keys, ranges, gradients beyond 35 permille,
// negative durations, unsorted lists, the route leaving the alignment ...).
WheelRailScenario ParseWheelRailScenario(std::string_view text, const std::string& file);
WheelRailScenario LoadWheelRailScenario(const std::filesystem::path& path);

// ---- line geometry of a scenario --------------------------------------------------------------
[[nodiscard]] double GradientPermilleAt(const VerticalAlignment& v, double s_m);
[[nodiscard]] double CurvatureAt(const std::vector<HorizontalCurve>& curves, double s_m);  // 1/m, + left
[[nodiscard]] double CantMmAt(const std::vector<HorizontalCurve>& curves, double s_m);     // >= 0

// Odometry sections of the scenario (design note §6): one section per gradient of the
// vertical alignment, from its change point to the next (the first from begin_m, the last
// to end_m), each with the steepest gradient magnitude in it (vertical curves included,
// rounded up to 0.1 permille) and the maximum compensation time (scenario's
// odometry.max_compensation_ms or the parameter max_compensation_ms); margin 0 (computed).
// Sections shorter than 1 m are merged into their neighbour.
[[nodiscard]] std::vector<ra::OdometrySection> OdometrySectionsOf(const WheelRailScenario& sc);

// The odometry configuration of the scenario: method kImu, nominal wheel diameter (with the
// calibration error), train length, Ta (scenario or parameter, never below the gravity
// component of the steepest gradient), start points, initial front, sections pointing
// into `sections` (which must outlive the configuration).
[[nodiscard]] ra::OdometryConfig OdometryConfigOf(const WheelRailScenario& sc,
                                                        const std::vector<ra::OdometrySection>& sections);

// ---- the vehicle, one step at a time ------------------------------------------------------------
// The Box2D car of the model summary above as an object advanced one fixed step at a time: the
// one wheel-rail model. SimulateWheelRail runs it under its driver schedule and records its
// sensor streams; the system simulator (cpp/offline/sim) runs it under the brake equipment that
// the real on-board unit commands. Its position is the line chainage of the alignment given.
struct WheelRailVehicleConfig {
  VehicleSpec vehicle;
  VerticalAlignment vertical;
  RailCondition rail;
  AdhesionLaw adhesion;
  SlipControlSpec slip_control;
  int tg_axle = 1;          // the axle whose rotation the TG count follows (TgCount)
  int tg_teeth = 90;
  double tg_phase = 0.5;    // initial angle of the TG wheel, in pulses [0.5, 1)
  double front_m = 0.0;     // the front at the start (line chainage along the rail)
  double speed_mps = 0.0;   // initial speed (every wheelset rolling)
};

// The demands of one step: traction as a notch fraction 0..1 (of max_traction_force_n, power
// limited), brake as a multiple of the full service brake (max_brake_force_n per axle): 0..1 the
// service brake, beyond 1 a stronger brake (the emergency brake of a train whose emergency
// deceleration exceeds its service deceleration). The slip control acts on both.
struct WheelRailDemand {
  double traction = 0.0;
  double brake = 0.0;
};

// A wheelset at the end of the last step (rail position and speed as of the last update).
struct WheelsetState {
  double omega = 0.0;        // rad/s, + rolling forward
  double normal_n = 0.0;     // N from the last step
  double friction_n = 0.0;   // static friction force while held (from the last step)
  double creep = 0.0;
  double force_n = 0.0;      // creep force applied in the last step
  double v = 0.0;            // wheelset speed along the rail
  double s = 0.0;            // rail position of its contact
  double control = 1.0;      // slip-control torque factor
  bool hold = false;         // braked standstill held by static friction
};

class WheelRailVehicle {
 public:
  // Builds the car at rest on the rail (or rolling at speed_mps); throws offline::InputError
  // when the configuration cannot be built.
  explicit WheelRailVehicle(const WheelRailVehicleConfig& config);
  ~WheelRailVehicle();
  WheelRailVehicle(WheelRailVehicle&&) noexcept;
  WheelRailVehicle& operator=(WheelRailVehicle&&) noexcept;
  WheelRailVehicle(const WheelRailVehicle&) = delete;
  WheelRailVehicle& operator=(const WheelRailVehicle&) = delete;

  // The demands from the wheelsets' mean speed along the rail at the start of a step.
  using Demand = std::function<WheelRailDemand(double speed_mps)>;
  // One Box2D step of dt_s: t_s is the time of the adhesion zones' windows, t_run_s the time
  // of the TG edges.
  void Step(double t_run_s, double t_s, double dt_s, const Demand& demand);
  // Rail position and speed of every wheelset from the bodies (Step does it at its start).
  void UpdateWheelsets();
  // Keeps the rail built around the car (pieces beyond its reach are removed); call it at
  // least every few metres run.
  void KeepRailAround();

  [[nodiscard]] double FrontM() const;   // leading axle's contact + overhang, as of the last update
  [[nodiscard]] double CentreM() const;
  [[nodiscard]] double SpeedMps() const;  // mean of the wheelsets' speeds along the rail
  [[nodiscard]] const WheelsetState& Wheelset(int axle) const;
  [[nodiscard]] double WheelRadiusM() const;
  // Car body velocity in the vertical plane (x along the unrolled track, z up) and pitch.
  [[nodiscard]] double BodyVx() const;
  [[nodiscard]] double BodyVz() const;
  [[nodiscard]] double BodyPitchRad() const;
  // TG axle: pulses completed since the start and the time of the latest edge (none yet: nullopt).
  [[nodiscard]] std::int64_t TgCount() const;
  [[nodiscard]] std::optional<double> TgEdgeS() const;
  // The demands of the last step.
  [[nodiscard]] const WheelRailDemand& LastDemand() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The configuration of a scenario's car: its vehicle, alignment, rail, adhesion law, slip
// control and TG; front and speed at the start (a lead-in's start, SimulateWheelRail).
[[nodiscard]] WheelRailVehicleConfig VehicleConfigOf(const WheelRailScenario& sc, double front_m, double speed_mps,
                                                     double tg_phase);

// ---- run --------------------------------------------------------------------------------------
enum class SlipKind : std::uint8_t { kSlip, kSlide };  // slip: wheel faster (traction), slide: slower
const char* ToString(SlipKind k);

struct TruthCycle {
  std::int64_t time_ms = 0;            // true cycle time (the cycle's time_ms unless a cycle_time fault)
  double front_m = 0.0;                // true front, line chainage along the rail
  double distance_m = 0.0;             // true distance run since t = 0
  double speed_mps = 0.0;              // true speed of the car body along the rail
  double accel_mps2 = 0.0;             // true acceleration along the rail (mean of the cycle)
  double tg_distance_m = 0.0;          // TG count x true pulse length (what the wheel rolled)
  double tg_wheel_speed_mps = 0.0;     // omega * r of the TG axle
  std::array<double, kWheelRailAxles> creep{};       // at the cycle time
  std::array<double, kWheelRailAxles> creep_peak{};  // largest magnitude in the cycle (signed)
  std::array<double, kWheelRailAxles> normal_force_n{};
  std::array<double, kWheelRailAxles> creep_force_n{};  // tangential force rail -> wheel, + forward
  double gradient_permille = 0.0;      // at the car's centre
  double pitch_rad = 0.0;              // car body pitch, nose up +
  double roll_rad = 0.0;               // car body roll (right-hand about x forward)
  double curvature_1pm = 0.0;          // + left
  double traction = 0.0;               // driver demands (before the slip control)
  double brake = 0.0;
  bool balise = false;                 // a balise fix is in this cycle
  std::uint32_t faults = 0;            // bit (1 << SensorFaultKind) of the faults active
};

struct SlipEvent {
  int axle = 0;
  bool tg_axle = false;
  SlipKind kind = SlipKind::kSlip;
  std::int64_t start_ms = 0;  // first time |creep| > event_creep
  std::int64_t end_ms = 0;    // first time back below
  double peak_creep = 0.0;    // signed
  double start_front_m = 0.0;
  double end_front_m = 0.0;
};

struct WheelRailRun {
  std::string scenario;
  std::vector<ra::CycleInput> cycles;  // one per 100 ms, time_ms = 100, 200, ... (faults aside)
  std::vector<TruthCycle> truth;             // one per cycle, same index
  std::vector<SlipEvent> events;             // sorted by start, then axle
  double simulated_s = 0.0;                  // the lead-in included
  std::int64_t lead_in_ms = 0;               // kLeadIn: the run's time of the scenario's t = 0
  std::uint64_t steps = 0;                   // Box2D steps
  double pulse_length_m = 0.0;               // true pulse length of the TG wheel
};

// Called about every 10 % of simulated time.
using WheelRailProgress = std::function<void(double simulated_s, double duration_s)>;

WheelRailRun SimulateWheelRail(const WheelRailScenario& sc, const WheelRailProgress& progress = {});

// Output files of wheelrail_sim: CSV (one row per cycle: truth, TG, cycle-mean IMU) and JSON
// (schema "railproof/wheelrail-run/1": scenario, events, every cycle's streams and truth).
std::string WheelRailCsv(const WheelRailRun& run);
nlohmann::ordered_json WheelRailJson(const WheelRailScenario& sc, const WheelRailRun& run);

}  // namespace railproof::ra::analysis
