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

#include "railproof/generated/ra_params.hpp"
#include "railproof/tg/aead.hpp"

namespace railproof::sim {

namespace {

// The link keys of the line's key management: each train's key, drawn at setup.
bool KeyOf(const void* context, std::uint32_t train_id, std::array<std::uint8_t, tg::kKeyBytes>& key) {
  const auto& trains = *static_cast<const std::vector<std::unique_ptr<TrainRt>>*>(context);
  for (const auto& t : trains) {
    if (t->spec.id == train_id) {
      key = t->key;
      return true;
    }
  }
  return false;
}

}  // namespace

const TrainType* Simulation::Impl::TrainTypeOf(const TrainSpec& spec) const {
  const std::int64_t length_mm = ToMm(spec.performance.length_m);
  const std::string where = sc.file + ": " + spec.entry;
  if (spec.train_type) {
    for (const auto& type : types) {
      if (type.name == *spec.train_type) {
        if (type.length_mm != length_mm) {
          throw InputError(where + ".length_m: " + Fmt(spec.performance.length_m) + " m is not the length of train type " +
                           type.name + " (" + Fmt(ToM(type.length_mm)) + " m)");
        }
        return &type;
      }
    }
    throw InputError(where + ".train_type: no train type " + *spec.train_type + " in the train data");
  }
  const TrainType* found = nullptr;
  for (const auto& type : types) {
    if (type.length_mm == length_mm) {
      if (found != nullptr) {
        throw InputError(where + ": train types " + found->name + " and " + type.name + " both have length " +
                         Fmt(spec.performance.length_m) + " m: name one with train_type");
      }
      found = &type;
    }
  }
  if (found == nullptr) {
    throw InputError(where + ": no train type of length " + Fmt(spec.performance.length_m) +
                     " m (the on-board unit's train data); name one with train_type");
  }
  return found;
}

void Simulation::Impl::Setup() {
  rl = &SelectRunningLine(sc, line);
  CheckScenarioAgainstLine(sc, *rl);
  if (sc.step_ms != units::kOnboardCycleMs) {
    throw InputError(sc.file + ": step_ms: must be the on-board unit's cycle, " +
                     std::to_string(units::kOnboardCycleMs) + " ms, got " + std::to_string(sc.step_ms));
  }
  if (sc.report_period_ms % units::kOnboardCycleMs != 0 || sc.ground_cycle_ms % units::kOnboardCycleMs != 0) {
    throw InputError(sc.file + ": report_period_ms, ground_cycle_ms: must be multiples of the on-board cycle");
  }
  channel = Channel(ChannelConfig{sc.channel.loss_probability, sc.channel.min_delay_ms, sc.channel.max_delay_ms,
                                  sc.channel.corrupt_probability},
                    sc.seed);
  gl = BuildGroundLine(line, *rl,
                       sc.margin_policy == MarginPolicy::kD2 ? mb::wayside::MarginPolicy::kD2Buffers
                                                             : mb::wayside::MarginPolicy::kReportedCorrection,
                       sc.ground_cycle_ms);
  SetupOnboardLine();
  Prng key_prng(sc.seed ^ 0x6B65796B65796B65ULL);
  for (std::size_t i = 0; i < sc.trains.size(); ++i) {
    const TrainSpec& spec = sc.trains[i];
    auto t = std::make_unique<TrainRt>();
    t->spec = spec;
    t->length_mm = ToMm(spec.performance.length_m);
    t->type = TrainTypeOf(spec);
    t->limits = PermittedProfile(*rl, t->type->MaxSpeedMmS());
    // The vehicle must be the one the unit's data describe: no more traction than the patterns'
    // run-up assumes, brakes no weaker than the pattern decelerations (REQ-BR-010). A train
    // that is not is simulated as it is (a finding, not an input error): its overruns are
    // what the invariants are there to catch.
    const br::TrainData td = ToTrainData(*t->type);
    const TrainPerformance& p = spec.performance;
    const auto finding = [&](const std::string& what) {
      train_data_findings.push_back(spec.entry + ": " + what + " (train type " + t->type->name + ")");
    };
    if (ToMm(p.accel_mps2) > td.accel_max_mm_s2) {
      finding("accel_mps2 above the type's accel_max");
    }
    if (ToMm(p.service_decel_mps2) < td.beta_n7_mm_s2) {
      finding("service_decel_mps2 below the service pattern deceleration");
    }
    if (ToMm(p.emergency_decel_mps2) < td.beta_e_mm_s2) {
      finding("emergency_decel_mps2 below the emergency pattern deceleration");
    }
    t->motion.position = ToM(spec.initial_front_mm);
    for (auto& b : t->key) {
      b = static_cast<std::uint8_t>(key_prng.Next() >> 56U);
    }
    trains.push_back(std::move(t));
  }
  SetupWayside();
  for (std::size_t p = 0; p < gl.points.size(); ++p) {
    bool running_reverse = false;
    for (const auto& r : gl.routes) {
      if (r.points_index == p && r.automatic) {
        running_reverse = r.reverse;
        break;
      }
    }
    points_running_reverse.push_back(running_reverse);
    points_reverse.push_back(Ground().PointsReverse(p));
  }
  for (const auto& f : sc.faults) {
    FaultRt fr;
    fr.spec = f;
    faults.push_back(fr);
  }
  for (const char* id : {"REQ-MB-007", "REQ-MB-008", "REQ-MB-009", "REQ-MB-011", "REQ-MB-013", "REQ-MB-014",
                         "ASM-013", "REQ-BR-004", "REQ-RA-012"}) {
    checks[id];
  }
  if (!crossings.empty()) {
    checks["REQ-LC-002"];
    checks["REQ-LC-003"];
  }
}

// The on-board track database: blocks, gradients, balises (ids by index), crossings (ids by
// index, as the wayside unit's) and the odometry sections (one per gradient segment with its
// magnitude, the odometry's longest compensation time).
void Simulation::Impl::SetupOnboardLine() {
  obl.blocks_mm = rl->blocks_mm;
  obl.gradients = GradientProfile(*rl);
  for (std::size_t i = 0; i < rl->balises.size(); ++i) {
    obl.balises.push_back(units::BaliseEntry{static_cast<std::uint32_t>(i + 1), rl->balises[i].position_mm});
  }
  for (std::size_t i = 0; i < rl->level_crossings.size(); ++i) {
    const LevelCrossing& c = rl->level_crossings[i];
    const auto id = static_cast<std::uint32_t>(i + 1);
    obl.crossings.push_back(lc::CrossingData{id, c.NearMm(), c.FarMm(), c.warning_time_ms});
    CrossingRt x;
    x.id = id;
    x.name = c.id;
    x.near_mm = c.NearMm();
    x.far_mm = c.FarMm();
    x.warning_time_ms = c.warning_time_ms;
    crossings.push_back(x);
    crossing_inputs.push_back(units::CrossingSensors{id, false, true, lc::wayside::ClockInput::kGnss});
  }
  for (const auto& g : rl->gradients) {
    ra::OdometrySection s;
    s.begin_mm = g.section.begin_mm;
    s.end_mm = g.section.end_mm;
    s.gradient_permille_x10 = static_cast<std::int32_t>(std::abs(g.permille_x10));
    s.max_compensation_ms = params::ra::max_compensation_ms;
    obl.sections.push_back(s);
  }
}

void Simulation::Impl::SetupWayside() {
  SplitWayside();
  for (std::size_t k = 0; k < waysides.size(); ++k) {
    WaysideRt& w = waysides[k];
    units::WaysideConfig c;
    c.radio_id = w.radio_id;
    c.radio = tg::DeploymentConfig(tg::Role::kGround, w.radio_id, static_cast<std::uint16_t>(w.radio_id + 1));
    c.keys = &KeyOf;
    c.key_context = &trains;
    c.line = w.gl.config;
    c.capacity = GroundCapacity(w.gl, sc.trains.size());
    c.secure_ahead_mm = ToMm(sc.handover_secure_ahead_m);
    c.crossings = w.crossings;
    c.origin_mm = w.origin_mm;
    if (k + 1 < waysides.size()) {
      c.handover_zone_begin_mm = waysides[k + 1].origin_mm - w.origin_mm;
    }
    auto created = units::WaysideUnit::Create(c);
    if (created.error != units::ConfigError::kNone) {
      throw InputError(line.file + ": running line '" + rl->id + "'" +
                       (k > 0 ? ": the wayside unit after " + sc.wayside_splits[k - 1].entry : std::string()) +
                       ": the wayside unit refuses the line: " + units::ToString(created.error) + " (" +
                       mb::wayside::ToString(created.line_error) + ", entry " + std::to_string(created.entry) + ")");
    }
    w.unit = std::move(created.unit);
  }
  wayside = waysides.front().unit.get();
}

// Without splits one unit holds the whole line (gl, every crossing). With splits, unit k holds
// [origin_k, end_k]: origin_0 = 0, origin_k = at - overlap of split k-1; end_k = at + overlap of
// split k, the line's end for the last; its system boundary is split k's at (the running
// line's own for the last). A crossing belongs to the unit between the boundaries around it;
// points and routes must lie before the first handover zone (the scenario's commands and the
// points' bookkeeping use the first unit).
void Simulation::Impl::SplitWayside() {
  const auto& splits = sc.wayside_splits;
  std::vector<std::size_t> all(crossings.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    all[i] = i;
  }
  if (splits.empty()) {
    WaysideRt w;
    w.gl = gl;
    w.radio_id = kGroundId;
    w.crossings = obl.crossings;
    w.crossing_index = all;
    waysides.push_back(std::move(w));
    return;
  }
  std::int64_t longest = 0;
  for (const auto& t : trains) {
    longest = std::max(longest, t->length_mm);
  }
  for (const WaysideSplit& s : splits) {
    const auto where = [&](const std::string& reason) { return InputError(sc.file + ": " + s.entry + ": " + reason); };
    if (s.at_mm - s.overlap_mm <= 0 || s.at_mm + s.overlap_mm > rl->length_mm) {
      throw where("the handover zone [" + Fmt(ToM(s.at_mm - s.overlap_mm)) + ", " + Fmt(ToM(s.at_mm + s.overlap_mm)) +
                  "] m lies off running line '" + rl->id + "'");
    }
    if (s.overlap_mm < longest) {
      throw where("overlap_m " + Fmt(ToM(s.overlap_mm)) + " is shorter than the longest train (" + Fmt(ToM(longest)) +
                  " m): the unit before must hold a train until its rear has passed the boundary");
    }
    if (rl->system_boundary_mm && *rl->system_boundary_mm <= s.at_mm + s.overlap_mm) {
      throw where("the split lies at or past the running line's system boundary");
    }
  }
  const std::int64_t first_zone = splits.front().at_mm - splits.front().overlap_mm;
  for (const auto& p : rl->points) {
    if (p.section.end_mm > first_zone) {
      throw InputError(sc.file + ": " + splits.front().entry + ": points " + p.id +
                       " lie in or after the first handover zone (they must belong to the first wayside unit)");
    }
  }
  for (const FaultSpec& f : sc.faults) {
    const bool on_track = f.type == FaultType::kPossession || f.type == FaultType::kSpeedRestriction;
    if (on_track && f.end_mm > first_zone) {
      throw InputError(sc.file + ": " + f.entry + ": with wayside_splits a " + ToString(f.type) +
                       " must lie before the first handover zone (the first wayside unit takes the commands)");
    }
  }
  for (std::size_t k = 0; k <= splits.size(); ++k) {
    WaysideRt w;
    w.origin_mm = k == 0 ? 0 : splits[k - 1].at_mm - splits[k - 1].overlap_mm;
    const std::int64_t end = k < splits.size() ? splits[k].at_mm + splits[k].overlap_mm : rl->length_mm;
    const std::optional<std::int64_t> boundary = k < splits.size() ? std::optional(splits[k].at_mm) : rl->system_boundary_mm;
    const std::string& entry = splits[k < splits.size() ? k : k - 1].entry;
    w.line = AreaOfRunningLine(*rl, w.origin_mm, end, boundary, sc.file + ": " + entry);
    w.gl = BuildGroundLine(line, w.line,
                           sc.margin_policy == MarginPolicy::kD2 ? mb::wayside::MarginPolicy::kD2Buffers
                                                                 : mb::wayside::MarginPolicy::kReportedCorrection,
                           sc.ground_cycle_ms);
    // the first keeps the line's ground id; the others count down from the top of the ids
    w.radio_id = k == 0 ? kGroundId : static_cast<std::uint16_t>(0xFFFF - (k - 1));
    if (Find(w.radio_id) != nullptr) {
      throw InputError(sc.file + ": " + entry + ": train id " + std::to_string(w.radio_id) +
                       " is the radio id of a wayside unit");
    }
    const std::int64_t own_begin = k == 0 ? 0 : splits[k - 1].at_mm;
    const std::int64_t own_end = k < splits.size() ? splits[k].at_mm : rl->length_mm + 1;
    for (std::size_t i = 0; i < crossings.size(); ++i) {
      const CrossingRt& x = crossings[i];
      if (x.near_mm < own_begin && x.far_mm >= own_begin) {
        throw InputError(sc.file + ": " + entry + ": level crossing " + x.name + " lies across the boundary");
      }
      if (x.near_mm >= own_begin && x.near_mm < own_end) {
        const lc::CrossingData& d = obl.crossings[i];
        w.crossings.push_back(lc::CrossingData{d.id, d.near_mm - w.origin_mm, d.far_mm - w.origin_mm, d.warning_time_ms});
        w.crossing_index.push_back(i);
      }
    }
    radio_areas.push_back(units::RadioArea{w.radio_id, w.origin_mm, boundary});
    waysides.push_back(std::move(w));
  }
  radio_areas.back().boundary_mm.reset();  // no neighbour past the last: the train has no link to hand over to
}

std::size_t Simulation::Impl::WaysideAt(std::int64_t front_mm) const {
  std::size_t k = 0;
  while (k + 1 < waysides.size() && *radio_areas[k].boundary_mm <= front_mm) {
    ++k;
  }
  return k;
}

std::optional<std::int64_t> Simulation::Impl::ProtectedAuthority(std::uint16_t train) const {
  std::optional<std::int64_t> best;
  for (const WaysideRt& w : waysides) {
    if (const auto p = w.unit->Ground().ProtectedAuthority(train)) {
      best = std::max(best.value_or(*p + w.origin_mm), *p + w.origin_mm);
    }
  }
  return best;
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
  MoveTrains();
  now += sc.step_ms;
  CheckInvariants();
  Measure();
  return true;
}

Simulation::Simulation(Scenario scenario, Line line, std::vector<TrainType> types)
    : impl_(std::make_unique<Impl>(std::move(scenario), std::move(line), std::move(types))) {
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
    if (const units::OnboardOutputs* o = t->Out()) {
      if (o->authority_limit_mm) {
        v.limit_m = ToM(*o->authority_limit_mm);
      }
      if (o->indications.limit_mm) {
        v.supervised_limit_m = ToM(*o->indications.limit_mm);
      }
      v.permitted_speed_mps = static_cast<double>(o->indications.permitted_speed_mm_s) / 1000.0;
      v.brake = units::ToString(o->brake);
      v.authority_usable = o->authority_usable;
      v.link_up = o->link == tg::LinkState::kUp;
    }
    v.emergency = t->brake == Brake::kEmergency;
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
