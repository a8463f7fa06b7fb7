// Wheel-rail scenario loader (spec/wheelrail/README.md): every failure names the file, the
// entry and the reason. The format is the schema's (spec/schemas/wheelrail_scenario.schema.json,
// applied with the requirements named by railproof_testgen validate); this loader keeps what
// the simulation needs when it is run by hand on a file the validator has not seen
// (spec/design/data.md): the type of every value, the ranges that keep the Box2D model and
// its unit conversions defined, and the rules between values the schema cannot say (order,
// the vertical curves fitting between the change points, the car inside the alignment, the
// step dividing the IMU period, fields that belong to one fault type).
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "railproof/offline/json_reader.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

namespace {

// The largest shock sample of an imu_out_of_range fault (m/s^2, about 1000 g: beyond any IMU's
// measuring range, the fault's purpose; spec/schemas/wheelrail_scenario.schema.json states no
// bound).
constexpr double kMaxShockMps2 = 1e4;

// Number in [lo, hi] (inclusive).
double Ranged(const JsonNode& n, double lo, double hi) { return n.NumberIn({lo, hi}); }

double RangedKey(const JsonNode& n, std::string_view key, double def, double lo, double hi) {
  const auto k = n.OptKey(key);
  return k ? Ranged(*k, lo, hi) : def;
}

// An optional member of a section, a number in [lo, hi]; absent or null, `value` keeps its
// default.
struct OptionalNumber {
  std::string_view key;
  double& value;
  double lo;
  double hi;
};

// The optional numbers of section `n`, in the order given.
void ReadOptionalNumbers(const JsonNode& n, std::span<const OptionalNumber> fields) {
  for (const auto& f : fields) {
    f.value = RangedKey(n, f.key, f.value, f.lo, f.hi);
  }
}
void ReadOptionalNumbers(const JsonNode& n, std::initializer_list<OptionalNumber> fields) {
  ReadOptionalNumbers(n, std::span(fields.begin(), fields.size()));
}

std::string Fmt(double v) { return offline::FormatNumber(v); }

void ParseVertical(const JsonNode& n, WheelRailScenario& sc) {
  auto& v = sc.vertical;
  v.begin_m = Ranged(n.Key("begin_m"), -1e7, 1e7);
  v.end_m = Ranged(n.Key("end_m"), -1e7, 1e7);
  if (v.end_m - v.begin_m < 100.0) {
    n.Key("end_m").Fail("must be at least 100 m beyond begin_m");
  }
  v.vertical_curve_radius_m = RangedKey(n, "vertical_curve_radius_m", 3000.0, 500.0, 100000.0);
  const auto arr = n.Key("gradients").NonEmptyArray("at least one gradient expected");
  for (const auto& e : arr) {
    GradientPoint g;
    g.from_m = e.Key("from_m").Number();
    const auto pn = e.Key("permille");
    g.permille = pn.Number();
    if (std::fabs(g.permille) > kMaxGradientPermille) {
      pn.Fail("gradient " + Fmt(g.permille) + " permille beyond the maximum +-35 permille");
    }
    g.entry = e.Path();
    if (v.gradients.empty()) {
      if (g.from_m != v.begin_m) {
        e.Key("from_m").Fail("the first gradient must start at vertical.begin_m (" + Fmt(v.begin_m) + ")");
      }
    } else if (g.from_m <= v.gradients.back().from_m) {
      e.Key("from_m").Fail("not after the previous gradient's from_m");
    } else if (g.from_m >= v.end_m) {
      e.Key("from_m").Fail("at or beyond vertical.end_m");
    }
    v.gradients.push_back(g);
  }
  // Vertical curves must fit between the change points and inside the alignment.
  double prev_end = v.begin_m;
  for (std::size_t i = 1; i < v.gradients.size(); ++i) {
    const double h = v.vertical_curve_radius_m *
                     std::fabs(v.gradients[i].permille - v.gradients[i - 1].permille) / 2000.0;
    const double c = v.gradients[i].from_m;
    if (c - h < prev_end - 1e-9) {
      arr[i].Fail("the vertical curve (" + Fmt(2 * h) + " m) overlaps the previous curve or the alignment start");
    }
    prev_end = c + h;
  }
  if (prev_end > v.end_m) {
    arr.back().Fail("the vertical curve extends beyond vertical.end_m");
  }
}

// A curve or an adhesion zone [begin, end) must lie on the vertical alignment, where the
// simulation has a track: beyond it the section would silently never act.
void InsideAlignment(const JsonNode& n, const char* what, double begin_m, double end_m, const VerticalAlignment& v) {
  if (begin_m < v.begin_m || end_m > v.end_m) {
    n.Fail(std::string(what) + " [" + Fmt(begin_m) + ", " + Fmt(end_m) + ") m lies outside the vertical alignment [" +
           Fmt(v.begin_m) + ", " + Fmt(v.end_m) + ") m");
  }
}

void ParseCurves(const JsonNode& n, WheelRailScenario& sc) {
  for (const auto& e : n.Array()) {
    HorizontalCurve c;
    c.begin_m = e.Key("begin_m").Number();
    c.end_m = e.Key("end_m").Number();
    if (c.end_m <= c.begin_m) {
      e.Key("end_m").Fail("not after begin_m");
    }
    InsideAlignment(e, "curve", c.begin_m, c.end_m, sc.vertical);
    const auto rn = e.Key("radius_m");
    c.radius_m = rn.Number();
    if (std::fabs(c.radius_m) < 100.0 || std::fabs(c.radius_m) > 100000.0) {
      rn.Fail("|radius| must be in [100, 100000] m (sign: + left)");
    }
    c.cant_mm = RangedKey(e, "cant_mm", 0.0, 0.0, 180.0);
    c.transition_m = RangedKey(e, "transition_m", 0.0, 0.0, 1000.0);
    if (2.0 * c.transition_m > c.end_m - c.begin_m) {
      e.Key("transition_m").Fail("two transitions longer than the curve");
    }
    if (!sc.curves.empty() && c.begin_m < sc.curves.back().end_m) {
      e.Key("begin_m").Fail("overlaps the previous curve (curves sorted, not overlapping)");
    }
    c.entry = e.Path();
    sc.curves.push_back(c);
  }
}

void ParseRail(const JsonNode& n, WheelRailScenario& sc) {
  const auto cn = n.Key("condition");
  const std::string cond = cn.String();
  if (cond == "wet") {
    sc.rail.wet = true;
  } else if (cond == "dry") {
    sc.rail.wet = false;
  } else {
    cn.Fail("expected 'dry' or 'wet', got '" + cond + "'");
  }
  if (const auto z = n.OptKey("zones")) {
    for (const auto& e : z->Array()) {
      AdhesionZone a;
      a.begin_m = e.Key("begin_m").Number();
      a.end_m = e.Key("end_m").Number();
      if (a.end_m <= a.begin_m) {
        e.Key("end_m").Fail("not after begin_m");
      }
      InsideAlignment(e, "adhesion zone", a.begin_m, a.end_m, sc.vertical);
      a.factor = Ranged(e.Key("factor"), 0.05, 1.0);
      if (const auto f = e.OptKey("from_s")) {
        a.from_s = Ranged(*f, 0.0, 1e6);
      }
      if (const auto t = e.OptKey("to_s")) {
        a.to_s = Ranged(*t, 0.0, 1e6);
        if (a.from_s && *a.to_s <= *a.from_s) {
          t->Fail("not after from_s");
        }
      }
      if (const auto note = e.OptKey("note")) {
        a.note = note->String();
      }
      a.entry = e.Path();
      sc.rail.zones.push_back(a);
    }
  }
}

void ParseAdhesion(const JsonNode& n, WheelRailScenario& sc) {
  auto& a = sc.adhesion;
  ReadOptionalNumbers(n, {{"wet_factor", a.wet_factor, 0.1, 1.0},
                          {"peak_creep", a.peak_creep, 0.001, 0.1},
                          {"tail_creep", a.tail_creep, 0.01, 1.0},
                          {"tail_ratio", a.tail_ratio, 0.1, 1.0},
                          {"creep_floor_mps", a.creep_floor_mps, 0.05, 2.0}});
  if (a.tail_creep <= a.peak_creep) {
    n.Key("tail_creep").Fail("must exceed peak_creep");
  }
}

void ParseVehicle(const JsonNode& n, WheelRailScenario& sc) {
  auto& v = sc.vehicle;
  // the schema's order: the geometry is checked after axle_spacing_m, motored read after
  // roll_coefficient
  const OptionalNumber numbers[]{
      {"length_m", v.length_m, 5.0, 40.0},
      {"bogie_centres_m", v.bogie_centres_m, 3.0, 30.0},
      {"axle_spacing_m", v.axle_spacing_m, 1.5, 4.0},
      {"wheel_diameter_m", v.wheel_diameter_m, 0.5, 1.5},
      {"body_mass_kg", v.body_mass_kg, 5000.0, 80000.0},
      {"bogie_mass_kg", v.bogie_mass_kg, 500.0, 10000.0},
      {"wheelset_mass_kg", v.wheelset_mass_kg, 300.0, 5000.0},
      {"wheelset_inertia_kgm2", v.wheelset_inertia_kgm2, 10.0, 2000.0},
      {"body_cog_height_m", v.body_cog_height_m, 1.0, 3.0},
      {"primary_hz", v.primary_hz, 2.0, 15.0},
      {"primary_damping", v.primary_damping, 0.0, 1.0},
      {"secondary_hz", v.secondary_hz, 0.5, 3.0},
      {"secondary_damping", v.secondary_damping, 0.0, 1.0},
      {"roll_coefficient", v.roll_coefficient, 0.0, 0.5},
      {"max_traction_force_n", v.max_traction_force_n, 0.0, 100000.0},
      {"max_power_w", v.max_power_w, 1000.0, 2e6},
      {"max_brake_force_n", v.max_brake_force_n, 0.0, 100000.0},
      {"resistance_a_n", v.resistance_a_n, 0.0, 20000.0},
      {"resistance_b_ns_m", v.resistance_b_ns_m, 0.0, 2000.0},
      {"resistance_c_ns2_m2", v.resistance_c_ns2_m2, 0.0, 200.0},
      {"max_speed_kmh", v.max_speed_kmh, 10.0, 300.0},
  };
  const std::span<const OptionalNumber> all(numbers);
  ReadOptionalNumbers(n, all.first(3));
  if (v.bogie_centres_m + v.axle_spacing_m > v.length_m) {
    n.Fail("bogie_centres_m + axle_spacing_m exceed length_m");
  }
  if (v.axle_spacing_m >= v.bogie_centres_m) {
    n.Fail("axle_spacing_m must be below bogie_centres_m");
  }
  ReadOptionalNumbers(n, all.subspan(3, 11));
  if (const auto m = n.OptKey("motored")) {
    const auto arr = m->Array();
    if (arr.size() != kWheelRailAxles) {
      m->Fail("expected 4 booleans (axle 0 leads)");
    }
    for (std::size_t i = 0; i < arr.size(); ++i) {
      v.motored[i] = arr[i].Bool();
    }
  }
  ReadOptionalNumbers(n, all.subspan(14));
}

void ParseDriver(const JsonNode& n, WheelRailScenario& sc) {
  const auto arr = n.NonEmptyArray("at least one driver command expected");
  for (const auto& e : arr) {
    DriverCommand d;
    const auto tn = e.Key("t_s");
    d.t_s = Ranged(tn, 0.0, 1e6);
    if (!sc.driver.empty() && d.t_s < sc.driver.back().t_s) {
      tn.Fail("before the previous command (commands sorted by t_s)");
    }
    d.traction = RangedKey(e, "traction", 0.0, 0.0, 1.0);
    d.brake = RangedKey(e, "brake", 0.0, 0.0, 1.0);
    if (d.traction > 0.0 && d.brake > 0.0 && !e.Has("hold_kmh")) {
      e.Fail("traction and brake both demanded (only with hold_kmh, as limits)");
    }
    d.ramp_s = RangedKey(e, "ramp_s", 1.0, 0.0, 60.0);
    if (const auto h = e.OptKey("hold_kmh")) {
      d.hold_kmh = Ranged(*h, 0.0, 300.0);
    }
    d.entry = e.Path();
    sc.driver.push_back(d);
  }
}

void ParseSlipControl(const JsonNode& n, WheelRailScenario& sc) {
  auto& s = sc.slip_control;
  s.enabled = n.Key("enabled").Bool();
  ReadOptionalNumbers(n, {{"creep_threshold", s.creep_threshold, 0.005, 0.5},
                          {"reduce_per_s", s.reduce_per_s, 0.01, 100.0},
                          {"recover_per_s", s.recover_per_s, 0.01, 100.0},
                          {"min_factor", s.min_factor, 0.0, 1.0}});
}

void ParseImu(const JsonNode& n, WheelRailScenario& sc) {
  auto& m = sc.imu;
  if (const auto e = n.OptKey("enabled")) {
    m.enabled = e->Bool();
  }
  ReadOptionalNumbers(n, {{"accel_bias_mps2", m.accel_bias_mps2, 0.0, 1.0},
                          {"accel_noise_mps2", m.accel_noise_mps2, 0.0, 2.0},
                          {"accel_drift_mps2_per_sqrt_s", m.accel_drift_mps2_per_sqrt_s, 0.0, 0.01},
                          {"rate_bias_deg_s", m.rate_bias_deg_s, 0.0, 1.0},
                          {"rate_noise_deg_s", m.rate_noise_deg_s, 0.0, 5.0},
                          {"rate_drift_deg_s_per_sqrt_s", m.rate_drift_deg_s_per_sqrt_s, 0.0, 0.01}});
}

void ParseTg(const JsonNode& n, WheelRailScenario& sc) {
  if (const auto a = n.OptKey("axle")) {
    const auto v = a->Int();
    if (v < 0 || v >= kWheelRailAxles) {
      a->Fail("axle must be 0..3");
    }
    sc.tg.axle = static_cast<int>(v);
  }
  if (const auto t = n.OptKey("teeth")) {
    const auto v = t->Int();
    if (v < 1 || v > 1000) {
      t->Fail("teeth must be 1..1000");
    }
    sc.tg.teeth = static_cast<int>(v);
  }
  sc.tg.calibration_error_ppm = RangedKey(n, "calibration_error_ppm", 0.0, -20000.0, 20000.0);
}

// "start" (REQ-RA-015): at_rest needs initial speed 0, lead_in and in_motion a speed above 0;
// a lead-in extends the first gradient backwards over its length and must not cross an
// adhesion zone that is there without a time window (the lead-in is not part of the test).
void ParseStart(const JsonNode& root, WheelRailScenario& sc) {
  const double v0 = sc.initial_speed_kmh / 3.6;
  sc.start = v0 > 0.0 ? ScenarioStart::kLeadIn : ScenarioStart::kAtRest;
  const auto n = root.OptKey("start");
  if (n) {
    const std::string t = n->String();
    bool known = false;
    for (const auto k : {ScenarioStart::kAtRest, ScenarioStart::kLeadIn, ScenarioStart::kInMotion}) {
      if (t == ToString(k)) {
        sc.start = k;
        known = true;
      }
    }
    if (!known) n->Fail("unknown start '" + t + "' (at_rest, lead_in, in_motion)");
    if ((sc.start == ScenarioStart::kAtRest) != (v0 == 0.0)) {
      n->Fail("start '" + t + "' with initial_speed_kmh " + Fmt(sc.initial_speed_kmh) +
              " (at_rest is a start at speed 0, lead_in and in_motion at a speed above 0)");
    }
  } else if (v0 > 0.0) {
    root.Fail("missing key 'start' (a run that begins in motion: lead_in or in_motion)");
  }
  if (sc.start != ScenarioStart::kLeadIn) return;
  const double from = sc.initial_front_m - LeadInDistanceM(sc.lead_in, v0);
  for (const AdhesionZone& z : sc.rail.zones) {
    if (z.begin_m < sc.initial_front_m && z.end_m > from - sc.vehicle.length_m && !z.from_s) {
      n->Fail("lead_in: the lead-in from " + Fmt(from) + " m crosses the adhesion zone [" + Fmt(z.begin_m) + ", " +
              Fmt(z.end_m) + ") m, which has no time window");
    }
  }
  const double begin = std::min(sc.vertical.begin_m, from - sc.vehicle.length_m - 20.0);
  sc.vertical.begin_m = begin;
  sc.vertical.gradients.front().from_m = begin;
}

SensorFaultKind FaultKind(const JsonNode& n) {
  const std::string t = n.String();
  for (const auto k : {SensorFaultKind::kTgDropout, SensorFaultKind::kTgStuck, SensorFaultKind::kTgBurst,
                       SensorFaultKind::kTgEdgeInvalid, SensorFaultKind::kImuNan, SensorFaultKind::kImuGap,
                       SensorFaultKind::kImuTimestamps, SensorFaultKind::kImuOutOfRange,
                       SensorFaultKind::kCycleTime}) {
    if (t == ToString(k)) {
      return k;
    }
  }
  n.Fail("unknown fault type '" + t +
         "' (tg_dropout, tg_stuck, tg_burst, tg_edge_invalid, imu_nan, imu_gap, imu_timestamps, "
         "imu_out_of_range, cycle_time)");
}

void ParseFaults(const JsonNode& n, WheelRailScenario& sc) {
  for (const auto& e : n.Array()) {
    SensorFault f;
    f.kind = FaultKind(e.Key("type"));
    f.from_s = Ranged(e.Key("from_s"), 0.0, 1e6);
    const auto tn = e.Key("to_s");
    f.to_s = Ranged(tn, 0.0, 1e6);
    if (f.to_s <= f.from_s) {
      tn.Fail("not after from_s (negative or zero duration)");
    }
    if (f.from_s >= sc.duration_s) {
      e.Key("from_s").Fail("at or after the end of the scenario (duration_s " + Fmt(sc.duration_s) + ")");
    }
    if (const auto s = e.OptKey("samples")) {
      if (f.kind != SensorFaultKind::kImuGap) {
        s->Fail("only for imu_gap");
      }
      const auto v = s->Int();
      if (v < 0 || v >= ra::kImuSamplesPerCycle) {
        s->Fail("delivered samples must be 0..9");
      }
      f.samples = static_cast<int>(v);
    }
    if (const auto p = e.OptKey("pulses")) {
      if (f.kind != SensorFaultKind::kTgBurst) {
        p->Fail("only for tg_burst");
      }
      f.pulses = p->Int();
      if (f.pulses < 1 || f.pulses > 1000000) {
        p->Fail("pulses must be 1..1000000");
      }
    }
    if (const auto v = e.OptKey("value")) {
      if (f.kind != SensorFaultKind::kImuOutOfRange) {
        v->Fail("only for imu_out_of_range");
      }
      f.value = Ranged(*v, -kMaxShockMps2, kMaxShockMps2);
    }
    if (const auto note = e.OptKey("note")) {
      f.note = note->String();
    }
    f.entry = e.Path();
    sc.faults.push_back(f);
  }
}

void ParseOdometry(const JsonNode& n, WheelRailScenario& sc) {
  if (const auto t = n.OptKey("detect_threshold_mm_s2")) {
    sc.odometry.detect_threshold_mm_s2 = std::llround(Ranged(*t, 50.0, 2000.0));
  }
  if (const auto t = n.OptKey("max_compensation_s")) {
    const double s = Ranged(*t, 3.0, 32.0);
    const auto ms = std::llround(s * 1000.0);
    if (ms % 100 != 0) {
      t->Fail("must be a whole number of 100 ms cycles");
    }
    sc.odometry.max_compensation_ms = ms;
  }
  if (const auto t = n.OptKey("start_points")) {
    const auto v = t->Int();
    if (v < 1 || v > 2) {
      t->Fail("start_points must be 1 or 2");
    }
    sc.odometry.start_points = static_cast<int>(v);
  }
  if (const auto t = n.OptKey("rate_error_udeg_s")) {
    sc.odometry.rate_error_udeg_s = std::llround(Ranged(*t, 0.0, 1e6));
  }
}

}  // namespace

WheelRailScenario ParseWheelRailScenario(std::string_view text, const std::string& file) {
  const JsonDocument root(text, file);
  WheelRailScenario sc;
  sc.file = file;
  const auto schema = root.Key("schema");
  if (schema.String() != kWheelRailSchema) {
    schema.Fail("expected '" + std::string(kWheelRailSchema) + "', got '" + schema.String() + "'");
  }
  sc.name = root.Key("name").String();
  if (const auto d = root.OptKey("description")) {
    sc.description = d->String();
  }
  for (const auto& r : root.Key("requirements").Array()) {
    sc.requirements.push_back(r.String());
  }
  if (const auto e = root.OptKey("expect_safe_reaction")) {
    sc.expect_safe_reaction = e->Bool();
  }
  const auto dn = root.Key("duration_s");
  sc.duration_s = dn.Number();
  if (sc.duration_s <= 0.0 || sc.duration_s > 3600.0) {
    dn.Fail("duration must be in (0, 3600] s, got " + Fmt(sc.duration_s));
  }
  if (std::fabs(sc.duration_s * 10.0 - std::round(sc.duration_s * 10.0)) > 1e-9) {
    dn.Fail("duration must be a whole number of 100 ms cycles");
  }
  if (const auto st = root.OptKey("step_ms")) {
    const double ms = Ranged(*st, 0.1, 5.0);
    sc.step_us = std::llround(ms * 1000.0);
    if (std::fabs(ms * 1000.0 - static_cast<double>(sc.step_us)) > 1e-6 || 10000 % sc.step_us != 0) {
      st->Fail("step must divide the 10 ms IMU sample period in whole microseconds");
    }
  }
  if (const auto s = root.OptKey("seed")) {
    const auto v = s->Int();
    if (v < 0) {
      s->Fail("seed must be >= 0");
    }
    sc.seed = static_cast<std::uint64_t>(v);
  }
  if (const auto a = root.OptKey("adhesion")) {
    ParseAdhesion(*a, sc);
  }
  if (const auto v = root.OptKey("vehicle")) {
    ParseVehicle(*v, sc);
  }
  ParseVertical(root.Key("vertical"), sc);
  if (const auto c = root.OptKey("curves")) {
    ParseCurves(*c, sc);
  }
  ParseRail(root.Key("rail"), sc);
  const auto fn = root.Key("initial_front_m");
  sc.initial_front_m = fn.Number();
  if (sc.initial_front_m - sc.vehicle.length_m < sc.vertical.begin_m + 10.0 || sc.initial_front_m >= sc.vertical.end_m) {
    fn.Fail("the train (front " + Fmt(sc.initial_front_m) + " m, length " + Fmt(sc.vehicle.length_m) +
            " m) must stand inside the vertical alignment with 10 m behind its rear");
  }
  sc.initial_speed_kmh = RangedKey(root, "initial_speed_kmh", 0.0, 0.0, sc.vehicle.max_speed_kmh);
  ParseStart(root, sc);
  if (const auto b = root.OptKey("balises")) {
    for (const auto& e : b->Array()) {
      BalisePoint p;
      p.id = e.Key("id").String();
      const auto pn = e.Key("position_m");
      p.position_m = pn.Number();
      if (p.position_m < sc.vertical.begin_m || p.position_m >= sc.vertical.end_m) {
        pn.Fail("outside the vertical alignment");
      }
      if (!sc.balises.empty() && p.position_m <= sc.balises.back().position_m) {
        pn.Fail("balises must be sorted by position");
      }
      sc.balises.push_back(p);
    }
  }
  ParseDriver(root.Key("driver"), sc);
  if (const auto s = root.OptKey("slip_control")) {
    ParseSlipControl(*s, sc);
  }
  if (const auto i = root.OptKey("imu")) {
    ParseImu(*i, sc);
  }
  if (const auto t = root.OptKey("tg")) {
    ParseTg(*t, sc);
  }
  if (const auto f = root.OptKey("faults")) {
    ParseFaults(*f, sc);
  }
  if (const auto t = root.OptKey("truth")) {
    ReadOptionalNumbers(*t, {{"event_creep", sc.truth.event_creep, 0.001, 1.0},
                             {"event_min_s", sc.truth.event_min_s, 0.0, 60.0}});
  }
  if (const auto o = root.OptKey("odometry")) {
    ParseOdometry(*o, sc);
  }
  return sc;
}

WheelRailScenario LoadWheelRailScenario(const std::filesystem::path& path) {
  return ParseWheelRailScenario(offline::ReadInputFile(path, ""), path.string());
}

}  // namespace railproof::ra::analysis
