// Line scenario simulation: see simulation.hpp for the step and the invariants.
#include "railproof/sim/simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <string>
#include <utility>

#include "railproof/generated/mb_params.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/mb/onboard/authority.hpp"
#include "railproof/tg/aead.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/sim/channel.hpp"
#include "railproof/sim/codec.hpp"
#include "railproof/offline/dynamics.hpp"
#include "railproof/sim/ground_line.hpp"
#include "railproof/offline/svg.hpp"
#include "railproof/mb/wayside/ground.hpp"

namespace railproof::sim {

namespace mbp = params::mb;
using Json = nlohmann::ordered_json;

namespace {

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

double Round(double v, double unit) { return std::round(v / unit) * unit; }
double R2(double v) { return Round(v, 0.01); }
double R1(double v) { return Round(v, 0.1); }
std::int64_t ToMm(double m) { return static_cast<std::int64_t>(std::llround(m * 1000.0)); }
double ToM(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }
double ToS(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }
std::uint32_t Clock32(std::int64_t ms) { return static_cast<std::uint32_t>(static_cast<std::uint64_t>(ms) & 0xFFFFFFFFULL); }

const char* VerdictName(tg::RejectReason r) { return tg::ToString(r); }

enum class Phase : std::uint8_t { kPending, kStanding, kRunning, kDwelling, kExited };
const char* ToString(Phase p) {
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

std::string Fmt(double v) {
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

}  // namespace

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
  std::vector<std::pair<std::int64_t, std::string>> route_events;
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

  // ---------------------------------------------------------------- setup
  void Setup() {
    rl = &SelectRunningLine(sc, line);
    CheckScenarioAgainstLine(sc, *rl);
    channel = Channel(ChannelConfig{sc.channel.loss_probability, sc.channel.min_delay_ms, sc.channel.max_delay_ms,
                                    sc.channel.corrupt_probability},
                      sc.seed);
    odo_prng = Prng(sc.seed ^ 0x0D0D0D0D0D0D0D0DULL);
    gl = BuildGroundLine(line, *rl,
                         sc.margin_policy == MarginPolicy::kD2 ? mb::wayside::MarginPolicy::kD2Buffers
                                                               : mb::wayside::MarginPolicy::kReportedCorrection,
                         sc.ground_cycle_ms);
    ground = CreateGround(line, *rl, gl, sc.trains.size(), 0);
    if (sc.boundary_accepted && rl->system_boundary_mm) {
      ground->AcceptAtBoundary(true);
    }
    for (std::size_t p = 0; p < gl.points.size(); ++p) {
      bool running_reverse = false;
      for (const auto& r : gl.routes) {
        if (r.points_index == p && r.automatic) {
          running_reverse = r.reverse;
          break;
        }
      }
      points_running_reverse.push_back(running_reverse);
      points_reverse.push_back(ground->PointsReverse(p));
    }
    Prng key_prng(sc.seed ^ 0x6B65796B65796B65ULL);
    for (const auto& spec : sc.trains) {
      auto t = std::make_unique<TrainRt>();
      t->spec = spec;
      t->length_mm = ToMm(spec.performance.length_m);
      t->motion.position = ToM(spec.initial_front_mm);
      std::array<std::uint8_t, tg::kKeyBytes> kb{};
      for (auto& b : kb) {
        b = static_cast<std::uint8_t>(key_prng.Next() >> 56U);
      }
      t->key = std::make_unique<tg::LinkKey>(kb);
      trains.push_back(std::move(t));
    }
    for (const auto& f : sc.faults) {
      FaultRt fr;
      fr.spec = f;
      faults.push_back(fr);
    }
    for (const char* id : {"REQ-MB-007", "REQ-MB-008", "REQ-MB-009", "REQ-MB-011", "REQ-MB-013", "REQ-MB-014",
                           "ASM-013"}) {
      checks[id];
    }
  }

  // ---------------------------------------------------------------- log
  void Emit(Json ev) {
    ++events;
    if (opts == nullptr || opts->log == nullptr) {
      return;
    }
    Json out;
    out["t_ms"] = now;
    for (auto& [k, v] : ev.items()) {
      out[k] = v;
    }
    *opts->log << (first_event ? "\n" : ",\n") << out.dump();
    first_event = false;
  }
  [[nodiscard]] bool Full() const { return opts != nullptr && opts->log != nullptr && opts->log_full; }

  // Records a violation of `req`. A condition that persists over several steps (same
  // `key`) is one violation episode: recorded at its onset, counted once; its steps are
  // counted in violation_steps.
  void Violate(const std::string& req, const std::string& key, const std::string& detail) {
    const std::string k = req + "/" + key;
    active_now.insert(k);
    ++checks[req].violation_steps;
    if (active_prev.count(k) != 0) {
      return;
    }
    ++checks[req].violations;
    if (violations.size() < 10000) {
      violations.push_back(Violation{now, req, detail});
    }
    Emit(Json{{"ev", "violation"}, {"requirement", req}, {"detail", detail}});
  }

  TrainRt* Find(std::uint16_t id) {
    for (auto& t : trains) {
      if (t->spec.id == id) {
        return t.get();
      }
    }
    return nullptr;
  }
  [[nodiscard]] const TrainRt* Find(std::uint16_t id) const {
    for (const auto& t : trains) {
      if (t->spec.id == id) {
        return t.get();
      }
    }
    return nullptr;
  }

  // ---------------------------------------------------------------- line helpers
  [[nodiscard]] double MeanGradient(double rear_m, double front_m) const {
    const std::int64_t a = std::max<std::int64_t>(0, ToMm(rear_m));
    const std::int64_t b = std::min(rl->length_mm, std::max(a + 1, ToMm(front_m)));
    double sum = 0.0;
    for (const auto& g : rl->gradients) {
      const std::int64_t lo = std::max(a, g.section.begin_mm);
      const std::int64_t hi = std::min(b, g.section.end_mm);
      if (hi > lo) {
        sum += static_cast<double>(hi - lo) * static_cast<double>(g.permille_x10) / 10.0;
      }
    }
    return b > a ? sum / static_cast<double>(b - a) : static_cast<double>(rl->GradientAt(a)) / 10.0;
  }
  // Steepest falling gradient (per mille, >= 0) over [a, b].
  [[nodiscard]] double SteepestFall(double a_m, double b_m) const {
    const std::int64_t a = ToMm(a_m);
    const std::int64_t b = std::max(a + 1, ToMm(b_m));
    double fall = 0.0;
    for (const auto& g : rl->gradients) {
      if (g.section.begin_mm < b && a < g.section.end_mm) {
        fall = std::max(fall, -static_cast<double>(g.permille_x10) / 10.0);
      }
    }
    return fall;
  }
  [[nodiscard]] std::int64_t CorrectionMm(const TrainRt& t) const {
    const double odo_m = std::max(0.0, t.est_front_m - t.balise_est_m);
    return static_cast<std::int64_t>(std::ceil(odo_m * 1000.0 * static_cast<double>(mbp::length_correction_ppm) / 1e6));
  }

  // ---------------------------------------------------------------- entry / exit
  bool EntryClear(const TrainRt& n) const {
    const std::int64_t front = n.spec.initial_front_mm;
    const std::int64_t rear = front - n.length_mm;
    const std::int64_t m = mbp::margin_preceding_train_mm;
    for (const auto& u : trains) {
      if (u.get() == &n || !u->OnLine()) {
        continue;
      }
      if (core::Overlaps(rear - m, front + m, u->RearMm(), u->FrontMm())) {
        return false;
      }
      if (u->FrontMm() <= front) {
        const auto prot = ground->ProtectedAuthority(u->spec.id);
        if (prot && *prot > rear - m) {
          return false;
        }
        const auto lim = u->auth.Limit();
        if (lim && *lim > rear - m) {
          return false;
        }
      }
    }
    return true;
  }

  void Enter(TrainRt& t) {
    const mb::wayside::TrainRegistration reg{t.spec.id, t.length_mm, t.spec.initial_front_mm, 0,
                                         mb::wayside::InitialPosition::kEntryBalise};
    const auto st = ground->RegisterTrain(reg);
    if (st != mb::wayside::RegisterStatus::kRegistered) {
      throw InputError(sc.file + ": " + t.spec.entry + ": the ground refuses the train registration (status " +
                       std::to_string(static_cast<int>(st)) + ")");
    }
    auto tc = tg::DeploymentConfig(tg::Role::kTrain, t.spec.id, kGroundId);
    auto gc = tg::DeploymentConfig(tg::Role::kGround, kGroundId, t.spec.id);
    if (t.train_ep.Init(tc, *t.key) != tg::ConfigError::kNone || t.ground_ep.Init(gc, *t.key) != tg::ConfigError::kNone) {
      throw std::runtime_error("radio endpoint initialisation failed (crypto unavailable?)");
    }
    t.phase = Phase::kStanding;
    t.entered_ms = now;
    t.motion = Motion{ToM(t.spec.initial_front_mm), 0.0};
    t.est_front_m = t.motion.position;
    t.balise_est_m = t.est_front_m;
    t.balise_true_m = t.motion.position;
    t.last_balise_mm = t.spec.initial_front_mm;
    t.odo_error = -kOdometryErrorShare * static_cast<double>(mbp::length_correction_ppm) / 1e6 * odo_prng.Uniform();
    t.next_balise = 0;
    while (t.next_balise < rl->balises.size() && rl->balises[t.next_balise].position_mm <= t.spec.initial_front_mm) {
      ++t.next_balise;
    }
    t.start_m = t.motion.position;
    // spread the report instants of the trains over the period
    t.next_report_ms = now + (static_cast<std::int64_t>(t.spec.id) * sc.step_ms) % sc.report_period_ms;
    Emit(Json{{"ev", "enter"}, {"train", t.spec.id}, {"front_mm", t.spec.initial_front_mm}, {"length_mm", t.length_mm}});
  }

  void Exit(TrainRt& t, const std::string& why) {
    ground->RemoveTrain(t.spec.id);
    channel.Purge(t.spec.id);
    t.phase = Phase::kExited;
    t.exited_ms = now;
    t.motion.speed = 0.0;
    Emit(Json{{"ev", "exit"}, {"train", t.spec.id}, {"front_mm", t.FrontMm()}, {"reason", why}});
  }

  // ---------------------------------------------------------------- faults and commands
  void ApplySchedule() {
    for (auto& f : faults) {
      const FaultSpec& s = f.spec;
      if (!f.started && now >= s.from_ms) {
        f.started = true;
        Json ev{{"ev", "fault_begin"}, {"type", ToString(s.type)}};
        switch (s.type) {
          case FaultType::kRadioLoss:
          case FaultType::kTrackingLoss: ev["train"] = *s.train; break;
          case FaultType::kPossession: {
            const auto r = ground->RequestPossession(core::Section{s.begin_mm, s.end_mm});
            f.possession_id = r.id;
            f.status = mb::wayside::ToString(r.status);
            ev["possession"] = r.id;
            ev["range_mm"] = {s.begin_mm, s.end_mm};
            ev["status"] = f.status;
            exercised.insert("REQ-MB-014");
            break;
          }
          case FaultType::kSidingRequest: {
            const auto st = ground->RequestRoute(static_cast<std::uint32_t>(SidingRoute(s)));
            f.status = mb::wayside::ToString(st);
            ev["route"] = SidingRoute(s);
            ev["status"] = f.status;
            exercised.insert("REQ-MB-012");
            exercised.insert("REQ-MB-013");
            break;
          }
          case FaultType::kSpeedRestriction: {
            const auto speed = static_cast<std::int64_t>(std::llround(s.speed_mps * 1000.0));
            const auto r = ground->RequestSpeedRestriction(core::Section{s.begin_mm, s.end_mm}, speed);
            f.restriction_id = r.id;
            const auto c = ground->ConfirmSpeedRestriction(r.id);
            f.status = std::string(mb::wayside::ToString(r.status)) + "/" + mb::wayside::ToString(c);
            ev["restriction"] = r.id;
            ev["range_mm"] = {s.begin_mm, s.end_mm};
            ev["speed_mm_s"] = speed;
            ev["status"] = f.status;
            exercised.insert("REQ-MB-015");
            break;
          }
        }
        Emit(ev);
      }
      if (f.started && !f.ended && now >= s.to_ms) {
        f.ended = true;
        Json ev{{"ev", "fault_end"}, {"type", ToString(s.type)}};
        switch (s.type) {
          case FaultType::kRadioLoss:
          case FaultType::kTrackingLoss: ev["train"] = *s.train; break;
          case FaultType::kPossession:
            ev["status"] = mb::wayside::ToString(ground->CancelPossession(f.possession_id));
            ev["possession"] = f.possession_id;
            break;
          case FaultType::kSidingRequest: f.free_pending = true; break;
          case FaultType::kSpeedRestriction:
            ev["status"] = mb::wayside::ToString(ground->CancelSpeedRestriction(f.restriction_id));
            break;
        }
        Emit(ev);
      }
      if (f.free_pending) {
        const auto st = ground->FreeRoute(static_cast<std::uint32_t>(SidingRoute(s)));
        if (st == mb::wayside::CommandStatus::kAccepted) {
          f.free_pending = false;
          f.freed_at = now;
          Emit(Json{{"ev", "route_freed"}, {"route", SidingRoute(s)}});
        } else if (st != mb::wayside::CommandStatus::kRefusedInUse) {
          f.free_pending = false;
          Emit(Json{{"ev", "route_free_refused"}, {"route", SidingRoute(s)}, {"status", mb::wayside::ToString(st)}});
        }
      }
    }
    for (auto& t : trains) {
      bool blocked = false;
      bool lost = false;
      for (const auto& f : faults) {
        if (f.spec.train && *f.spec.train == t->spec.id && now >= f.spec.from_ms && now < f.spec.to_ms) {
          blocked = blocked || f.spec.type == FaultType::kRadioLoss;
          lost = lost || f.spec.type == FaultType::kTrackingLoss;
        }
      }
      t->radio_blocked = blocked;
      t->position_lost = lost;
    }
  }

  [[nodiscard]] std::int64_t SidingRoute(const FaultSpec& s) const {
    if (s.route != 0) {
      return s.route;
    }
    for (const auto& r : rl->routes) {
      if (r.reverse && !r.automatic) {
        return r.id;
      }
    }
    return 0;
  }

  // ---------------------------------------------------------------- radio
  void DeliverFrames() {
    std::array<std::uint8_t, tg::kPayloadMax> payload{};
    for (Frame& f : channel.Deliver(now)) {
      TrainRt* t = Find(f.train);
      if (t == nullptr || !t->OnLine()) {
        continue;
      }
      if (f.direction == Direction::kUplink) {
        const auto r = t->ground_ep.Receive(Clock32(now), f.bytes, payload);
        if (r.reason != tg::RejectReason::kNone) {
          ++up.rejected[VerdictName(r.reason)];
          Emit(Json{{"ev", "telegram_rejected"}, {"dir", "up"}, {"train", t->spec.id}, {"reason", VerdictName(r.reason)},
                    {"sent_ms", f.sent_ms}, {"corrupted_symbols", f.corrupted_symbols}});
          continue;
        }
        ++up.accepted;
        bool malformed = false;
        const auto rep = DecodePosition(std::span<const std::uint8_t>(payload).first(r.header.payload_len), malformed);
        if (malformed) {
          ++up.malformed;
          continue;
        }
        if (!rep) {
          continue;  // no position (tracking loss on board): nothing for the ground
        }
        if (rep->train_id != t->spec.id) {
          ++up.malformed;
          continue;
        }
        const auto st = ground->OnReport(*rep);
        ++report_status[mb::wayside::ToString(st)];
        if (st == mb::wayside::ReportStatus::kAccepted) {
          ++t->reports_accepted;
          if (Full()) {
            Emit(Json{{"ev", "report"}, {"train", t->spec.id}, {"front_mm", ToFront(*rep)}, {"correction_mm", rep->correction_mm},
                      {"speed_mm_s", rep->speed_mm_s}, {"sent_ms", f.sent_ms}, {"status", "Accepted"}});
          }
        } else {
          Emit(Json{{"ev", "report"}, {"train", t->spec.id}, {"front_mm", ToFront(*rep)}, {"status", mb::wayside::ToString(st)}});
        }
      } else {
        const auto r = t->train_ep.Receive(Clock32(now), f.bytes, payload);
        t->link_up = r.link == tg::LinkState::kUp;
        if (r.reason != tg::RejectReason::kNone) {
          ++down.rejected[VerdictName(r.reason)];
          Emit(Json{{"ev", "telegram_rejected"}, {"dir", "down"}, {"train", t->spec.id}, {"reason", VerdictName(r.reason)},
                    {"sent_ms", f.sent_ms}, {"corrupted_symbols", f.corrupted_symbols}});
          continue;
        }
        ++down.accepted;
        bool malformed = false;
        const auto tg = DecodeStopLimit(std::span<const std::uint8_t>(payload).first(r.header.payload_len), malformed);
        if (malformed || (tg && tg->train_id != t->spec.id)) {
          ++down.malformed;
          continue;
        }
        if (!tg) {
          continue;  // keep-alive: no limit for this train
        }
        const auto before = t->auth.Limit();
        const auto v = t->auth.Receive(tg->limit_mm, tg->issue_time_ms, now);
        ++verdicts[mb::onboard::ToString(v)];
        if (v == mb::onboard::Verdict::kAccept) {
          const bool changed_kind = tg->kind != t->limit_kind;
          t->limit_kind = tg->kind;
          t->tsr.Update(std::span<const messages::SpeedRestriction>(tg->restrictions.data(), tg->restriction_count),
                        ToMm(t->est_front_m), t->length_mm);
          if (Full() || !before || *before > tg->limit_mm || changed_kind) {
            Emit(Json{{"ev", "limit"}, {"train", t->spec.id}, {"limit_mm", tg->limit_mm}, {"kind", messages::ToString(tg->kind)},
                      {"issue_ms", tg->issue_time_ms}, {"age_ms", now - tg->issue_time_ms},
                      {"previous_mm", before ? Json(*before) : Json(nullptr)}});
          }
        } else {
          Emit(Json{{"ev", "limit_refused"}, {"train", t->spec.id}, {"verdict", mb::onboard::ToString(v)},
                    {"limit_mm", tg->limit_mm}, {"issue_ms", tg->issue_time_ms}});
        }
      }
    }
  }

  [[nodiscard]] std::int64_t ToFront(const messages::PositionReport& r) const {
    return rl->blocks_mm[std::min<std::size_t>(r.front_block, rl->blocks_mm.size() - 1)] + r.offset_mm;
  }

  // Canonical block + offset: the block holding front - 1 (block 0 for front 0).
  [[nodiscard]] std::pair<std::uint32_t, std::int64_t> Locate(std::int64_t front_mm) const {
    const auto& b = rl->blocks_mm;
    if (front_mm <= 0) {
      return {0, 0};
    }
    const auto it = std::lower_bound(b.begin(), b.end(), front_mm);  // first boundary >= front
    const auto idx = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - b.begin())) - 1;
    const std::size_t block = std::min(idx, b.size() - 2);
    return {static_cast<std::uint32_t>(block), front_mm - b[block]};
  }

  void GroundCycle() {
    // radio channel management: secure the handovers ahead of every tracked train
    for (auto& t : trains) {
      if (!t->OnLine()) {
        continue;
      }
      const auto ext = ground->Extended(t->spec.id);
      if (!ext) {
        continue;
      }
      for (const auto& h : gl.handovers) {
        if (h.position_mm >= ext->begin_mm && h.position_mm - ext->end_mm <= ToMm(sc.handover_secure_ahead_m) &&
            !ground->HandoverSecured(t->spec.id, h.id)) {
          ground->SecureHandover(t->spec.id, h.id);
          exercised.insert("REQ-MB-017");
          if (Full()) {
            Emit(Json{{"ev", "handover_secured"}, {"train", t->spec.id}, {"handover", h.id}});
          }
        }
      }
    }
    const std::vector<bool> before = points_reverse;
    ground->Cycle(now);
    ++ground_cycles;
    // points movement (REQ-MB-011)
    for (std::size_t p = 0; p < gl.points.size(); ++p) {
      points_reverse[p] = ground->PointsReverse(p);
      if (points_reverse[p] != before[p]) {
        ++checks["REQ-MB-011"].checks;
        Emit(Json{{"ev", "points"}, {"points", rl->points[p].id}, {"reverse", points_reverse[p]}});
        for (const auto& t : trains) {
          if (t->OnLine() && core::Overlaps(t->RearMm(), t->FrontMm(), gl.points[p].section.begin_mm,
                                               gl.points[p].section.end_mm)) {
            Violate("REQ-MB-011", "move@" + std::to_string(now) + "/" + rl->points[p].id + "/" + std::to_string(t->spec.id),
                    "points " + rl->points[p].id + " moved under train " + std::to_string(t->spec.id));
          }
        }
      }
    }
    for (auto& f : faults) {
      if (f.spec.type == FaultType::kPossession && f.possession_id != 0) {
        const auto st = ground->Possession(f.possession_id);
        auto& prev = possession_state[f.possession_id];
        if (st != prev) {
          Emit(Json{{"ev", "possession"}, {"possession", f.possession_id}, {"state", mb::wayside::ToString(st)}});
          if (st == mb::wayside::PossessionState::kActive && !f.active_at) {
            f.active_at = now;
          }
          prev = st;
        }
      }
      if (f.spec.type == FaultType::kSidingRequest && f.started && !f.active_at &&
          ground->RouteSet(static_cast<std::uint32_t>(SidingRoute(f.spec)))) {
        f.active_at = now;
        Emit(Json{{"ev", "route_set"}, {"route", SidingRoute(f.spec)}});
      }
    }
    // per-train outputs and telegrams
    std::map<std::uint32_t, const messages::StopLimitTelegram*> tgs;
    for (const auto& tg : ground->Telegrams()) {
      tgs[tg.train_id] = &tg;
    }
    Json cyc = Json::array();
    for (auto& t : trains) {
      if (!t->OnLine()) {
        continue;
      }
      const auto o = ground->Train(t->spec.id);
      if (!o) {
        continue;
      }
      if (o->abnormal != t->abnormal) {
        Emit(Json{{"ev", o->abnormal ? "tracking_abnormal" : "tracking_restored"}, {"train", t->spec.id}});
        if (o->abnormal) {
          ++abnormal_events;
          exercised.insert("REQ-MB-004");
        }
        for (auto& f : faults) {
          if (f.spec.train && *f.spec.train == t->spec.id && f.started) {
            if (o->abnormal && !f.abnormal_at) {
              f.abnormal_at = now;
            }
            if (!o->abnormal && f.ended && !f.tracked_again_at) {
              f.tracked_again_at = now;
            }
          }
        }
      }
      if (o->kind != t->ground_kind && !o->abnormal) {
        Emit(Json{{"ev", "limit_kind"}, {"train", t->spec.id}, {"kind", messages::ToString(o->kind)},
                  {"limit_mm", o->limit_mm ? Json(*o->limit_mm) : Json(nullptr)}});
      }
      t->abnormal = o->abnormal;
      t->ground_limit = o->limit_mm;
      t->ground_kind = o->kind;
      Json c{{"train", t->spec.id}, {"limit_mm", o->limit_mm ? Json(*o->limit_mm) : Json(nullptr)},
             {"kind", messages::ToString(o->kind)}, {"abnormal", o->abnormal}};
      cyc.push_back(c);
      std::vector<std::uint8_t> payload;
      const auto it = tgs.find(t->spec.id);
      if (it != tgs.end()) {
        payload = EncodeStopLimit(*it->second);
        ++telegrams_issued;
        exercised.insert("REQ-MB-024");
        exercised.insert("REQ-MB-006");
      } else {
        payload = EncodeKeepAlive();
      }
      tg::EncodedFrame frame{};
      const auto out = t->ground_ep.Cycle(Clock32(now), payload, frame);
      if (out.status == tg::SendStatus::kSent) {
        channel.Send(t->spec.id, Direction::kDownlink, now, frame.View(), t->radio_blocked);
      }
    }
    Emit(Json{{"ev", "cycle"}, {"trains", cyc}});
  }

  void SendReports() {
    for (auto& t : trains) {
      if (!t->OnLine() || now < t->next_report_ms) {
        continue;
      }
      t->next_report_ms += sc.report_period_ms;
      std::vector<std::uint8_t> payload;
      if (t->position_lost) {
        payload = EncodeNoPosition();
      } else {
        const std::int64_t front = std::clamp<std::int64_t>(ToMm(t->est_front_m), 0, rl->length_mm);
        const auto [block, offset] = Locate(front);
        messages::PositionReport rep{};
        rep.train_id = t->spec.id;
        rep.front_block = block;
        rep.offset_mm = offset;
        rep.length_mm = t->length_mm;
        rep.correction_mm = CorrectionMm(*t);
        rep.last_balise_mm = t->last_balise_mm;
        rep.speed_mm_s = static_cast<std::int64_t>(std::llround(t->motion.speed * 1000.0));
        rep.direction = mb::wayside::Direction::kNominal;
        payload = EncodePosition(rep);
        ++t->reports_sent;
        exercised.insert("REQ-MB-001");
        exercised.insert("REQ-MB-002");
        exercised.insert("REQ-MB-003");
      }
      tg::EncodedFrame frame{};
      const auto out = t->train_ep.Cycle(Clock32(now), payload, frame);
      t->link_up = out.link == tg::LinkState::kUp;
      if (out.status == tg::SendStatus::kSent) {
        channel.Send(t->spec.id, Direction::kUplink, now, frame.View(), t->radio_blocked);
      }
    }
  }

  // ---------------------------------------------------------------- driving
  // Highest speed the line's speed limits and the held speed restrictions allow at the
  // next step (braking curves to lower limits ahead with deceleration b).
  [[nodiscard]] double LineSpeed(const TrainRt& t, double safe_front, double rear, double b, double look) const {
    double v = std::numeric_limits<double>::infinity();
    const double front = safe_front + look;
    const auto limit_mps = [](const SpeedLimit& s) { return static_cast<double>(s.kmh) / 3.6; };
    rl->ForEachLimitActing(rear, front, [&](std::size_t i) { v = std::min(v, limit_mps(rl->speed_limits[i])); }, 1000.0);
    for (const auto& s : rl->speed_limits) {
      const double begin = ToM(s.section.begin_mm);
      if (begin > front) {  // ahead: the speed from which braking with b reaches the limit at its begin
        v = std::min(v, SpeedAfter(limit_mps(s), b, begin - front));
      }
    }
    const auto front_mm = ToMm(t.est_front_m);
    if (const auto tsr = t.tsr.ApplicableSpeed(front_mm, t.length_mm)) {
      v = std::min(v, static_cast<double>(*tsr) / 1000.0);
    }
    for (const auto& r : t.tsr.Held()) {
      const double begin = ToM(r.begin_mm);
      const double lim = static_cast<double>(r.speed_mm_s) / 1000.0;
      if (begin >= front) {
        v = std::min(v, SpeedAfter(lim, b, begin - front));
      } else if (rear < ToM(r.end_mm)) {
        v = std::min(v, lim);
      }
    }
    return v;
  }

  Control Drive(TrainRt& t, double dt) {
    const TrainPerformance& p = t.spec.performance;
    const double v = t.motion.speed;
    const double corr = ToM(CorrectionMm(t));
    const double safe_front = t.est_front_m + corr;
    const double rear = t.est_front_m - p.length_m - corr;
    t.link_up = t.train_ep.Link() == tg::LinkState::kUp;
    const bool usable = t.auth.Usable(now) && t.link_up;
    Control c;
    const auto limit_mm = t.auth.Limit();
    if (!usable || !limit_mm) {
      // no usable authority (none yet, expired, or radio link down): standstill demanded
      if (!t.eb && v > 0.0) {
        ++t.emergency_brakes;
        Emit(Json{{"ev", "emergency_brake"}, {"train", t.spec.id}, {"speed_mps", R2(v)},
                  {"reason", !t.link_up ? "radio link not up" : "no usable authority"}});
        exercised.insert("REQ-MB-009");
      }
      t.eb = true;
      c.emergency = true;
      return c;
    }
    const double limit = ToM(*limit_mm);
    const double d = limit - safe_front;
    const double fall = SteepestFall(safe_front, std::max(safe_front, limit) + 1.0);
    const double bs = std::max(0.05, p.service_decel_mps2 - GradeDecel(fall));
    const double be = std::max(0.05, p.emergency_decel_mps2 - GradeDecel(fall));
    const double v_e = CurveSpeed(d, be, sc.supervision.emergency_free_running_s);
    if (v > v_e + 1e-9 && !t.eb) {
      ++t.emergency_brakes;
      t.eb = true;
      Emit(Json{{"ev", "emergency_brake"}, {"train", t.spec.id}, {"speed_mps", R2(v)}, {"reason", "emergency curve exceeded"},
                {"distance_to_limit_m", R2(d)}});
    }
    if (t.eb) {
      if (v > 0.0) {
        c.emergency = true;
        return c;
      }
      t.eb = false;  // standstill with a usable authority: released
    }
    if (t.position_lost || t.phase == Phase::kStanding || t.phase == Phase::kDwelling) {
      c.brake_mps2 = p.service_decel_mps2;  // hold / brake to a stop
      return c;
    }
    // running: target speed for the end of this step
    const double look = v * dt;
    double target = std::min(p.max_speed_mps, t.spec.speed_cap_mps.value_or(p.max_speed_mps));
    target = std::min(target, LineSpeed(t, safe_front, rear, bs, look));
    target = std::min(target, CurveSpeed(d - sc.supervision.margin_m - look, bs, sc.supervision.free_running_s));
    if (t.next_stop < t.spec.stops.size()) {
      const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
      const double ds = ToM(st->stop_mm) - t.est_front_m;
      const double vs = ds > 0.5 ? std::max(kCreepMps, CurveSpeed(ds - 0.3 - look, kStationDecelShare * bs, 0.0)) : 0.0;
      target = std::min(target, vs);
    }
    target = std::max(0.0, target);
    if (target < 0.01 && v < 0.5) {
      c.brake_mps2 = p.service_decel_mps2;  // stopping or standing: full service brake holds the train
      return c;
    }
    const double other = NetAcceleration(p, Control{}, v, MeanGradient(t.motion.position - p.length_m, t.motion.position));
    const double need = (target - v) / dt - other;  // applied acceleration needed
    if (need > 0.0) {
      c.traction_mps2 = std::min(need, p.accel_mps2);
    } else {
      c.brake_mps2 = std::min(-need, p.service_decel_mps2);
    }
    return c;
  }

  void EnterTrains() {
    for (auto& tp : trains) {
      TrainRt& t = *tp;
      if (t.phase == Phase::kPending && now >= t.spec.enter_ms) {
        if (EntryClear(t)) {
          Enter(t);
        } else if (!t.deferral_logged) {
          t.deferral_logged = true;
          Emit(Json{{"ev", "entry_deferred"}, {"train", t.spec.id}});
        }
      }
    }
  }

  void MoveTrains() {
    const double dt = ToS(sc.step_ms);
    for (auto& tp : trains) {
      TrainRt& t = *tp;
      if (!t.OnLine()) {
        continue;
      }
      // phase transitions at t
      if (t.phase == Phase::kStanding && now >= t.spec.depart_ms) {
        t.phase = Phase::kRunning;
        Emit(Json{{"ev", "depart"}, {"train", t.spec.id}});
      }
      if (t.phase == Phase::kDwelling && now >= t.dwell_until_ms) {
        ++t.next_stop;
        t.phase = Phase::kRunning;
        Emit(Json{{"ev", "depart"}, {"train", t.spec.id}});
        if (t.next_stop >= t.spec.stops.size()) {
          Exit(t, "terminus (last stop)");
          continue;
        }
      }
      const Control c = Drive(t, dt);
      const double grad = MeanGradient(t.motion.position - t.spec.performance.length_m, t.motion.position);
      const double a = NetAcceleration(t.spec.performance, c, t.motion.speed, grad);
      const Motion before = t.motion;
      t.motion = offline::Advance(before, a, dt);
      const double moved = t.motion.position - before.position;
      // odometry: under-reads by odo_error; a balise passed resets it
      t.est_front_m += moved * (1.0 + t.odo_error);
      while (t.next_balise < rl->balises.size() && ToMm(t.motion.position) >= rl->balises[t.next_balise].position_mm) {
        const auto& b = rl->balises[t.next_balise];
        const double beyond = t.motion.position - ToM(b.position_mm);
        t.odo_error = -kOdometryErrorShare * static_cast<double>(mbp::length_correction_ppm) / 1e6 * odo_prng.Uniform();
        t.balise_est_m = ToM(b.position_mm);
        t.balise_true_m = ToM(b.position_mm);
        t.est_front_m = std::max(t.est_front_m, t.balise_est_m + beyond * (1.0 + t.odo_error));
        t.last_balise_mm = b.position_mm;
        ++t.next_balise;
        if (Full()) {
          Emit(Json{{"ev", "balise"}, {"train", t.spec.id}, {"balise", b.id}});
        }
      }
      t.max_speed = std::max(t.max_speed, t.motion.speed);
      if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && (t.eb || !t.auth.Usable(now))) {
        t.standstill_no_authority_ms += sc.step_ms;
      }
      // station arrival
      if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop < t.spec.stops.size()) {
        const Station* st = rl->FindStation(t.spec.stops[t.next_stop].station);
        const double ds = ToM(st->stop_mm) - t.est_front_m;
        if (ds <= kStopWindowM) {
          t.phase = Phase::kDwelling;
          t.dwell_until_ms = now + sc.step_ms + t.spec.stops[t.next_stop].dwell_ms;
          ++t.stops_made;
          Emit(Json{{"ev", "arrive"}, {"train", t.spec.id}, {"station", st->name}, {"stop_error_m", R2(-ds)}});
        }
      }
      // beyond an accepted system boundary: handed over to the neighbour once its rear has
      // passed the boundary (until then it obstructs like any train)
      if (rl->system_boundary_mm && sc.boundary_accepted && t.RearMm() >= *rl->system_boundary_mm) {
        Exit(t, "crossed the system boundary");
        continue;
      }
      // end of the line: leaves the area (removed from the ground)
      if (t.phase == Phase::kRunning && t.motion.speed <= 0.0 && t.next_stop >= t.spec.stops.size() &&
          t.limit_kind == messages::Obstruction::kEndOfTrack && t.auth.Limit()) {
        const double d = ToM(*t.auth.Limit()) - t.est_front_m - ToM(CorrectionMm(t));
        if (d <= sc.supervision.margin_m + kExitWindowM) {
          Exit(t, "end of line");
        }
      }
    }
  }

  // ---------------------------------------------------------------- invariants
  void CheckInvariants() {
    active_prev.swap(active_now);
    active_now.clear();
    std::vector<const TrainRt*> on;
    for (const auto& t : trains) {
      if (t->OnLine()) {
        on.push_back(t.get());
      }
    }
    std::sort(on.begin(), on.end(),
              [](const TrainRt* a, const TrainRt* b) { return a->motion.position < b->motion.position; });
    // REQ-MB-008 separation (true ranges; neighbours in front order suffice)
    ++checks["REQ-MB-008"].checks;
    for (std::size_t i = 1; i < on.size(); ++i) {
      const TrainRt& f = *on[i - 1];
      const TrainRt& l = *on[i];
      if (core::Overlaps(f.RearMm(), f.FrontMm(), l.RearMm(), l.FrontMm())) {
        const std::string a = std::to_string(f.spec.id);
        const std::string b = std::to_string(l.spec.id);
        Violate("REQ-MB-008", a + "/" + b,
                "true ranges of trains " + a + " [" + std::to_string(f.RearMm()) + ", " + std::to_string(f.FrontMm()) +
                    ") and " + b + " [" + std::to_string(l.RearMm()) + ", " + std::to_string(l.FrontMm()) +
                    ") mm overlap");
      }
    }
    for (std::size_t i = 0; i < on.size(); ++i) {
      const TrainRt& t = *on[i];
      const auto lim = t.auth.Limit();
      // ASM-013: the true front never passes the last accepted stop limit
      ++checks["ASM-013"].checks;
      const double bound = lim ? ToM(*lim) : ToM(t.spec.initial_front_mm);
      if (t.motion.position > bound + kLimitToleranceM) {
        Violate("ASM-013", std::to_string(t.spec.id),
                "train " + std::to_string(t.spec.id) + " front " + Fmt(t.motion.position) +
                    " m beyond its on-board stop limit " + Fmt(bound) + " m");
      }
      if (!lim || !t.auth.Usable(now)) {
        continue;
      }
      // REQ-MB-009: the usable on-board authority lies within what the ground protects
      ++checks["REQ-MB-009"].checks;
      const auto prot = ground->ProtectedAuthority(t.spec.id);
      if (!prot || *lim > *prot) {
        const std::string id = std::to_string(t.spec.id);
        Violate("REQ-MB-009", id,
                "train " + id + " usable limit " + std::to_string(*lim) + " mm beyond the ground's protected authority " +
                    (prot ? std::to_string(*prot) + " mm" : std::string("(none)")));
      }
      // REQ-MB-007: never beyond the true rear of the next train ahead minus its margin
      if (i + 1 < on.size()) {
        ++checks["REQ-MB-007"].checks;
        const TrainRt& ahead = *on[i + 1];
        if (*lim > ahead.RearMm() - mbp::margin_preceding_train_mm) {
          const std::string id = std::to_string(t.spec.id);
          Violate("REQ-MB-007", id,
                  "train " + id + " usable limit " + std::to_string(*lim) + " mm beyond the true rear of train " +
                      std::to_string(ahead.spec.id) + " (" + std::to_string(ahead.RearMm()) + " mm) minus the margin");
        }
      }
    }
    // REQ-MB-014: no train inside an active possession
    for (const auto& f : faults) {
      if (f.spec.type != FaultType::kPossession || f.possession_id == 0) {
        continue;
      }
      if (ground->Possession(f.possession_id) != mb::wayside::PossessionState::kActive) {
        continue;
      }
      ++checks["REQ-MB-014"].checks;
      for (const TrainRt* t : on) {
        if (core::Overlaps(t->RearMm(), t->FrontMm(), f.spec.begin_mm, f.spec.end_mm)) {
          const std::string id = std::to_string(t->spec.id);
          const std::string pid = std::to_string(f.possession_id);
          Violate("REQ-MB-014", id + "/" + pid, "train " + id + " inside active possession " + pid);
        }
      }
    }
    // REQ-MB-013: trains on points only in the running line's route position
    for (std::size_t p = 0; p < gl.points.size(); ++p) {
      ++checks["REQ-MB-013"].checks;
      if (points_reverse[p] == points_running_reverse[p]) {
        continue;
      }
      for (const TrainRt* t : on) {
        if (core::Overlaps(t->RearMm(), t->FrontMm(), gl.points[p].section.begin_mm, gl.points[p].section.end_mm)) {
          const std::string id = std::to_string(t->spec.id);
          Violate("REQ-MB-013", id + "/" + rl->points[p].id,
                  "train " + id + " on points " + rl->points[p].id + " lying against its route");
        }
      }
    }
  }

  void Measure() {
    for (auto& f : faults) {
      if (!f.spec.train || !f.started) {
        continue;
      }
      const TrainRt* t = Find(*f.spec.train);
      if (t == nullptr || !t->OnLine()) {
        continue;
      }
      if (!f.ended && !f.standstill_at && t->motion.speed <= 0.0) {
        f.standstill_at = now;
      }
      if (f.ended && !f.moving_again_at && t->motion.speed > 0.0) {
        f.moving_again_at = now;
      }
    }
    if (sc.gap && now >= sc.gap->from_ms && now <= sc.gap->to_ms) {
      const TrainRt* l = Find(sc.gap->leader);
      const TrainRt* f = Find(sc.gap->follower);
      if (l != nullptr && f != nullptr && l->OnLine() && f->OnLine()) {
        const double gap = l->Rear() - f->motion.position;
        ++gap_n;
        gap_sum += gap;
        gap_min = std::min(gap_min, gap);
        gap_max = std::max(gap_max, gap);
        gap_vl += l->motion.speed;
        gap_vf += f->motion.speed;
      }
    }
    if (now % sc.sample_ms == 0) {
      for (auto& t : trains) {
        if (!t->OnLine()) {
          continue;
        }
        const auto lim = t->auth.Limit();
        const bool usable = lim && t->auth.Usable(now);
        t->samples.push_back(Sample{now, t->motion.position, t->Rear(), usable ? ToM(*lim) : std::nan("")});
      }
    }
  }

  bool Step() {
    if (now >= sc.duration_ms) {
      return false;
    }
    ApplySchedule();
    EnterTrains();
    DeliverFrames();
    if (now % sc.ground_cycle_ms == 0) {
      GroundCycle();
    }
    SendReports();
    MoveTrains();
    now += sc.step_ms;
    CheckInvariants();
    Measure();
    return true;
  }
};

// ================================================================== public interface

Simulation::Simulation(Scenario scenario, Line line) : impl_(std::make_unique<Impl>(std::move(scenario), std::move(line))) {
  if (tg::CryptoInit() != tg::AeadStatus::kOk) {
    throw std::runtime_error("libsodium could not be initialised");
  }
  impl_->Setup();
}

Simulation::~Simulation() = default;

std::int64_t Simulation::NowMs() const { return impl_->now; }
const std::vector<Violation>& Simulation::Violations() const { return impl_->violations; }
const Scenario& Simulation::GetScenario() const { return impl_->sc; }

bool Simulation::Step() { return impl_->Step(); }

void Simulation::Run(const RunOptions& options) {
  Impl& s = *impl_;
  s.opts = &options;
  if (options.log != nullptr) {
    Json head{{"schema", "railproof/sim-log/1"},
              {"scenario", s.sc.name},
              {"line", s.line.name},
              {"running_line", s.rl->id},
              {"seed", s.sc.seed}};
    std::string h = head.dump();
    h.pop_back();  // reopen the object
    *options.log << h << ",\"events\":[";
  }
  int next_decile = 1;
  while (s.Step()) {
    while (options.progress && next_decile <= 10 && s.now * 10 >= s.sc.duration_ms * next_decile) {
      std::size_t on = 0;
      std::size_t done = 0;
      for (const auto& t : s.trains) {
        on += t->OnLine() ? 1U : 0U;
        done += t->phase == Phase::kExited ? 1U : 0U;
      }
      char buf[256];
      std::snprintf(buf, sizeof buf, "%s: %3d%%  t = %.0f of %.0f s, trains on line %zu, left %zu, violations %zu",
                    s.sc.name.c_str(), next_decile * 10, ToS(s.now), ToS(s.sc.duration_ms), on, done,
                    s.violations.size());
      options.progress(buf);
      ++next_decile;
    }
  }
  if (options.log != nullptr) {
    *options.log << "\n],\"summary\":" << Summary().dump(1) << "}\n";
  }
  s.opts = nullptr;
}

std::vector<TrainView> Simulation::Trains() const {
  std::vector<TrainView> out;
  for (const auto& t : impl_->trains) {
    TrainView v;
    v.id = t->spec.id;
    v.phase = ToString(t->phase);
    v.front_m = t->motion.position;
    v.rear_m = t->Rear();
    v.speed_mps = t->motion.speed;
    if (const auto lim = t->auth.Limit()) {
      v.limit_m = ToM(*lim);
    }
    v.authority_usable = t->auth.Usable(impl_->now);
    v.link_up = t->link_up;
    v.emergency = t->eb;
    v.abnormal = t->abnormal;
    v.stops_made = t->stops_made;
    v.emergency_brakes = t->emergency_brakes;
    out.push_back(v);
  }
  return out;
}

std::optional<TrainView> Simulation::Train(std::uint16_t id) const {
  for (auto& v : Trains()) {
    if (v.id == id) {
      return v;
    }
  }
  return std::nullopt;
}

std::optional<GapResult> Simulation::Gap() const {
  const Impl& s = *impl_;
  if (!s.sc.gap || s.gap_n == 0) {
    return std::nullopt;
  }
  GapResult g;
  g.leader = s.sc.gap->leader;
  g.follower = s.sc.gap->follower;
  g.from_s = ToS(s.sc.gap->from_ms);
  g.to_s = ToS(s.sc.gap->to_ms);
  g.samples = s.gap_n;
  const auto n = static_cast<double>(s.gap_n);
  g.mean_m = s.gap_sum / n;
  g.min_m = s.gap_min;
  g.max_m = s.gap_max;
  g.leader_speed_kmh = s.gap_vl / n * 3.6;
  g.follower_speed_kmh = s.gap_vf / n * 3.6;
  return g;
}

nlohmann::ordered_json Simulation::Summary() const {
  const Impl& s = *impl_;
  Json j;
  j["schema"] = "railproof/sim-summary/1";
  j["scenario"] = s.sc.name;
  j["description"] = s.sc.description;
  j["line"] = s.line.name;
  j["line_assumption"] = s.line.assumption;
  j["running_line"] = s.rl->id;
  j["simulated_s"] = ToS(s.now);
  j["step_ms"] = s.sc.step_ms;
  j["seed"] = s.sc.seed;
  j["ground_cycle_ms"] = s.sc.ground_cycle_ms;
  j["report_period_ms"] = s.sc.report_period_ms;
  j["margin_policy"] = s.sc.margin_policy == MarginPolicy::kD2 ? "d2" : "reported";
  j["channel"] = Json{{"loss_probability", s.sc.channel.loss_probability},
                      {"min_delay_ms", s.sc.channel.min_delay_ms},
                      {"max_delay_ms", s.sc.channel.max_delay_ms},
                      {"corrupt_probability", s.sc.channel.corrupt_probability}};
  j["supervision"] = Json{{"margin_m", s.sc.supervision.margin_m},
                          {"free_running_s", s.sc.supervision.free_running_s},
                          {"emergency_free_running_s", s.sc.supervision.emergency_free_running_s},
                          {"limit_tolerance_m", kLimitToleranceM}};
  std::uint64_t nviol = 0;
  for (const auto& [id, c] : s.checks) {
    nviol += c.violations;
  }
  j["result"] = nviol == 0 ? "PASS" : "FAIL";
  j["violations"] = nviol;
  std::set<std::string> reqs = s.exercised;
  for (const auto& [id, c] : s.checks) {
    if (c.checks > 0) {
      reqs.insert(id);
    }
  }
  if (s.ground_cycles > 0) {
    reqs.insert("REQ-MB-010");
    reqs.insert("REQ-MB-018");
  }
  Json req = Json::array();
  for (const auto& r : reqs) {
    if (r.rfind("REQ-", 0) == 0) {
      req.push_back(r);
    }
  }
  j["requirements"] = req;
  Json asm_ = Json::array();
  for (const auto& r : reqs) {
    if (r.rfind("ASM-", 0) == 0) {
      asm_.push_back(r);
    }
  }
  j["assumptions_checked"] = asm_;
  Json checks = Json::object();
  for (const auto& [id, c] : s.checks) {
    checks[id] = Json{{"checks", c.checks}, {"violations", c.violations}, {"violation_steps", c.violation_steps}};
  }
  j["checks"] = checks;
  Json vl = Json::array();
  for (std::size_t i = 0; i < s.violations.size() && i < 50; ++i) {
    vl.push_back(Json{{"t_s", ToS(s.violations[i].t_ms)}, {"requirement", s.violations[i].requirement},
                      {"detail", s.violations[i].detail}});
  }
  j["violation_list"] = vl;

  Json trains = Json::array();
  std::size_t entered = 0;
  std::size_t exited = 0;
  std::int64_t last_exit = -1;
  double total_km = 0.0;
  for (const auto& t : s.trains) {
    entered += t->entered_ms >= 0 ? 1U : 0U;
    exited += t->exited_ms >= 0 ? 1U : 0U;
    last_exit = std::max(last_exit, t->exited_ms);
    const double dist = t->entered_ms >= 0 ? t->motion.position - t->start_m : 0.0;
    total_km += dist / 1000.0;
    trains.push_back(Json{{"id", t->spec.id},
                          {"phase", ToString(t->phase)},
                          {"entered_s", t->entered_ms >= 0 ? Json(ToS(t->entered_ms)) : Json(nullptr)},
                          {"exited_s", t->exited_ms >= 0 ? Json(ToS(t->exited_ms)) : Json(nullptr)},
                          {"front_m", R1(t->motion.position)},
                          {"distance_m", R1(dist)},
                          {"max_speed_kmh", R1(t->max_speed * 3.6)},
                          {"stops_made", t->stops_made},
                          {"emergency_brakes", t->emergency_brakes},
                          {"standstill_without_authority_s", ToS(t->standstill_no_authority_ms)},
                          {"reports_sent", t->reports_sent},
                          {"reports_accepted", t->reports_accepted}});
  }
  j["trains"] = trains;
  j["progress"] = Json{{"trains_entered", entered},
                       {"trains_left_line", exited},
                       {"last_departure_from_line_s", last_exit >= 0 ? Json(ToS(last_exit)) : Json(nullptr)},
                       {"train_km", R2(total_km)}};
  const auto dir = [&](Direction d, const DirStats& ds) {
    const ChannelStats& cs = s.channel.Stats(d);
    Json rej = Json::object();
    for (const auto& [k, v] : ds.rejected) {
      rej[k] = v;
    }
    return Json{{"sent", cs.sent},           {"lost_random", cs.lost_random}, {"lost_fault", cs.lost_fault},
                {"corrupted", cs.corrupted}, {"delivered", cs.delivered},     {"accepted", ds.accepted},
                {"rejected", rej},           {"malformed_payload", ds.malformed}};
  };
  j["radio"] = Json{{"uplink", dir(Direction::kUplink, s.up)}, {"downlink", dir(Direction::kDownlink, s.down)}};
  Json rs = Json::object();
  for (const auto& [k, v] : s.report_status) {
    rs[k] = v;
  }
  Json vs = Json::object();
  for (const auto& [k, v] : s.verdicts) {
    vs[k] = v;
  }
  j["ground"] = Json{{"cycles", s.ground_cycles},
                     {"stop_limit_telegrams", s.telegrams_issued},
                     {"reports", rs},
                     {"tracking_abnormal_events", s.abnormal_events}};
  j["onboard"] = Json{{"stop_limit_verdicts", vs}};
  const auto after = [](const std::optional<std::int64_t>& at, std::int64_t ref) {
    return at ? Json(ToS(*at - ref)) : Json(nullptr);
  };
  Json faults = Json::array();
  for (const auto& f : s.faults) {
    Json fj{{"type", ToString(f.spec.type)}, {"from_s", ToS(f.spec.from_ms)}, {"to_s", ToS(f.spec.to_ms)}};
    switch (f.spec.type) {
      case FaultType::kRadioLoss:
      case FaultType::kTrackingLoss:
        fj["train"] = *f.spec.train;
        fj["abnormal_after_s"] = after(f.abnormal_at, f.spec.from_ms);
        fj["standstill_after_s"] = after(f.standstill_at, f.spec.from_ms);
        fj["tracked_again_after_end_s"] = after(f.tracked_again_at, f.spec.to_ms);
        fj["moving_again_after_end_s"] = after(f.moving_again_at, f.spec.to_ms);
        break;
      case FaultType::kPossession:
        fj["range_m"] = {ToM(f.spec.begin_mm), ToM(f.spec.end_mm)};
        fj["request_status"] = f.status;
        fj["active_after_s"] = after(f.active_at, f.spec.from_ms);
        break;
      case FaultType::kSidingRequest:
        fj["route"] = s.SidingRoute(f.spec);
        fj["request_status"] = f.status;
        fj["set_after_s"] = after(f.active_at, f.spec.from_ms);
        fj["freed_after_end_s"] = after(f.freed_at, f.spec.to_ms);
        break;
      case FaultType::kSpeedRestriction:
        fj["range_m"] = {ToM(f.spec.begin_mm), ToM(f.spec.end_mm)};
        fj["speed_kmh"] = R1(f.spec.speed_mps * 3.6);
        fj["request_status"] = f.status;
        break;
    }
    faults.push_back(fj);
  }
  j["faults"] = faults;
  if (const auto g = Gap()) {
    j["gap"] = Json{{"leader", g->leader},
                    {"follower", g->follower},
                    {"window_s", {g->from_s, g->to_s}},
                    {"samples", g->samples},
                    {"settled_gap_m", R1(g->mean_m)},
                    {"min_m", R1(g->min_m)},
                    {"max_m", R1(g->max_m)},
                    {"leader_speed_kmh", R1(g->leader_speed_kmh)},
                    {"follower_speed_kmh", R1(g->follower_speed_kmh)}};
  } else {
    j["gap"] = nullptr;
  }
  j["events"] = s.events;
  return j;
}

std::string Simulation::Svg() const {
  const Impl& s = *impl_;
  const double t_end = std::max(1.0, ToS(s.now));
  const double len_km = ToM(s.rl->length_mm) / 1000.0;
  // distance range: what the trains covered (whole line if they spread over it)
  double lo = len_km;
  double hi = 0.0;
  for (const auto& t : s.trains) {
    for (const auto& p : t->samples) {
      lo = std::min(lo, p.rear_m / 1000.0);
      hi = std::max(hi, p.front_m / 1000.0);
      if (!std::isnan(p.limit_m)) {
        hi = std::max(hi, std::min(len_km, p.limit_m / 1000.0));
      }
    }
  }
  for (const auto& f : s.faults) {
    if (f.spec.type == FaultType::kPossession || f.spec.type == FaultType::kSpeedRestriction) {
      lo = std::min(lo, ToM(f.spec.begin_mm) / 1000.0);
      hi = std::max(hi, ToM(f.spec.end_mm) / 1000.0);
    }
  }
  if (hi <= lo) {
    lo = 0.0;
    hi = len_km;
  }
  const double pad = std::max(0.05, (hi - lo) * 0.03);
  lo = std::max(0.0, lo - pad);
  hi = std::min(len_km, hi + pad);
  SvgPlot plot(0.0, t_end, lo, hi);
  plot.SetTitle("Time-distance diagram: " + s.sc.name + " (" + s.line.name + ", running line " + s.rl->id + ")");
  plot.SetXLabel("time [s]");
  plot.SetYLabel("distance along the running line [km]");
  static const std::array<const char*, 10> kColours = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                                                       "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  for (const auto& st : s.rl->stations) {
    const double y = ToM(st.stop_mm) / 1000.0;
    if (y >= lo && y <= hi) {
      plot.AddRect(0.0, t_end, ToM(st.platform.begin_mm) / 1000.0, ToM(st.platform.end_mm) / 1000.0, "#999999", 0.12);
      plot.AddHLine(y, st.name, SvgStyle{"#999999", 0.6, "2 3", 1.0});
    }
  }
  for (std::size_t p = 0; p < s.rl->points.size(); ++p) {
    const double y = ToM(s.rl->points[p].section.begin_mm) / 1000.0;
    if (y >= lo && y <= hi) {
      plot.AddHLine(y, "points " + s.rl->points[p].id, SvgStyle{"#bbbbbb", 0.5, "1 3", 1.0});
    }
  }
  bool any_poss = false;
  bool any_radio = false;
  bool any_track = false;
  bool any_siding = false;
  bool any_tsr = false;
  for (const auto& f : s.faults) {
    const double from = ToS(f.spec.from_ms);
    const double to = std::min(t_end, ToS(f.spec.to_ms));
    if (from > t_end) {
      continue;
    }
    switch (f.spec.type) {
      case FaultType::kPossession:
        plot.AddRect(from, to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#ff9900", 0.25,
                     "possession " + std::to_string(f.possession_id));
        if (f.active_at) {
          plot.AddRect(ToS(*f.active_at), to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#ff6600", 0.35);
        }
        any_poss = true;
        break;
      case FaultType::kSpeedRestriction:
        plot.AddRect(from, to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#33aa33", 0.18,
                     "TSR " + std::to_string(static_cast<int>(std::lround(f.spec.speed_mps * 3.6))) + " km/h");
        any_tsr = true;
        break;
      case FaultType::kSidingRequest: {
        for (const auto& r : s.rl->routes) {
          if (r.id == s.SidingRoute(f.spec)) {
            plot.AddRect(from, to, ToM(r.section.begin_mm) / 1000.0 - 0.05, ToM(r.section.end_mm) / 1000.0 + 0.05,
                         "#3366ff", 0.2, "siding route " + std::to_string(r.id));
          }
        }
        any_siding = true;
        break;
      }
      case FaultType::kRadioLoss:
      case FaultType::kTrackingLoss: {
        const TrainRt* t = s.Find(*f.spec.train);
        double a = hi;
        double b = lo;
        if (t != nullptr) {
          for (const auto& p : t->samples) {
            if (ToS(p.t_ms) >= from - 30.0 && ToS(p.t_ms) <= to + 30.0) {
              a = std::min(a, p.rear_m / 1000.0);
              b = std::max(b, p.front_m / 1000.0);
            }
          }
        }
        if (b < a) {
          break;  // the train was not on the line during the window: nothing to shade
        }
        const bool radio = f.spec.type == FaultType::kRadioLoss;
        plot.AddRect(from, to, a - 0.1, b + 0.1, radio ? "#ff0000" : "#9900cc", 0.15,
                     std::string(radio ? "radio loss T" : "tracking loss T") + std::to_string(*f.spec.train));
        (radio ? any_radio : any_track) = true;
        break;
      }
    }
  }
  const bool many = s.trains.size() > 12;
  for (std::size_t i = 0; i < s.trains.size(); ++i) {
    const auto& t = *s.trains[i];
    const std::string colour = kColours[i % kColours.size()];
    std::vector<std::pair<double, double>> front;
    std::vector<std::pair<double, double>> rear;
    std::vector<std::pair<double, double>> limit;
    std::int64_t prev = -1;
    for (const auto& p : t.samples) {
      if (prev >= 0 && p.t_ms - prev > s.sc.sample_ms) {
        front.emplace_back(0.0, std::nan(""));
        rear.emplace_back(0.0, std::nan(""));
        limit.emplace_back(0.0, std::nan(""));
      }
      prev = p.t_ms;
      front.emplace_back(ToS(p.t_ms), p.front_m / 1000.0);
      rear.emplace_back(ToS(p.t_ms), p.rear_m / 1000.0);
      limit.emplace_back(ToS(p.t_ms), std::isnan(p.limit_m) ? std::nan("") : p.limit_m / 1000.0);
    }
    plot.AddPolyline(limit, SvgStyle{colour, 0.9, "5 4", 0.8});
    plot.AddPolyline(rear, SvgStyle{colour, 0.8, "", 0.9});
    plot.AddPolyline(front, SvgStyle{colour, 1.6, "", 1.0});
    if (!many) {
      plot.AddLegend("train " + std::to_string(t.spec.id) + " front (thick), rear (thin)", SvgStyle{colour, 1.6, "", 1.0});
    }
  }
  if (many) {
    plot.AddLegend(std::to_string(s.trains.size()) + " trains: front (thick), rear (thin)", SvgStyle{"#1f77b4", 1.6, "", 1.0});
  }
  plot.AddLegend("on-board stop limit (dashed)", SvgStyle{"#555555", 0.9, "5 4", 1.0});
  plot.AddLegend("station platform", SvgStyle{"#999999", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  if (any_poss) {
    plot.AddLegend("possession requested / active", SvgStyle{"#ff9900", 1.0, "", 0.4}, SvgPlot::LegendKind::kBox);
  }
  if (any_tsr) {
    plot.AddLegend("temporary speed restriction", SvgStyle{"#33aa33", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  }
  if (any_siding) {
    plot.AddLegend("siding route requested", SvgStyle{"#3366ff", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  }
  if (any_radio) {
    plot.AddLegend("radio loss window", SvgStyle{"#ff0000", 1.0, "", 0.25}, SvgPlot::LegendKind::kBox);
  }
  if (any_track) {
    plot.AddLegend("tracking loss window", SvgStyle{"#9900cc", 1.0, "", 0.25}, SvgPlot::LegendKind::kBox);
  }
  for (std::size_t i = 0; i < s.violations.size() && i < 200; ++i) {
    plot.AddMarker(ToS(s.violations[i].t_ms), lo + (hi - lo) * 0.02, "#ff0000", i == 0 ? s.violations[i].requirement : "");
  }
  if (!s.violations.empty()) {
    plot.AddLegend("invariant violation", SvgStyle{"#ff0000", 3.0, "", 1.0});
  }
  return plot.Render();
}

}  // namespace railproof::sim
