// Output files of the wheel-rail simulator: CSV (one row per cycle) and JSON (every cycle's
// streams and truth, the events). Non-finite IMU values (injected faults) are written as
// "nan" in the CSV and null in the JSON.
#include <cmath>
#include <cstdio>
#include <string>

#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

namespace {
std::string F(double v, int prec = 6) {
  if (!std::isfinite(v)) {
    return "nan";
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

// Mean of the delivered samples; NaN if none.
double Mean(const ra::CycleInput& c, double ra::ImuSample::*field) {
  if (c.imu_count == 0) {
    return std::nan("");
  }
  double s = 0.0;
  for (std::size_t k = 0; k < c.imu_count && k < c.imu.size(); ++k) {
    s += c.imu[k].*field;
  }
  return s / c.imu_count;
}

nlohmann::ordered_json Num(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}
}  // namespace

std::string WheelRailCsv(const WheelRailRun& run) {
  std::string out =
      "time_ms,front_m,distance_m,speed_mps,accel_mps2,tg_pulses,tg_last_edge_us,tg_distance_m,"
      "tg_wheel_speed_mps,imu_count,ax_mean,ay_mean,az_mean,wx_mean,wy_mean,wz_mean,creep0,creep1,creep2,"
      "creep3,creep_peak0,creep_peak1,creep_peak2,creep_peak3,gradient_permille,pitch_rad,roll_rad,"
      "curvature_1pm,traction,brake,balise_mm,faults\n";
  // Fields are appended one by one (operator+ chains on temporaries trip a false
  // -Wrestrict in g++ 12 at -O3).
  const auto field = [&out](const std::string& v) {
    out += ',';
    out += v;
  };
  for (std::size_t i = 0; i < run.cycles.size(); ++i) {
    const auto& c = run.cycles[i];
    const auto& t = run.truth[i];
    out += std::to_string(c.time_ms);
    for (const std::string& v :
         {F(t.front_m, 4), F(t.distance_m, 4), F(t.speed_mps, 5), F(t.accel_mps2, 5), std::to_string(c.tg.pulses),
          std::to_string(c.tg.last_edge_us), F(t.tg_distance_m, 4), F(t.tg_wheel_speed_mps, 5),
          std::to_string(c.imu_count), F(Mean(c, &ra::ImuSample::ax)), F(Mean(c, &ra::ImuSample::ay)),
          F(Mean(c, &ra::ImuSample::az)), F(Mean(c, &ra::ImuSample::wx), 8),
          F(Mean(c, &ra::ImuSample::wy), 8), F(Mean(c, &ra::ImuSample::wz), 8)}) {
      field(v);
    }
    for (const double v : t.creep) field(F(v, 6));
    for (const double v : t.creep_peak) field(F(v, 6));
    for (const std::string& v :
         {F(t.gradient_permille, 3), F(t.pitch_rad, 7), F(t.roll_rad, 7), F(t.curvature_1pm, 8), F(t.traction, 4),
          F(t.brake, 4), c.balise ? std::to_string(c.balise->front_mm) : std::string(), std::to_string(t.faults)}) {
      field(v);
    }
    out += '\n';
  }
  return out;
}

nlohmann::ordered_json WheelRailJson(const WheelRailScenario& sc, const WheelRailRun& run) {
  using J = nlohmann::ordered_json;
  J events = J::array();
  for (const auto& e : run.events) {
    events.push_back(J{{"axle", e.axle},
                       {"tg_axle", e.tg_axle},
                       {"kind", ToString(e.kind)},
                       {"start_ms", e.start_ms},
                       {"end_ms", e.end_ms},
                       {"peak_creep", e.peak_creep},
                       {"start_front_m", e.start_front_m},
                       {"end_front_m", e.end_front_m}});
  }
  J faults = J::array();
  for (const auto& f : sc.faults) {
    faults.push_back(J{{"type", ToString(f.kind)}, {"from_s", f.from_s}, {"to_s", f.to_s}});
  }
  J cycles = J::array();
  for (std::size_t i = 0; i < run.cycles.size(); ++i) {
    const auto& c = run.cycles[i];
    const auto& t = run.truth[i];
    J imu = J::array();
    for (std::size_t k = 0; k < c.imu_count && k < c.imu.size(); ++k) {
      const auto& m = c.imu[k];
      imu.push_back(J::array({m.time_us, Num(m.ax), Num(m.ay), Num(m.az), Num(m.wx), Num(m.wy), Num(m.wz)}));
    }
    J truth{{"time_ms", t.time_ms},
            {"front_m", t.front_m},
            {"distance_m", t.distance_m},
            {"speed_mps", t.speed_mps},
            {"accel_mps2", t.accel_mps2},
            {"tg_distance_m", t.tg_distance_m},
            {"tg_wheel_speed_mps", t.tg_wheel_speed_mps},
            {"creep", t.creep},
            {"creep_peak", t.creep_peak},
            {"normal_force_n", t.normal_force_n},
            {"creep_force_n", t.creep_force_n},
            {"gradient_permille", t.gradient_permille},
            {"pitch_rad", t.pitch_rad},
            {"roll_rad", t.roll_rad},
            {"curvature_1pm", t.curvature_1pm},
            {"traction", t.traction},
            {"brake", t.brake},
            {"faults", t.faults}};
    cycles.push_back(J{{"time_ms", c.time_ms},
                       {"tg", J{{"time_us", c.tg.time_us}, {"pulses", c.tg.pulses}, {"last_edge_us", c.tg.last_edge_us}}},
                       {"imu_count", c.imu_count},
                       {"imu", imu},
                       {"balise_front_mm", c.balise ? J(c.balise->front_mm) : J(nullptr)},
                       {"truth", truth}});
  }
  return J{{"schema", "railproof/wheelrail-run/1"},
           {"scenario", sc.name},
           {"requirements", sc.requirements},
           {"expect_safe_reaction", sc.expect_safe_reaction},
           {"seed", sc.seed},
           {"duration_s", run.simulated_s},
           {"start", ToString(sc.start)},
           {"lead_in_ms", run.lead_in_ms},
           {"wheel_diameter_m", sc.vehicle.wheel_diameter_m},
           {"tg_axle", sc.tg.axle},
           {"tg_teeth", sc.tg.teeth},
           {"pulse_length_m", run.pulse_length_m},
           {"imu_sample_layout", "[time_us, ax, ay, az, wx, wy, wz]"},
           {"faults", faults},
           {"events", events},
           {"cycles", cycles}};
}

}  // namespace railproof::ra::analysis
