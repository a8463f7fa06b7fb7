// Offline odometry study (spec/design/ra.md §1, §6, §8; D1 §3 items 6-9, D1 §5.2):
//
//  1. margin tables: the permanent margin Delta_d(T_max, g) of the IMU method (the runtime's
//     error model, ra::ErrorBoundM) at the full and the tenth angular-rate error, the
//     envelope extension of the former max/min-acceleration method over the same times, and
//     the clearing-time cost of the permanent margin (time to clear train length + margins
//     from rest at clearing_accel_mm_s2);
//  2. the check of every train type's readhesion_margin_mm against the error model at the
//     reference configuration and the steepest gradient of the train's line;
//  3. the analysis of recorded odometry runs (one StudyCycle per 100 ms cycle: the truth, the
//     odometry output and the re-adhesion machine state): compensation episodes, the
//     matching of simulated slip/slide events to episodes, the true distance error over the
//     compensation interval against the error bound, and the check that the true front lies
//     inside the reported envelope in every cycle with a valid position.
//
// Units: metres, seconds, m/s, m/s^2 and permille in the tables (as D1 states them); the
// recorded runs keep the runtime's integer mm/ms. Offline module (allocates; throws
// InputError "<file>: <entry>: <reason>" on bad input).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "railproof/offline/train_type.hpp"
#include "railproof/ra/odometry.hpp"
#include "railproof/ra/readhesion_machine.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// ---- error model, baseline, clearing time (D1 §3 items 6, 7, 9) ------------------------

// Vehicle figures of the former method (D1 §3 item 9, in km/h/s: acceleration 2.1-3.3,
// deceleration 3.5-5.2; spec/parameters/ra.yaml former_*), in m/s^2.
struct VehicleAccelBounds {
  double accel_min = 0.0;  // m/s^2, lowest traction acceleration on the level
  double accel_max = 0.0;  // m/s^2, highest traction acceleration on the level
  double decel_min = 0.0;  // m/s^2, lowest braking deceleration on the level
  double decel_max = 0.0;  // m/s^2, highest braking deceleration on the level
};
[[nodiscard]] VehicleAccelBounds D1VehicleBounds() noexcept;

[[nodiscard]] double GravityMS2() noexcept;             // gravity_mm_s2 / 1000
[[nodiscard]] double RateErrorFullDegS() noexcept;      // imu_rate_error_full_udeg_s (0.025 deg/s)
[[nodiscard]] double RateErrorTenthDegS() noexcept;     // imu_rate_error_udeg_s (0.0025 deg/s)
[[nodiscard]] double ClearingAccelMS2() noexcept;       // clearing_accel_mm_s2 / 1000 (0.58)
[[nodiscard]] double ReferenceMaxCompensationS() noexcept;  // max_compensation_ms / 1000 (20 s)

// The study grid of D1's comparison: T_max in {3, 5, 10, 15, 20, 25, 32} s and
// g in {0, 10, 16, 25, 35} permille.
[[nodiscard]] std::vector<double> StudyTimesS();
[[nodiscard]] std::vector<double> StudyGradientsPermille();

// Permanent margin of the IMU method per side (front and rear), metres: the runtime's error
// model Delta_d(t, g) = 1/2 (Da_t + Da_a + G sin(Da_w t) + G g/1000) t^2 (ra::ErrorBoundM).
// @implements REQ-RA-008 REQ-RA-009
[[nodiscard]] double ImuMarginM(double t_s, double gradient_permille, double rate_error_deg_s);

// Envelope extension of the former method (D5 §7.4.2) after a slip/slide lasting t: from the
// start point (position x0, speed v0) the front is advanced with the upper acceleration
// bound a_f and the rear with the lower bound a_r, so the occupied range grows by
// (a_f - a_r) t^2 / 2 (v0 high enough that the rear bound does not reach standstill, the
// worst case). With G_g = G g/1000 for the steepest gradient magnitude g (D1 §3.4.3):
//   slip            a_f = accel_max + G_g (falling gradient), a_r = -G_g (the minimum
//                   acceleration including coasting: coasting on the rising gradient)
//   slide           a_f = +G_g (least deceleration incl. coasting on the falling gradient),
//                   a_r = -(decel_max + G_g) (most deceleration on the rising gradient)
//   slide (braked)  a_f = -decel_min + G_g (the brake known to act: least braking deceleration)
// The IMU method's comparable figure is its total extension 2 Delta_d (front + rear margin).
struct BaselineExtension {
  double slip_front_accel = 0.0, slip_rear_accel = 0.0;    // m/s^2 (signed, forward +)
  double slide_front_accel = 0.0, slide_rear_accel = 0.0;  // m/s^2
  double slip_m = 0.0;          // occupied-range growth after a slip of t
  double slide_m = 0.0;         // after a slide of t (front coasting)
  double slide_braked_m = 0.0;  // after a slide of t (front with the least braking deceleration)
  double worst_m = 0.0;         // max(slip_m, slide_m)
};
// @implements REQ-RA-014
[[nodiscard]] BaselineExtension BaselineExtensionM(double t_s, double gradient_permille,
                                                   const VehicleAccelBounds& b);

// Time to travel `distance_m` from rest at constant `accel` (sqrt(2 d / a)).
[[nodiscard]] double ClearingTimeS(double distance_m, double accel_m_s2);
// Extra time to clear train length + front and rear margin (2 x margin_per_side) from rest,
// against the train length alone (D1 §3 item 7).
[[nodiscard]] double ClearingCostS(double train_length_m, double margin_per_side_m, double accel_m_s2);

struct MarginTableRow {
  double t_max_s = 0.0;
  double gradient_permille = 0.0;
  double imu_margin_full_m = 0.0;    // Delta_d at 0.025 deg/s, per side
  double imu_margin_tenth_m = 0.0;   // Delta_d at 0.0025 deg/s, per side
  BaselineExtension baseline;        // former method, occupied-range growth
};
// One row per (time, gradient), times outer.
[[nodiscard]] std::vector<MarginTableRow> MarginTable(const std::vector<double>& times_s,
                                                      const std::vector<double>& gradients_permille,
                                                      const VehicleAccelBounds& b);

// ---- train types against the error model (REQ-RA-009, ASM-024) -------------------------

// Steepest gradient magnitude of every running line of a line (permille x 10).
[[nodiscard]] std::int64_t SteepestGradientX10(const offline::Line& line);

// The line of a train type: a train "<type>_dN" runs on the line "dN_<...>" of lines_dir
// (emu3_d1 -> d1_test_line, dmu2_d4 -> d4_local_line, emu10_d2 -> d2_urban_line), and the
// line's design_train_length_mm must equal the train's length. InputError when there is no
// such line, more than one, or the lengths differ.
[[nodiscard]] std::filesystem::path LineOfTrain(const TrainType& t, const std::filesystem::path& lines_dir);

struct TrainMarginCheck {
  std::string train;
  std::string train_file;
  std::string line;
  std::string line_file;
  double length_m = 0.0;
  std::int64_t steepest_gradient_permille_x10 = 0;
  std::int64_t max_compensation_ms = 0;   // reference configuration
  std::int64_t rate_error_udeg_s = 0;     // reference configuration
  std::int64_t readhesion_margin_mm = 0;  // the train type's value
  std::int64_t error_model_mm = 0;        // ra::ErrorBoundMm at the reference configuration
  std::int64_t headroom_mm = 0;           // readhesion_margin_mm - error_model_mm
  double clearing_extra_s = 0.0;          // cost of the train's margin at clearing_accel
  bool meets_target = false;              // readhesion_margin_mm >= error_model_mm
};
// @implements REQ-RA-009
[[nodiscard]] TrainMarginCheck CheckTrainMargin(const TrainType& t, const offline::Line& line);

// ---- recorded odometry runs ------------------------------------------------------------

// One 100 ms cycle of a run: the truth at the cycle time, the odometry output and the
// re-adhesion machine state after the cycle, and the steepest gradient of the odometry
// sections under the true train.
struct StudyCycle {
  std::int64_t time_ms = 0;
  double true_front_m = 0.0;       // line position of the true front
  double true_speed_m_s = 0.0;
  double gradient_permille = 0.0;  // steepest section gradient under the true train
  bool balise = false;             // a balise fix was delivered with this cycle's input
  ra::OdometryOutput out{};
  ra::MachineState machine{};
};

// A simulated slip or slide (ground truth of the simulator).
struct TruthEvent {
  int id = 0;
  std::string kind;       // "slip" or "slide"
  std::int64_t start_ms = 0;
  std::int64_t end_ms = 0;  // last cycle of the event (inclusive)
};

enum class EpisodeOutcome : std::uint8_t {
  kAdopted,        // a candidate completed the re-adhesion judgement
  kTimeout,        // the last candidate reached the maximum compensation time: stop demand
  kSensorFailure,  // a sensor failure ended the compensation
  kOpen,           // still compensating at the end of the run
};
[[nodiscard]] const char* ToString(EpisodeOutcome o) noexcept;

// A compensation episode: from the detection cycle (mode becomes kCompensating) to the
// cycle that leaves kCompensating.
struct Episode {
  int index = 0;
  std::size_t detect = 0;  // cycle index of the detection
  std::size_t end = 0;     // cycle index that left kCompensating (or the last cycle)
  EpisodeOutcome outcome = EpisodeOutcome::kOpen;
  int adopted = -1;                  // adopted candidate index
  std::int32_t start_age_cycles = 0;  // age of the primary start point at detection
  std::int32_t comp_cycles = 0;      // compensation time of the adopted candidate (or of the
                                     // longest-lived candidate at the end) in cycles
  int candidate = 0;                 // the candidate comp_cycles refers to
  std::int64_t max_compensation_ms = 0;  // t_max in force at the end
};
// @implements REQ-RA-003 REQ-RA-006 REQ-RA-007 REQ-RA-010
// Candidate ages come from the recorded machine state (they include the spacing).
[[nodiscard]] std::vector<Episode> FindEpisodes(const std::vector<StudyCycle>& run);

// For every episode the truth event that caused it: the latest-starting event with the
// detection in [start, end + match_window_ms]; -1 for a detection without a cause (spurious).
[[nodiscard]] std::vector<int> EpisodeCauses(const std::vector<TruthEvent>& events, const std::vector<StudyCycle>& run,
                                             const std::vector<Episode>& episodes, std::int64_t match_window_ms);

// For every truth event the episode detecting it: the first episode whose detection lies in
// [start, end + match_window_ms]; -1 if none. Several events may map to one episode (close
// slips compensated together).
[[nodiscard]] std::vector<int> MatchEvents(const std::vector<TruthEvent>& events, const std::vector<StudyCycle>& run,
                                           const std::vector<Episode>& episodes, std::int64_t match_window_ms);
// Window after the end of an event in which its detection is still attributed to it: the
// moving-average delay (moving_average_ms) plus confirm_cycles cycles plus one cycle.
[[nodiscard]] std::int64_t DefaultMatchWindowMs() noexcept;

// The true distance error of an episode over its compensation interval [s, e] (s = the start
// point of the candidate, e = the re-adhesion cycle or the last compensating cycle):
// (front(e) - front(r)) - (true(e) - true(r)) against ErrorBound(t, g), t = the candidate's
// compensation time, g = the steepest section gradient under the train over [s, e], and
// r = s, or the last cycle in (s, e] with a balise fix and a valid position (the fix
// re-established the position base: the nominal front of earlier cycles, e.g. while stopped
// before the fix, is not the base the compensation continued from; the error accrued before
// the fix was removed by it).
struct EpisodeError {
  bool valid = false;          // false: the start point lies before the recorded run
  std::size_t start = 0;       // cycle index of the start point s
  std::size_t reference = 0;   // cycle index r (s, or the last balise fix inside)
  std::size_t stop = 0;        // cycle index e
  double comp_time_s = 0.0;
  double gradient_permille = 0.0;
  double odometry_distance_m = 0.0;  // front(e) - front(r)
  double true_distance_m = 0.0;      // true(e) - true(r)
  double error_m = 0.0;        // odometry - true
  double bound_m = 0.0;
  double ratio = 0.0;          // |error| / bound
  double tg_error_m = 0.0;     // what TG odometry alone would have introduced over [s, e]
  bool balise_in_interval = false;  // a balise fix inside (s, e]: r is the last one
  double worst_ratio_during = 0.0;  // max over the compensating cycles of the nominal
                                    // candidate's |error| / bound at its age
};
// r for a start point s and a cycle k: s, or the last cycle in (s, k] with a balise fix and
// a valid position.
[[nodiscard]] std::size_t ErrorReference(const std::vector<StudyCycle>& run, std::size_t s, std::size_t k);

// `tg_distance_m(i)` is the TG distance (pulses x pulse length) of cycle i, for tg_error_m;
// pass an empty vector to skip it.
// @implements REQ-RA-005 REQ-RA-008
[[nodiscard]] EpisodeError EvaluateEpisode(const std::vector<StudyCycle>& run, const Episode& ep,
                                           double rate_error_deg_s, const std::vector<double>& tg_distance_m);

// The true front must lie in [front - rear_error, front + front_error] in every cycle with
// a valid position (REQ-RA-012).
struct EnvelopeCheck {
  int cycles_checked = 0;
  int violations = 0;
  double worst_excess_m = 0.0;  // how far the truth was outside (0 if never)
  std::int64_t first_violation_ms = -1;
  double min_front_slack_m = 0.0;  // smallest front_error - (true - front) over the run
  double min_rear_slack_m = 0.0;   // smallest rear_error - (front - true)
};
// @implements REQ-RA-012
[[nodiscard]] EnvelopeCheck CheckEnvelope(const std::vector<StudyCycle>& run);

// ---- the scenario suite (ra::analysis::WheelRailScenario, spec/wheelrail) ------------------------

// A slip/slide phase: the simulator's per-axle events (ra::analysis::SlipEvent) merged across axles
// while they overlap or follow each other within gap_ms (a wheel-slip protection makes the
// creep of each axle cross the event threshold many times in one adhesion loss; the
// odometry sees one disturbance).
struct SlipPhase {
  int id = 0;
  std::int64_t start_ms = 0;
  std::int64_t end_ms = 0;
  std::string kind;          // "slip", "slide" or "slip+slide"
  std::vector<int> events;   // indices into the simulator's events
  std::vector<int> axles;    // axles involved, sorted
  bool tg_axle = false;      // the TG axle is among them
  double peak_creep = 0.0;   // signed creep of largest magnitude
};
inline constexpr std::int64_t kPhaseGapMs = 1000;
[[nodiscard]] std::vector<SlipPhase> GroupSlipEvents(const std::vector<ra::analysis::SlipEvent>& events, std::int64_t gap_ms);

// Former method's envelope around one of its episodes (REQ-RA-014).
struct BaselineEpisode {
  double extension_at_end_m = 0.0;   // (front + rear error) at the episode's end minus before detection
  double max_extension_m = 0.0;      // largest such growth until the next balise fix (or the run's end)
  int cycles_checked = 0;            // valid-position cycles from detection to the next balise fix
  int violations = 0;                // of those, cycles with the truth outside the envelope
  double worst_excess_m = 0.0;
};

// One odometry configuration replayed over a simulated run.
struct StudyRun {
  std::string label;  // "imu_2sp", "imu_1sp", "baseline"
  ra::OdometryConfig config{};
  std::vector<StudyCycle> cycles;
  std::vector<Episode> episodes;
  std::vector<EpisodeError> errors;        // per episode
  std::vector<BaselineEpisode> baseline;   // per episode (method kMaxMinAcceleration only)
  std::vector<int> event_episode;          // per truth event (phase): first episode or -1
  std::vector<int> episode_event;          // per episode: the phase that caused it or -1
  EnvelopeCheck envelope;
  double worst_ratio = 0.0;                // over the adopted episodes (error at re-adhesion)
  int worst_episode = -1;
};

// Runs the odometry with `cfg` over the simulated cycle stream and records every cycle
// (truth, output, machine state, steepest section gradient under the true train). InputError
// "<where>: odometry configuration: <reason>" if Create rejects the configuration.
[[nodiscard]] std::vector<StudyCycle> ReplayOdometry(const ra::analysis::WheelRailRun& sim, const ra::OdometryConfig& cfg,
                                                     const std::vector<ra::OdometrySection>& sections,
                                                     const std::string& where);

// Episodes, errors against the bound, event matching, envelope (and the baseline envelope).
[[nodiscard]] StudyRun AnalyseRun(std::string label, const ra::OdometryConfig& cfg,
                                  std::vector<StudyCycle> cycles, const ra::analysis::WheelRailRun& sim,
                                  const std::vector<TruthEvent>& events);

// A named check of a scenario with its outcome (fails the study when !ok).
struct ScenarioCheck {
  std::string name;
  bool ok = true;
  std::string detail;
};

struct ScenarioStudy {
  ra::analysis::WheelRailScenario scenario;
  ra::analysis::WheelRailRun sim;
  std::vector<ra::OdometrySection> sections;
  std::vector<SlipPhase> phases;   // the simulator's slip/slide events grouped (kPhaseGapMs)
  std::vector<TruthEvent> events;  // one per phase, id = phase index
  StudyRun primary;   // Method::kImu with the configured start points (parameter: 2)
  StudyRun single;    // Method::kImu with one start point
  StudyRun baseline;  // Method::kMaxMinAcceleration
  std::vector<ScenarioCheck> checks;
  std::vector<std::string> failures;  // one line each: scenario, event, figures
  [[nodiscard]] bool Pass() const { return failures.empty(); }
};

// Simulates the scenario, replays the three configurations and checks: the error at
// re-adhesion of every adopted episode of the primary run within the bound (ratio <= 1;
// timeouts and sensor failures invalidate the position instead and are reported, not
// checked against the bound), no envelope violation in either
// IMU run, expect_safe_reaction -> a maximum-time stop (stop demand, position invalid, kept
// until a balise fix), a sensor-fault scenario -> the typed rejection with the right stop
// reason in the fault's first cycle.
// @implements REQ-RA-007 REQ-RA-008 REQ-RA-010 REQ-RA-013 REQ-RA-014
[[nodiscard]] ScenarioStudy StudyScenario(const ra::analysis::WheelRailScenario& sc, const ra::analysis::WheelRailProgress& progress = {});

// The input error a sensor fault must produce (kNone: not visible to the validation, e.g.
// a stuck TG, which appears as a slide instead).
[[nodiscard]] ra::InputError ExpectedInputError(ra::analysis::SensorFaultKind k) noexcept;

// ---- plots (SVG, offline::SvgPlot) -----------------------------------------------------------

// Four stacked panels over time: the averaged IMU acceleration against the TG acceleration
// with the threshold band Ap +- Ta (detections, re-adhesions, timeouts marked; simulated
// slip/slide events shaded); true, TG and compensated speeds; the true front relative to
// the nominal front inside the reported envelope (IMU and former method); the distance
// error of the nominal candidate since its start point against +-ErrorBound(t, g).
[[nodiscard]] std::string ScenarioPlotSvg(const ScenarioStudy& st);

// Two stacked panels: the permanent margin Delta_d(T, g) per side for both rate errors; the
// growth of the occupied range of the IMU method (2 Delta_d, permanent) against the former
// method's slip and slide extension after a slip/slide lasting T.
[[nodiscard]] std::string MarginPlotSvg(const std::vector<double>& gradients_permille, double t_max_s,
                                        const VehicleAccelBounds& b);

// Extra time to clear train length + 2 x margin from rest at clearing_accel against the
// margin per side, one curve per train; each train's readhesion_margin_mm marked.
[[nodiscard]] std::string ClearingPlotSvg(const std::vector<TrainMarginCheck>& trains, double max_margin_m);

}  // namespace railproof::ra::analysis
