// Offline line scenario simulation (issue 3 item 6): runs one running line with several
// trains, the runtime ground (mb::wayside::Ground) and on-board authority handling
// (mb::onboard::AuthorityReceiver, SpeedRestrictionStore), simple longitudinal dynamics
// (dynamics.hpp), position reports and stop-limit telegrams carried through the real radio
// telegram layer (tg::Endpoint, frames with RS + CRC + AEAD) over a lossy, delaying
// channel (channel.hpp), and injected faults. Safety invariants are checked on the true
// state after every step; an event log (JSON), a summary (JSON) and a time-distance
// diagram (SVG) are produced.
//
// One step of length step_ms at time t (t = 0, step, 2 step, ...):
//   1. scheduled commands and fault windows at t (possession request/cancel, siding route
//      request/free, speed restriction request+confirm/cancel; radio / tracking loss),
//   2. trains due to enter are registered with the ground (deferred while the entry is
//      not clear of other trains and their authorities),
//   3. frames due at t are delivered: POSITION to the ground endpoint of that train (an
//      accepted one is decoded and given to Ground::OnReport), CONTROL to the train's
//      endpoint (an accepted one is decoded and given to AuthorityReceiver::Receive),
//   4. if t is a ground cycle: handovers ahead of trains are secured, Ground::Cycle(t),
//      and every registered train's ground endpoint sends one CONTROL telegram (its stop
//      limit, or a keep-alive without limit when the ground gives none),
//   5. trains whose report time has come send one POSITION telegram (report_period_ms),
//   6. every train's driver / supervision chooses a control and the dynamics advance to
//      t + step; odometry (under-reading, reset at balises) and the length correction
//      (length_correction_ppm of the distance since the last balise) are updated,
//   7. invariants are checked at t + step.
//
// Invariants (violation = recorded with time and details; the CLI exits non-zero):
//   REQ-MB-008  true occupied ranges [front - length, front) of trains never overlap;
//   ASM-013     true front <= last accepted on-board stop limit + kLimitToleranceM (the
//               braking-supervision stand-in must discharge it);
//   REQ-MB-007  a usable on-board limit never lies beyond the true rear of a train ahead
//               minus the preceding-train margin;
//   REQ-MB-009  a usable on-board limit never exceeds the ground's protected authority;
//   REQ-MB-014  no train inside an active possession;
//   REQ-MB-011  points never move while a train's true range overlaps their block;
//   REQ-MB-013  a train is on a set of points only while they lie in the position of the
//               running line's (automatic) route.
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
#include "railproof/sim/scenario.hpp"

namespace railproof::sim {

// the shared offline pieces (line and train data, JSON, plots, command line)
using namespace ::railproof::offline;  // NOLINT(google-build-using-namespace)

// Discretisation allowance of the ASM-013 check (m): the supervision acts once per step.
inline constexpr double kLimitToleranceM = 0.5;

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
  // Checks the scenario against the line, builds the ground (InputError on bad input).
  Simulation(Scenario scenario, Line line);
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
