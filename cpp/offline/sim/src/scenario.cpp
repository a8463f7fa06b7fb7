// Scenario file reader (spec/scenarios/README.md). The format is the schema's
// (spec/schemas/scenario.schema.json, applied with the line, stations and routes named by
// railproof_testgen validate); this reader keeps what the simulation needs when it is run by
// hand on a file the validator has not seen (spec/design/data.md): the type of every value,
// the ranges that keep its arithmetic and its containers defined (positive divisors, times
// and lengths that convert to integer ms and mm, bounded copies, 16-bit train addresses other
// than the ground's), the rules between values the schema cannot say (windows, order, train
// ids) and the fit to the line it is given.
#include "railproof/sim/scenario.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "railproof/core/units.hpp"
#include "railproof/generated/mb_params.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::sim {

namespace mb = params::mb;

const char* ToString(FaultType type) {
  switch (type) {
    case FaultType::kRadioLoss: return "radio_loss";
    case FaultType::kTrackingLoss: return "tracking_loss";
    case FaultType::kPossession: return "possession";
    case FaultType::kSidingRequest: return "siding_request";
    case FaultType::kSpeedRestriction: return "speed_restriction";
  }
  return "invalid";
}

bool Scenario::OnWheelRail(std::uint16_t id) const {
  return !low_adhesion.empty() &&
         (!wheel_rail_trains || std::find(wheel_rail_trains->begin(), wheel_rail_trains->end(), id) != wheel_rail_trains->end());
}

namespace {

// The ranges of the reader. Times: spec/schemas/scenario.schema.json ($defs/time, at most a
// week). The schema states no upper bound for the positions and the running resistance; these
// ranges are stated here: positions within the runtime's line coordinate range
// (core::kMaxPositionMm, 10,000 km), the resistance terms at most 100 N/kN, 10 N/kN per km/h
// and 1 N/kN per (km/h)^2. Beyond them a value is no longer a scenario the simulation models:
// a conversion to mm or ms would leave the integers, and the motion near the largest double
// would not be finite.
constexpr double kMaxDurationS = 7.0 * 24.0 * 3600.0;
constexpr NumberRange kTime{0.0, kMaxDurationS};
constexpr NumberRange kPosition{0.0, static_cast<double>(core::kMaxPositionMm) / 1000.0};
constexpr NumberRange kSpeed{0.0, 400.0, true};  // km/h

double Positive(const JsonNode& n, double max) { return n.NumberIn({0.0, max, true}); }

double Probability(const JsonNode& n) { return n.NumberIn({0.0, 1.0}); }

std::int64_t SecondsToMs(const JsonNode& n) { return n.ScaledIn(kTime, 1000.0, "s"); }

std::int64_t MetresToMm(const JsonNode& n) { return n.ScaledIn(kPosition, 1000.0, "m"); }

std::int64_t PositiveMs(const JsonNode& n) { return n.IntIn(1, 3'600'000, "ms"); }

// A time of the scenario that must fall before its end: what comes later would silently
// never happen while the run reports its result.
void BeforeEnd(const JsonNode& n, std::int64_t ms, std::int64_t duration_ms, const std::string& what) {
  if (ms >= duration_ms) {
    n.Fail(what + " at " + FormatNumber(static_cast<double>(ms) / 1000.0) + " s, at or after the end of the scenario (duration_s " +
           FormatNumber(static_cast<double>(duration_ms) / 1000.0) + ")");
  }
}

TrainSpec ReadTrain(const JsonNode& n, const std::string& entry) {
  TrainSpec t;
  t.entry = entry;
  const JsonNode idn = n.Key("id");
  const std::int64_t id = idn.Int();
  if (id < 0 || id > 0xFFFF || id == params::tg::ground_id) {
    idn.Fail("train id must be in 0..65535 and differ from the ground id " + std::to_string(params::tg::ground_id));
  }
  t.id = static_cast<std::uint16_t>(id);
  if (auto tt = n.OptKey("train_type")) {
    t.train_type = tt->String();
  }
  t.performance.length_m = Positive(n.Key("length_m"), 2000.0);
  t.performance.max_speed_mps = n.Key("max_speed_kmh").NumberIn(kSpeed, "km/h") / 3.6;
  t.performance.accel_mps2 = Positive(n.Key("accel_mps2"), 5.0);
  t.performance.service_decel_mps2 = Positive(n.Key("service_decel_mps2"), 5.0);
  const JsonNode en = n.Key("emergency_decel_mps2");
  t.performance.emergency_decel_mps2 = Positive(en, 5.0);
  if (t.performance.emergency_decel_mps2 < t.performance.service_decel_mps2) {
    en.Fail("emergency deceleration below the service deceleration");
  }
  t.initial_front_mm = MetresToMm(n.Key("initial_front_m"));
  if (auto e = n.OptKey("enter_s")) {
    t.enter_ms = SecondsToMs(*e);
  }
  const JsonNode dn = n.Key("depart_s");
  t.depart_ms = SecondsToMs(dn);
  if (t.depart_ms < t.enter_ms) {
    dn.Fail("departure before the train enters (enter_s)");
  }
  if (auto sn = n.OptKey("stops")) {
    for (const auto& s : sn->Array()) {
      t.stops.push_back(StopSpec{s.Key("station").String(), SecondsToMs(s.Key("dwell_s"))});
    }
  }
  if (auto c = n.OptKey("speed_cap_kmh")) {
    t.speed_cap_mps = c->NumberIn(kSpeed, "km/h") / 3.6;
  }
  if (auto r = n.OptKey("resistance")) {
    t.performance.resistance = Resistance{r->Key("a0").NumberIn({0.0, 100.0}, "N/kN"),
                                          r->Key("a1").NumberIn({0.0, 10.0}, "N/kN per km/h"),
                                          r->Key("a2").NumberIn({0.0, 1.0}, "N/kN per (km/h)^2")};
  }
  return t;
}

FaultType ReadFaultType(const JsonNode& n) {
  const std::string type = n.String();
  for (const FaultType t : {FaultType::kRadioLoss, FaultType::kTrackingLoss, FaultType::kPossession,
                            FaultType::kSidingRequest, FaultType::kSpeedRestriction}) {
    if (type == ToString(t)) {
      return t;
    }
  }
  n.Fail("unknown fault type '" + type + "' (radio_loss, tracking_loss, possession, siding_request, speed_restriction)");
}

FaultSpec ReadFault(const JsonNode& n, const std::string& entry) {
  FaultSpec f;
  f.entry = entry;
  f.type = ReadFaultType(n.Key("type"));
  if (f.type == FaultType::kRadioLoss || f.type == FaultType::kTrackingLoss) {
    const JsonNode trn = n.Key("train");
    const std::int64_t id = trn.Int();
    if (id < 0 || id > 0xFFFF) {
      trn.Fail("train id out of range 0..65535");
    }
    f.train = static_cast<std::uint16_t>(id);
  } else if (f.type == FaultType::kPossession || f.type == FaultType::kSpeedRestriction) {
    const bool possession = f.type == FaultType::kPossession;
    f.begin_mm = MetresToMm(n.Key("begin_m"));
    const JsonNode en = n.Key("end_m");
    f.end_mm = MetresToMm(en);
    if (f.end_mm <= f.begin_mm) {
      en.Fail(std::string(possession ? "possession" : "restriction") + " end not after its begin");
    }
    if (!possession) {
      f.speed_mps = n.Key("speed_kmh").NumberIn(kSpeed, "km/h") / 3.6;
    }
  } else if (auto r = n.OptKey("route")) {  // a siding request naming its route
    f.route = r->Int();
    if (f.route <= 0) {
      r->Fail("route id must be positive");
    }
  }
  f.from_ms = SecondsToMs(n.Key("from_s"));
  const JsonNode ton = n.Key("to_s");
  f.to_ms = SecondsToMs(ton);
  if (f.to_ms <= f.from_ms) {
    ton.Fail("window end not after its start (from_s)");
  }
  return f;
}

// low_adhesion.sections[]: sorted and disjoint, so that a point of the line has one rail
// condition (the wheel-rail vehicle would multiply overlapping factors).
std::vector<AdhesionSectionSpec> ReadAdhesionSections(const JsonNode& n) {
  std::vector<AdhesionSectionSpec> out;
  for (const auto& e : n.NonEmptyArray("no low-adhesion section")) {
    AdhesionSectionSpec a;
    a.entry = e.Path();
    a.begin_mm = MetresToMm(e.Key("begin_m"));
    const JsonNode en = e.Key("end_m");
    a.end_mm = MetresToMm(en);
    if (a.end_mm <= a.begin_mm) {
      en.Fail("section end not after its begin");
    }
    if (!out.empty() && a.begin_mm < out.back().end_mm) {
      e.Key("begin_m").Fail("section begins before the end of the previous one (" +
                            FormatNumber(static_cast<double>(out.back().end_mm) / 1000.0) + " m): sections are sorted and disjoint");
    }
    if (auto r = e.OptKey("rail")) {
      const std::string rail = r->String();
      if (rail != "wet" && rail != "dry") {
        r->Fail("unknown rail condition '" + rail + "' (wet, dry)");
      }
      a.wet = rail == "wet";
    }
    if (auto f = e.OptKey("factor")) {
      a.factor = f->NumberIn({0.0, 1.0, true});
    }
    if (!a.wet && a.factor == 1.0) {
      e.Fail("a dry section with factor 1 does not reduce the adhesion");
    }
    out.push_back(a);
  }
  return out;
}

}  // namespace

Scenario ParseScenario(std::string_view text, const std::string& file) {
  const JsonDocument root(text, file, kScenarioSchema);
  Scenario sc;
  sc.file = file;
  sc.name = root.Key("name").String();
  if (auto d = root.OptKey("description")) {
    sc.description = d->String();
  }
  sc.line = root.Key("line").String();
  // the line file is <lines-dir>/<line>.json: no other file may be opened
  if (sc.line.empty() || sc.line.find_first_of("/\\") != std::string::npos) {
    root.Key("line").Fail("line must be a plain line name (file <lines-dir>/<line>.json)");
  }
  sc.running_line = root.Key("running_line").String();
  const JsonNode dur = root.Key("duration_s");
  sc.duration_ms = dur.ScaledIn({0.0, kMaxDurationS, true}, 1000.0, "s");

  sc.step_ms = root.Has("step_ms") ? root.Key("step_ms").IntIn(1, 1000, "ms") : 100;
  if (sc.duration_ms < sc.step_ms) {
    dur.Fail("the scenario is shorter than one step (step_ms " + std::to_string(sc.step_ms) + ")");
  }
  sc.seed = static_cast<std::uint64_t>(root.Key("seed").IntIn(0, std::numeric_limits<std::int64_t>::max()));

  sc.ground_cycle_ms = root.Has("ground_cycle_ms") ? PositiveMs(root.Key("ground_cycle_ms")) : mb::ground_cycle_ms;
  sc.report_period_ms = root.Has("report_period_ms") ? PositiveMs(root.Key("report_period_ms")) : mb::report_period_ms;
  for (const auto& [key, value] : {std::pair<const char*, std::int64_t>{"ground_cycle_ms", sc.ground_cycle_ms},
                                   {"report_period_ms", sc.report_period_ms}}) {
    if (value % sc.step_ms != 0) {
      (root.Has(key) ? root.Key(key) : root.Key("step_ms"))
          .Fail(std::string(key) + " " + std::to_string(value) + " is not a multiple of step_ms " + std::to_string(sc.step_ms));
    }
  }
  if (auto mp = root.OptKey("margin_policy")) {
    const std::string p = mp->String();
    if (p == "reported") {
      sc.margin_policy = MarginPolicy::kReported;
    } else if (p == "d2") {
      sc.margin_policy = MarginPolicy::kD2;
    } else {
      mp->Fail("unknown margin policy '" + p + "' (reported, d2)");
    }
  }
  if (auto h = root.OptKey("handover_secure_ahead_m")) {
    sc.handover_secure_ahead_m = h->NumberIn(kPosition, "m");
  }
  if (auto b = root.OptKey("boundary_accepted")) {
    sc.boundary_accepted = b->Bool();
  }
  if (auto ws = root.OptKey("wayside_splits")) {
    for (const auto& n : ws->Array()) {
      WaysideSplit s;
      s.at_mm = MetresToMm(n.Key("at_m"));
      s.overlap_mm = n.Key("overlap_m").ScaledIn({0.0, kPosition.hi, true}, 1000.0, "m");
      s.entry = n.Path();
      if (!sc.wayside_splits.empty() &&
          s.at_mm - s.overlap_mm <= sc.wayside_splits.back().at_mm + sc.wayside_splits.back().overlap_mm) {
        n.Key("at_m").Fail("the handover zone must begin after the previous split's overlap ends");
      }
      sc.wayside_splits.push_back(s);
    }
  }
  if (auto sm = root.OptKey("sample_ms")) {
    sc.sample_ms = PositiveMs(*sm);
    if (sc.sample_ms % sc.step_ms != 0) {
      sm->Fail("sample_ms is not a multiple of step_ms");
    }
  }

  {
    const JsonNode ch = root.Key("channel");
    sc.channel.loss_probability = Probability(ch.Key("loss_probability"));
    if (auto c = ch.OptKey("corrupt_probability")) {
      sc.channel.corrupt_probability = Probability(*c);
    }
    const JsonNode mx = ch.Key("max_delay_ms");
    sc.channel.max_delay_ms = mx.IntIn(0, 60'000, "ms");
    if (auto mn = ch.OptKey("min_delay_ms")) {
      sc.channel.min_delay_ms = mn->IntIn(0, 60'000, "ms");
    }
    if (sc.channel.max_delay_ms < sc.channel.min_delay_ms) {
      mx.Fail("max_delay_ms must lie in [min_delay_ms, 60000], got " + std::to_string(sc.channel.max_delay_ms));
    }
  }

  {
    std::set<std::uint16_t> ids;
    for (const auto& n : root.Key("trains").NonEmptyArray("no train")) {
      const TrainSpec base = ReadTrain(n, n.Path());
      std::int64_t count = 1;
      double interval_s = 0.0;
      if (auto rp = n.OptKey("repeat")) {
        count = rp->Key("count").IntIn(1, 1000);
        interval_s = Positive(rp->Key("interval_s"), kMaxDurationS);
      }
      for (std::int64_t k = 0; k < count; ++k) {
        TrainSpec t = base;
        const std::int64_t id = std::int64_t{base.id} + k;
        if (id > 0xFFFF || id == params::tg::ground_id) {
          n.Key("id").Fail("repeated train id " + std::to_string(id) + " out of range or equal to the ground id");
        }
        t.id = static_cast<std::uint16_t>(id);
        const auto shift = static_cast<std::int64_t>(std::llround(static_cast<double>(k) * interval_s * 1000.0));
        t.enter_ms += shift;
        t.depart_ms += shift;
        if (k > 0) {
          t.entry = n.Path() + " copy " + std::to_string(k);
        }
        BeforeEnd(k > 0 ? n.Key("repeat").Key("interval_s") : n.Key("depart_s"), t.depart_ms, sc.duration_ms,
                  (k > 0 ? "copy " + std::to_string(k) + " departs" : std::string("the train departs")));
        if (!ids.insert(t.id).second) {
          n.Key("id").Fail("duplicate train id " + std::to_string(t.id));
        }
        sc.trains.push_back(std::move(t));
      }
    }
  }
  if (auto fn = root.OptKey("faults")) {
    for (const auto& n : fn->Array()) {
      FaultSpec f = ReadFault(n, n.Path());
      BeforeEnd(n.Key("from_s"), f.from_ms, sc.duration_ms, "the fault begins");
      if (f.train && std::none_of(sc.trains.begin(), sc.trains.end(), [&](const TrainSpec& t) { return t.id == *f.train; })) {
        n.Key("train").Fail("unknown train " + std::to_string(*f.train));
      }
      sc.faults.push_back(f);
    }
  }
  if (auto gn = root.OptKey("gap")) {
    GapSpec g;
    for (auto [key, out] : {std::pair<const char*, std::uint16_t*>{"leader", &g.leader}, {"follower", &g.follower}}) {
      const JsonNode idn = gn->Key(key);
      const std::int64_t id = idn.Int();
      if (std::none_of(sc.trains.begin(), sc.trains.end(), [&](const TrainSpec& t) { return t.id == id; })) {
        idn.Fail("unknown train " + std::to_string(id));
      }
      *out = static_cast<std::uint16_t>(id);
    }
    if (g.leader == g.follower) {
      gn->Key("follower").Fail("follower equals leader");
    }
    g.from_ms = SecondsToMs(gn->Key("from_s"));
    const JsonNode t = gn->Key("to_s");
    g.to_ms = SecondsToMs(t);
    if (g.to_ms <= g.from_ms || g.to_ms > sc.duration_ms) {
      t.Fail("gap window must end after from_s and within duration_s");
    }
    sc.gap = g;
  }
  if (auto la = root.OptKey("low_adhesion")) {
    sc.low_adhesion = ReadAdhesionSections(la->Key("sections"));
    if (auto tn = la->OptKey("trains")) {
      sc.wheel_rail_trains.emplace();
      for (const auto& e : tn->NonEmptyArray("no train (omit the key: every train)")) {
        const std::int64_t id = e.Int();
        if (std::none_of(sc.trains.begin(), sc.trains.end(), [&](const TrainSpec& t) { return t.id == id; })) {
          e.Fail("unknown train " + std::to_string(id));
        }
        sc.wheel_rail_trains->push_back(static_cast<std::uint16_t>(id));
      }
    }
  }
  return sc;
}

Scenario LoadScenario(const std::filesystem::path& path) {
  return ParseScenario(ReadInputFile(path, "scenario file"), path.string());
}

const RunningLine& SelectRunningLine(const Scenario& sc, const Line& line) {
  if (line.name != sc.line) {
    throw InputError(sc.file + ": line: the scenario names line '" + sc.line + "' but " + line.file + " holds line '" +
                     line.name + "'");
  }
  std::string have;
  for (const auto& rl : line.running_lines) {
    if (rl.id == sc.running_line) {
      return rl;
    }
    have += (have.empty() ? "" : ", ") + rl.id;
  }
  throw InputError(sc.file + ": running_line: unknown running line '" + sc.running_line + "' on line '" + line.name +
                   "' (has: " + have + ")");
}

void CheckScenarioAgainstLine(const Scenario& sc, const RunningLine& line) {
  const auto fail = [&](const std::string& entry, const std::string& reason) {
    throw InputError(sc.file + ": " + entry + ": " + reason);
  };
  const auto len = line.length_mm;
  for (const auto& t : sc.trains) {
    const auto length_mm = static_cast<std::int64_t>(std::llround(t.performance.length_m * 1000.0));
    if (t.initial_front_mm - length_mm < 0 || t.initial_front_mm > len) {
      fail(t.entry + ".initial_front_m", "train range [" + std::to_string(t.initial_front_mm - length_mm) + ", " +
                                             std::to_string(t.initial_front_mm) + ") mm lies off running line '" +
                                             line.id + "' [0, " + std::to_string(len) + ")");
    }
    std::int64_t last = t.initial_front_mm;
    for (std::size_t i = 0; i < t.stops.size(); ++i) {
      const Station* st = line.FindStation(t.stops[i].station);
      const std::string entry = t.entry + ".stops[" + std::to_string(i) + "].station";
      if (st == nullptr) {
        std::string have;
        for (const auto& s : line.stations) {
          have += (have.empty() ? "" : ", ") + s.name;
        }
        fail(entry, "unknown station '" + t.stops[i].station + "' on running line '" + line.id + "' (has: " + have + ")");
      }
      if (st->stop_mm < last) {
        fail(entry, "station '" + st->name + "' (stop at " + std::to_string(st->stop_mm) +
                        " mm) lies behind the train's previous position " + std::to_string(last) + " mm");
      }
      last = st->stop_mm;
    }
  }
  for (const auto& a : sc.low_adhesion) {
    if (a.end_mm > len) {
      fail(a.entry, "low-adhesion section [" + std::to_string(a.begin_mm) + ", " + std::to_string(a.end_mm) +
                        ") mm lies off running line '" + line.id + "' [0, " + std::to_string(len) + ")");
    }
  }
  for (const auto& f : sc.faults) {
    if ((f.type == FaultType::kPossession || f.type == FaultType::kSpeedRestriction) && f.end_mm > len) {
      fail(f.entry, std::string(ToString(f.type)) + " [" + std::to_string(f.begin_mm) + ", " + std::to_string(f.end_mm) +
                        ") mm lies off running line '" + line.id + "'");
    }
    if (f.type == FaultType::kSidingRequest) {
      const bool found = std::any_of(line.routes.begin(), line.routes.end(), [&](const Route& r) {
        return f.route != 0 ? r.id == f.route : (r.reverse && !r.automatic);
      });
      if (!found) {
        fail(f.entry, f.route != 0 ? "unknown route " + std::to_string(f.route) + " on running line '" + line.id + "'"
                                   : "running line '" + line.id + "' has no siding (reverse, non-automatic) route");
      }
    }
  }
}

}  // namespace railproof::sim
