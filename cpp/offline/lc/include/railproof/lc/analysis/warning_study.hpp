// Warning-time study of level crossings (REQ-LC-017; spec/design/lc.md,
// spec/timetables/README.md). For every train of a timetable and every crossing it passes,
// the run is simulated with a simple kinematic model and the warning time (arrival of the
// front at the crossing's near edge minus the start of the warning) is computed for
//   (a) fixed treadles at the distance giving the design warning time to the fastest train
//       at the permitted speed (the former practice: warning time varies with the speed),
//   (b) the on-board request (D5 §5.3) through the runtime lc::onboard::CrossingProtection in the
//       loop: without dwell awareness, dwell-aware as the contract states (only while the
//       train stands at its stop), and dwell-aware from the approach to the stop on,
//   (c) GNSS-time pre-arming (D4 §4.8.2): start times from the planned departure and the
//       earliest arrival minus the clock allowance, recomputed from position reports.
// It also counts the trains whose protection pattern would have braked them for a crossing
// (the closure confirmation later than the pattern's first brake command, REQ-LC-015).
//
// Kinematic model (documented in spec/timetables/README.md): per section between two stops
// the train accelerates at its accel_max up to its cruising speed (cruise factor x the
// permitted speed: the line limit applying until the rear has left it, lowered to the
// supervision's ceiling on the line profile, capped at the train's maximum speed), brakes
// at the lower bound of its service deceleration for lower limits
// and for the stop; gradients are not modelled. Dwell, departure delays, cruise factor,
// radio delays, barrier travel and clock errors are drawn from the timetable's seed.
//
// Offline module (may allocate and throw offline::InputError "<file>: <entry>: <reason>").
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/offline/train_type.hpp"
#include "railproof/br/patterns.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::lc::analysis {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// The timetable JSON that railproof_testgen timetables writes from spec/timetables/<name>.yaml
// (build/gen/timetables/<name>.json: validated against spec/, times in ms, a dwell per stop).
inline constexpr std::string_view kTimetableSchema = "railproof/timetable-json/1";

// ---- timetable -------------------------------------------------------------------------------

struct RangeMs {
  std::int64_t min = 0;
  std::int64_t max = 0;
};

// Driver behaviour (drawn per section or per departure).
struct DriverModel {
  std::int64_t cruise_min_percent = 85;   // cruising speed, % of the permitted speed
  std::int64_t cruise_max_percent = 100;
  RangeMs start_delay_ms{0, 10'000};      // departure after the signal / departure time
  std::int64_t min_dwell_ms = 20'000;     // a late train shortens its stop down to this
};

// Communication, barriers and clocks.
struct CommsModel {
  RangeMs uplink_ms{200, 1'500};          // on-board request -> crossing controller
  RangeMs downlink_ms{200, 1'500};        // controller report -> train
  std::int64_t ground_cycle_ms = 500;     // controller cycle
  std::int64_t onboard_cycle_ms = 200;    // on-board cycle
  RangeMs barrier_travel_ms{4'000, 7'000};  // barriers commanded down -> detected down
  RangeMs report_latency_ms{300, 2'000};  // GNSS position report -> centre -> crossing
  std::int64_t onboard_clock_error_ms = 100;  // on-board variant: train and controller clocks
  std::int64_t gnss_clock_error_ms = 1'000;   // GNSS variant: each clock within +- this
};

struct ServiceStop {
  std::string station;
  std::int64_t dwell_ms = 0;  // planned dwell
};

// One train of the timetable: from its origin (first stop of its running line, or `from`)
// to its destination (last stop, or `to`), calling at `stops` in between (others passed).
struct Service {
  std::string id;
  std::string train;         // train type (build/gen/trains/<train>.json)
  std::string running_line;  // up / down
  std::int64_t depart_ms = 0;  // from the origin, ms after midnight
  std::string from;          // origin station (empty: the first of the running line)
  std::string to;            // destination (empty: the last of the running line)
  std::vector<ServiceStop> stops;
  std::string kind;          // "fast" (passes a station) or "stopping" (calls at all)
};

struct Timetable {
  std::string file;
  std::string name;
  std::string line;  // line name (must equal the line JSON's name)
  std::string title;
  std::uint64_t seed = 1;
  std::int64_t running_time_allowance_percent = 8;  // planned over technical running time
  std::int64_t planned_time_step_ms = 5'000;        // planned times rounded up to this
  DriverModel driver;
  CommsModel comms;
  std::vector<Service> services;
};

// ms after midnight -> "HH:MM:SS".
std::string FormatClockTime(std::int64_t ms);

// Reads the timetable JSON (kTimetableSchema): types, and every value within the range the
// study's arithmetic is made for; the rest of the format is the validator's (spec/design/data.md).
// `file` names it in messages: InputError "<file>: <entry>: <reason>".
Timetable ParseTimetable(std::string_view text, const std::string& file);
Timetable LoadTimetable(const std::filesystem::path& path);

// Checks that the timetable fits the line and the train types the study is given (which need
// not be those the validator saw): line name, train types known, running lines, stations (on
// the running line, origin before destination, stops strictly between them in running
// order), the train on every platform it starts, stops or ends at.
// Throws InputError "<file>: services[i] (<id>)...: <reason>".
void CheckTimetable(const Timetable& tt, const offline::Line& line, const std::map<std::string, TrainType>& trains);

// ---- kinematics ------------------------------------------------------------------------------

// The permitted-speed profile of a running line for a train: the line limits as restriction
// segments (mm/s, km/h rounded up), each capped at cap_mm_s (the train's maximum speed; 0: no cap).
std::vector<br::RestrictionSegment> PermittedProfile(const offline::RunningLine& rl, std::int64_t cap_mm_s);

// Fixed treadle: the distance before `near_mm` from which a train running at the permitted
// speed of `profile` (the fastest train at line speed) needs exactly `warning_ms` to reach
// near (walked back piece by piece, rounded up to the mm); clamped to the line start
// (result <= near_mm). Constant speed v: ceil(v * warning_ms / 1000).
// @implements REQ-LC-017
std::int64_t TreadleDistanceMm(std::span<const br::RestrictionSegment> profile, std::int64_t near_mm,
                               std::int64_t warning_ms);

// One simulated run: samples (t, x, v) with x non-decreasing; a stop is two samples at the
// same x (arrival, departure).
struct RunSample {
  double t_ms = 0.0;
  double x_mm = 0.0;
  double v_mm_s = 0.0;
};

struct RunStop {
  std::string station;
  std::int64_t front_mm = 0;       // stop point (running position)
  std::int64_t planned_arrival_ms = 0;
  std::int64_t planned_departure_ms = 0;  // t_dep (departure not authorised before)
  double arrival_ms = 0.0;         // simulated
  double departure_ms = 0.0;       // simulated
  bool origin = false;
  bool destination = false;
};

struct Run {
  std::vector<RunSample> samples;
  std::vector<RunStop> stops;  // origin, calls, destination (in running order)

  // First time the front is at or beyond x (nullopt if never).
  [[nodiscard]] std::optional<double> TimeAt(double x_mm) const;
  // Front and speed at time t (clamped to the run).
  [[nodiscard]] RunSample StateAt(double t_ms) const;
  // Index of the stop the train stands at at time t (nullopt if moving or outside).
  [[nodiscard]] std::optional<std::size_t> StandingAt(double t_ms) const;
};

// A section's speed limit along the grid: the cruising target, the train's acceleration and
// deceleration. Exposed for the unit tests.
struct SectionDriving {
  double cruise_factor = 1.0;           // x permitted speed
  double accel_mm_s2 = 0.0;
  double decel_mm_s2 = 0.0;
  std::int64_t train_length_mm = 0;
  std::int64_t max_speed_mm_s = 0;
  // Per speed-limit segment of the running line (same order), the highest speed at which the
  // supervision commands no brake on the line profile alone (mm/s); null: the line limits.
  // The driver cruises below the supervised ceiling, not above it.
  const std::vector<double>* ceiling_mm_s = nullptr;
};

// Time (ms) to run a section from rest at `from_mm` to rest at `to_mm` with the driving of
// `d` on the line limits of `rl`; appends the samples (relative to t0_ms) unless null.
double RunSection(const offline::RunningLine& rl, std::int64_t from_mm, std::int64_t to_mm, const SectionDriving& d,
                  double t0_ms, std::vector<RunSample>* out);

// ---- the study -----------------------------------------------------------------------------

// Methods, in the order of the outputs.
enum class Method : std::uint8_t {
  kTreadle,          // (a) fixed treadles
  kOnboard,          // (b) on-board request without dwell awareness
  kOnboardDwell,     // (b) dwell-aware while standing at the stop (the contract, design §2-§3)
  kOnboardApproach,  // (b) dwell-aware from the approach to the stop on
  kGnss,             // (c) GNSS-time pre-arming, updates from reports (report time stamps)
  kGnssReceiveTime,  // (c) sensitivity: updates computed with the centre's receive time
};
inline constexpr std::size_t kMethodCount = 6;
const char* ToString(Method m);
const char* Describe(Method m);
// Methods whose warning must never be shorter than the design warning time (REQ-LC-017).
bool MustMeetDesignTime(Method m);
// On-board methods (the protection pattern applies; REQ-LC-015).
bool IsOnboard(Method m);

// One train passing one crossing.
struct Passage {
  std::string service;
  std::string train;
  std::string kind;  // fast / stopping
  std::string running_line;
  std::string crossing;
  std::int64_t near_mm = 0;
  std::int64_t design_ms = 0;
  double arrival_ms = 0.0;        // front at the near edge (simulated time)
  double speed_kmh = 0.0;         // speed at the near edge
  bool stop_in_approach = false;  // the train stops at a station within 1 km before the crossing
  std::array<double, kMethodCount> warning_ms{};   // arrival - warning start
  std::array<bool, kMethodCount> braked{};         // on-board: pattern braking before clearance
  std::array<double, kMethodCount> brake_at_ms{};  // first brake command (if braked)
  std::array<double, kMethodCount> request_ms{};   // on-board: first request (-1: none)
  std::array<double, kMethodCount> cleared_ms{};   // on-board: cleared (-1: never)
  std::int64_t treadle_distance_mm = 0;
};

struct StudyInputs {
  const offline::Line* line = nullptr;
  const Timetable* timetable = nullptr;
  const std::map<std::string, TrainType>* trains = nullptr;
  // request_lead_ms of the on-board methods (default: spec/parameters/lc.yaml);
  // other values for the sensitivity of REQ-LC-015
  std::int64_t request_lead_ms = -1;
};

struct StudyResult {
  std::vector<Passage> passages;
  std::vector<Run> runs;  // per service (same order as the timetable)
  std::size_t onboard_cycles = 0;
  std::size_t pattern_evaluations = 0;
};

// Runs the study; progress(done, total) after every service (may be empty).
// @implements REQ-LC-017
StudyResult RunStudy(const StudyInputs& in, const std::function<void(std::size_t, std::size_t)>& progress = {});

// Statistics of a set of warning times (ms).
struct WarningStats {
  std::size_t count = 0;
  double min_s = 0, p05_s = 0, p10_s = 0, p50_s = 0, p90_s = 0, p95_s = 0, max_s = 0, mean_s = 0;
  double share_45_74 = 0;       // fraction within [45 s, 74 s]
  std::size_t below_design = 0;  // warning < design warning time
  double min_margin_s = 0;       // min over passages of warning - design
};
WarningStats ComputeStats(const std::vector<Passage>& passages, Method m,
                          const std::function<bool(const Passage&)>& filter = {});

// The JSON result (schema railproof/warning-study/1) and the SVG histogram of one method.
nlohmann::ordered_json StudyJson(const StudyInputs& in, const StudyResult& r, double wall_s);
std::string HistogramSvg(const StudyResult& r, Method m, const std::string& line_name);
// One row of the request-lead sensitivity (informational, no meets_target): trains braked
// and warning statistics of the on-board methods with request_lead_ms = lead_ms.
nlohmann::ordered_json LeadSensitivityRow(const StudyResult& r, std::int64_t lead_ms);
// True if no warning of a method that must meet the design time is shorter than it and no
// train braked for a crossing under the contract's on-board method.
bool StudyPasses(const StudyResult& r);

}  // namespace railproof::lc::analysis
