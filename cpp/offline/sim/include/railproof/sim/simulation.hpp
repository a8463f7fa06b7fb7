// Offline system simulation of a running line (issue 15 item 4): every train is its true
// motion (the one train-motion model, dynamics.hpp: traction, running resistance, gradients),
// its sensors (sensors.hpp: tachogenerator, IMU, balises), the real on-board unit
// (units::OnboardUnit: odometry, braking supervision, crossing protection, radio) and a driver
// model; the ground is the real wayside unit (units::WaysideUnit: radio endpoints, moving-block
// ground, crossing controllers). The units talk only through their telegram frames over a
// lossy, delaying channel (channel.hpp). The crossings' lights and barriers follow the wayside
// unit's commands. Faults and commands go through the units' interfaces. Safety invariants are
// checked on the true state after every step; an event log (JSON), a summary (JSON) and a
// time-distance diagram (SVG) are produced. Design note: spec/design/sim.md.
//
// One step of step_ms (= the on-board cycle, 100 ms) at time t:
//   1. scheduled commands and fault windows at t (possession request/cancel, siding route
//      request/free, speed restriction request+confirm/cancel; radio / tracking loss),
//   2. trains due to enter are admitted and registered with the wayside unit (deferred while
//      the entry is not clear of other trains and their authorities); their on-board unit
//      starts at the entry balise,
//   3. frames due at t are delivered: a train's to the wayside unit (Receive), the wayside
//      unit's to the train's on-board unit (read in its cycle at t),
//   4. if t is a ground cycle: the wayside unit's cycle with the crossings' barrier detection;
//      its frames go to the channel, its commands to the crossings' equipment,
//   5. every train: its on-board unit's cycle (sensors of the last 100 ms, balise read, frames,
//      driver inputs); its telegram to the channel; the driver and the brake equipment choose
//      the control (the unit's brake demand overrides the driver); the true motion advances to
//      t + step and the sensors record it,
//   6. invariants are checked at t + step.
//
// Invariants (violation = recorded with time and details; the CLI exits non-zero):
//   REQ-MB-008  true trains keep at least the preceding-train margin between them;
//   ASM-013     a true front never passes the limit its unit supervises (the movement
//               authority or the crossing protection limit, REQ-BR-001, REQ-LC-003);
//   REQ-MB-007  a usable on-board limit never lies beyond the true rear of a train ahead
//               minus the preceding-train margin;
//   REQ-MB-009  a usable on-board limit never exceeds the ground's protected authority;
//   REQ-MB-014  no train inside an active possession;
//   REQ-MB-011  points never move while a train's true range overlaps their block;
//   REQ-MB-013  a train is on a set of points only while they lie in the position of the
//               running line's (automatic) route;
//   REQ-LC-003  a true train occupies a level crossing only while its barriers are down;
//   REQ-LC-002  ... and only after its lights have warned for the design warning time;
//   REQ-BR-004  no true speed above the ceiling of the unit's permitted-speed profile under the
//               train plus the emergency overspeed allowance (REQ-BR-001).
#pragma once

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/offline/line.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/sim/scenario.hpp"

namespace railproof::sim {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

struct Violation {
  std::int64_t t_ms = 0;
  std::string requirement;  // e.g. "REQ-MB-008"
  std::string detail;
};

struct TrainView {
  std::uint16_t id = 0;
  std::string phase;  // pending, standing, running, dwelling, exited
  double front_m = 0.0;
  double rear_m = 0.0;
  double speed_mps = 0.0;
  std::optional<double> limit_m;  // last accepted on-board limit
  std::optional<double> supervised_limit_m;  // the limit the unit supervises (authority or crossing)
  double permitted_speed_mps = 0.0;          // the unit's indication
  std::string brake;                         // the unit's demand: NONE, SERVICE, EMERGENCY
  bool authority_usable = false;
  bool link_up = false;
  bool emergency = false;
  bool abnormal = false;  // as the ground sees it
  std::size_t stops_made = 0;
  std::uint32_t emergency_brakes = 0;
};

struct GapResult {
  std::uint16_t leader = 0;
  std::uint16_t follower = 0;
  double from_s = 0.0;
  double to_s = 0.0;
  std::size_t samples = 0;
  double mean_m = 0.0;
  double min_m = 0.0;
  double max_m = 0.0;
  double std_m = 0.0;  // standard deviation over the window
  double leader_speed_kmh = 0.0;    // mean over the window
  double follower_speed_kmh = 0.0;  // mean over the window
};

struct RunOptions {
  std::ostream* log = nullptr;  // JSON event log, streamed
  bool log_full = false;        // also every accepted report and telegram
  // Called with one line per 10 % of simulated time.
  std::function<void(const std::string&)> progress;
};

class Simulation {
 public:
  // Checks the scenario against the line, picks each train's type (the one of `types` of the
  // train's length: its on-board data), builds the units (InputError on bad input).
  Simulation(Scenario scenario, Line line, std::vector<TrainType> types);
  ~Simulation();
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  // Runs to the scenario's duration (or from the current time on).
  void Run(const RunOptions& options = {});
  // One step (for tests); false once the duration is reached.
  bool Step();

  [[nodiscard]] std::int64_t NowMs() const;
  [[nodiscard]] const std::vector<Violation>& Violations() const;
  [[nodiscard]] std::vector<TrainView> Trains() const;
  [[nodiscard]] std::optional<TrainView> Train(std::uint16_t id) const;
  [[nodiscard]] std::optional<GapResult> Gap() const;
  [[nodiscard]] nlohmann::ordered_json Summary() const;
  [[nodiscard]] std::string Svg() const;
  [[nodiscard]] const Scenario& GetScenario() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace railproof::sim
