// Line scenario simulation: setup, the step, the run, the event log and the violation
// records, and the public interface (simulation.hpp; the other steps: simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "railproof/tg/aead.hpp"

namespace railproof::sim {

void Simulation::Impl::Setup() {
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

void Simulation::Impl::Emit(Json ev) {
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

void Simulation::Impl::Violate(const std::string& req, const std::string& key, const std::string& detail) {
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

TrainRt* Simulation::Impl::Find(std::uint16_t id) {
  return const_cast<TrainRt*>(static_cast<const Impl*>(this)->Find(id));  // NOLINT(cppcoreguidelines-pro-type-const-cast)
}

const TrainRt* Simulation::Impl::Find(std::uint16_t id) const {
  for (const auto& t : trains) {
    if (t->spec.id == id) {
      return t.get();
    }
  }
  return nullptr;
}

std::vector<TrainRt*> Simulation::Impl::TrainsOnLine() const {
  std::vector<TrainRt*> on;
  for (const auto& t : trains) {
    if (t->OnLine()) {
      on.push_back(t.get());
    }
  }
  return on;
}

bool Simulation::Impl::Step() {
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

}  // namespace railproof::sim
