// Wheel-rail simulator: a scenario's run of the vehicle (WheelRailVehicle, wheel_rail_vehicle.cpp)
// under its driver schedule, with the sensors and the truth (see wheel_rail.hpp for the model
// summary).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

namespace {

constexpr double kG = kWheelRailGravity;
constexpr double kPi = 3.14159265358979323846;
constexpr std::int64_t kImuPeriodUs = 10000;
constexpr std::int64_t kCycleUs = 100000;
constexpr double kImuPeriodS = 0.01;

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

// v expressed in the body frame of attitude (pitch theta nose up, roll psi right-hand about
// x forward) relative to the level track frame (x along the heading, y left, z up):
// R = Ry(-theta) * Rx(psi), result = R^T v.
Vec3 ToBody(const Vec3& v, double theta, double psi) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double cp = std::cos(psi), sp = std::sin(psi);
  // Ry(-theta)^T v
  const Vec3 a{ct * v.x + st * v.z, v.y, -st * v.x + ct * v.z};
  // Rx(psi)^T a
  return Vec3{a.x, cp * a.y + sp * a.z, -sp * a.y + cp * a.z};
}

struct EventTrack {
  bool active = false;
  std::int64_t start_us = 0;
  double peak = 0.0;
  double start_front = 0.0;
};

class Simulator {
 public:
  explicit Simulator(const WheelRailScenario& sc) : sc_(sc), rng_(sc.seed) {
    leading_ = sc_.start == ScenarioStart::kLeadIn;
    const double tg_phase = InitSensors();
    // a lead-in starts at rest so far back that its speed ramp and hold end at the front
    const double front = leading_ ? sc_.initial_front_m - LeadInDistanceM(sc_.lead_in, sc_.initial_speed_kmh / 3.6)
                                  : sc_.initial_front_m;
    const double v0 = leading_ ? 0.0 : sc_.initial_speed_kmh / 3.6;
    car_ = std::make_unique<WheelRailVehicle>(VehicleConfigOf(sc_, front, v0, tg_phase));
  }

  WheelRailRun Run(const WheelRailProgress& progress);

 private:
  // ---- setup ---------------------------------------------------------------------------------
  // Draws the sensors' constants; returns the TG wheel's random tooth phase (in pulses).
  double InitSensors() {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const double tg_phase = 0.5 + 0.5 * u(rng_);
    if (sc_.imu.enabled) {
      for (int k = 0; k < 3; ++k) {
        accel_bias_[static_cast<std::size_t>(k)] = sc_.imu.accel_bias_mps2 * u(rng_);
      }
      for (int k = 0; k < 3; ++k) {
        rate_bias_[static_cast<std::size_t>(k)] = sc_.imu.rate_bias_deg_s * kPi / 180.0 * u(rng_);
      }
    }
    return tg_phase;
  }

  // Roll of the car body (right-hand about x forward): cant towards the inside of the curve
  // plus the suspension's lean outwards under uncompensated lateral acceleration.
  [[nodiscard]] double BodyRoll(double s, double v) const {
    double track = 0.0;
    for (const auto& c : sc_.curves) {
      if (s < c.begin_m || s >= c.end_m) {
        continue;
      }
      double ramp = 1.0;
      if (c.transition_m > 0.0) {
        ramp = std::min({1.0, (s - c.begin_m) / c.transition_m, (c.end_m - s) / c.transition_m});
      }
      track += -(c.radius_m > 0.0 ? 1.0 : -1.0) * std::asin(ramp * c.cant_mm / kCantBaseMm);
    }
    const double kappa = CurvatureAt(sc_.curves, s);
    const double lateral = v * v * kappa * std::cos(track) + kG * std::sin(track);
    return track + sc_.vehicle.roll_coefficient * lateral / kG;
  }

  // ---- driver -------------------------------------------------------------------------------
  // The lead-in (LeadInSpec): braked at standstill, then a PI speed controller on the ramp
  // to the initial speed, jerk-limited like the hold controller.
  void LeadInDriver(double dt, double v) {
    const LeadInSpec& l = sc_.lead_in;
    lead_t_ += dt;
    if (lead_t_ < l.standstill_s) {
      traction_ = 0.0;
      brake_ = l.brake_cap;
      hold_u_ = -l.brake_cap;
      return;
    }
    const double target = std::min(sc_.initial_speed_kmh / 3.6, l.accel_mps2 * (lead_t_ - l.standstill_s));
    const double e = target - v;
    double u = 1.0 * e + 0.2 * lead_integral_;
    if (u > -l.brake_cap && u < l.traction_cap) {
      lead_integral_ += e * dt;
    }
    u = std::clamp(u, -l.brake_cap, l.traction_cap);
    hold_u_ += std::clamp(u - hold_u_, -0.5 * dt, 0.5 * dt);
    traction_ = std::max(hold_u_, 0.0);
    brake_ = std::max(-hold_u_, 0.0);
  }

  void Driver(double t, double dt, double v) {
    if (leading_) {
      LeadInDriver(dt, v);
      return;
    }
    const auto& cmds = sc_.driver;
    while (next_cmd_ < cmds.size() && cmds[next_cmd_].t_s <= t) {
      const auto& c = cmds[next_cmd_];
      trac_from_ = traction_;  // ramps start from the demands in force
      brake_from_ = brake_;
      ramp_t0_ = c.t_s;
      active_cmd_ = static_cast<long>(next_cmd_);
      ++next_cmd_;
      if (c.hold_kmh && !hold_active_) {
        hold_integral_ = 0.0;
        hold_u_ = traction_ - brake_;
      }
      hold_active_ = c.hold_kmh.has_value();
    }
    const double tc = TracCap(t);
    const double bc = BrakeCap(t);
    if (!hold_active_) {
      traction_ = tc;
      brake_ = bc;
      return;
    }
    const double target = *cmds[static_cast<std::size_t>(active_cmd_)].hold_kmh / 3.6;
    const double e = target - v;
    double u = 0.3 * e + 0.05 * hold_integral_;
    const double lo = -bc, hi = tc;
    if (u > lo && u < hi) {
      hold_integral_ += e * dt;
    }
    u = std::clamp(u, lo, hi);
    hold_u_ += std::clamp(u - hold_u_, -0.5 * dt, 0.5 * dt);  // jerk limit 0.5 /s
    traction_ = std::max(hold_u_, 0.0);
    brake_ = std::max(-hold_u_, 0.0);
  }
  [[nodiscard]] double Ramp(double from, double to, double t, double ramp) const {
    if (ramp <= 0.0 || t >= ramp_t0_ + ramp) {
      return to;
    }
    return from + (to - from) * (t - ramp_t0_) / ramp;
  }
  [[nodiscard]] double TracCap(double t) const {
    if (active_cmd_ < 0) {
      return 0.0;
    }
    const auto& c = sc_.driver[static_cast<std::size_t>(active_cmd_)];
    return Ramp(trac_from_, c.traction, t, c.ramp_s);
  }
  [[nodiscard]] double BrakeCap(double t) const {
    if (active_cmd_ < 0) {
      return 0.0;
    }
    const auto& c = sc_.driver[static_cast<std::size_t>(active_cmd_)];
    return Ramp(brake_from_, c.brake, t, c.ramp_s);
  }


  // ---- sensors ------------------------------------------------------------------------------
  ra::ImuSample ImuSample(std::int64_t t_us);
  double Normal() { return normal_(rng_); }

  const WheelRailScenario& sc_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::unique_ptr<WheelRailVehicle> car_;

  // lead-in (kLeadIn scenarios): running until the front reaches the initial front
  bool leading_ = false;
  double lead_t_ = 0.0, lead_integral_ = 0.0;

  // driver
  std::size_t next_cmd_ = 0;
  long active_cmd_ = -1;
  double trac_from_ = 0.0, brake_from_ = 0.0, ramp_t0_ = 0.0;
  bool hold_active_ = false;
  double hold_integral_ = 0.0, hold_u_ = 0.0;
  double traction_ = 0.0, brake_ = 0.0;

  // TG faults
  enum class TgMode : std::uint8_t { kNormal, kDropout, kStuck };
  TgMode tg_mode_ = TgMode::kNormal;
  std::int64_t tg_offset_ = 0;        // reported = true - offset in normal operation
  std::int64_t tg_frozen_ = 0;
  std::int64_t tg_fault_true_ = 0;    // true count in the last faulty cycle
  std::int64_t tg_reported_ = 0;
  std::int64_t tg_edge_reported_ = 0;

  // IMU
  std::array<double, 3> accel_bias_{}, rate_bias_{}, accel_drift_{}, rate_drift_{};
  double prev_vx_ = 0.0, prev_vz_ = 0.0, prev_pitch_ = 0.0, prev_roll_ = 0.0, prev_vkappa_ = 0.0, prev_v2kappa_ = 0.0;
};

ra::ImuSample Simulator::ImuSample(std::int64_t t_us) {
  const double vx = car_->BodyVx(), vz = car_->BodyVz();
  const double pitch = car_->BodyPitchRad();
  const double v = car_->SpeedMps();
  const double s = car_->CentreM();
  const double kappa = CurvatureAt(sc_.curves, s);
  const double roll = BodyRoll(s, v);
  const double vkappa = v * kappa;
  const double v2kappa = v * v * kappa;

  // Mean over the sample period: delta-velocity and delta-angle.
  const double ax_w = (vx - prev_vx_) / kImuPeriodS;
  const double az_w = (vz - prev_vz_) / kImuPeriodS;
  const double theta = 0.5 * (pitch + prev_pitch_);
  const double psi = 0.5 * (roll + prev_roll_);
  const double theta_dot = (pitch - prev_pitch_) / kImuPeriodS;
  const double psi_dot = (roll - prev_roll_) / kImuPeriodS;
  const double yaw_rate = 0.5 * (vkappa + prev_vkappa_);
  const double centripetal = 0.5 * (v2kappa + prev_v2kappa_);
  prev_vx_ = vx;
  prev_vz_ = vz;
  prev_pitch_ = pitch;
  prev_roll_ = roll;
  prev_vkappa_ = vkappa;
  prev_v2kappa_ = v2kappa;

  // Specific force in the level track frame (x heading, y left, z up) -> body.
  const Vec3 f = ToBody(Vec3{ax_w, centripetal, az_w + kG}, theta, psi);
  // Angular velocity: yaw about the vertical, pitch about the level y (nose up = -y), roll.
  const Vec3 yaw_b = ToBody(Vec3{0.0, 0.0, yaw_rate}, theta, psi);
  const double cp = std::cos(psi), sp = std::sin(psi);
  Vec3 w{yaw_b.x + psi_dot, yaw_b.y - theta_dot * cp, yaw_b.z + theta_dot * sp};

  ra::ImuSample out;
  out.time_us = t_us;
  std::array<double, 3> acc{f.x, f.y, f.z};
  std::array<double, 3> rate{w.x, -w.y, w.z};  // wy: nose-up pitch rate (design note §7 convention)
  if (sc_.imu.enabled) {
    const double sq = std::sqrt(kImuPeriodS);
    const double deg = kPi / 180.0;
    for (std::size_t k = 0; k < 3; ++k) {
      accel_drift_[k] += sc_.imu.accel_drift_mps2_per_sqrt_s * sq * Normal();
      acc[k] += accel_bias_[k] + accel_drift_[k] + sc_.imu.accel_noise_mps2 * Normal();
    }
    for (std::size_t k = 0; k < 3; ++k) {
      rate_drift_[k] += sc_.imu.rate_drift_deg_s_per_sqrt_s * deg * sq * Normal();
      rate[k] += rate_bias_[k] + rate_drift_[k] + sc_.imu.rate_noise_deg_s * deg * Normal();
    }
  }
  out.ax = acc[0];
  out.ay = acc[1];
  out.az = acc[2];
  out.wx = rate[0];
  out.wy = rate[1];
  out.wz = rate[2];
  return out;
}

// Active in the cycle ending at t_us: from <= t < to (compared in whole microseconds).
bool FaultActive(const SensorFault& f, std::int64_t t_us) {
  return t_us >= std::llround(f.from_s * 1e6) && t_us < std::llround(f.to_s * 1e6);
}

WheelRailRun Simulator::Run(const WheelRailProgress& progress) {
  WheelRailRun run;
  run.scenario = sc_.name;
  run.pulse_length_m = kPi * sc_.vehicle.wheel_diameter_m / sc_.tg.teeth;
  const std::int64_t step_us = sc_.step_us;
  const double dt = static_cast<double>(step_us) * 1e-6;
  const auto total_us = static_cast<std::int64_t>(std::llround(sc_.duration_s * 1e6));
  const std::int64_t steps_per_imu = kImuPeriodUs / step_us;
  const auto n_cycles = static_cast<std::size_t>(total_us / kCycleUs);
  run.cycles.reserve(n_cycles);
  run.truth.reserve(n_cycles);

  // Initial state in line terms.
  car_->UpdateWheelsets();
  const double front0 = car_->FrontM();
  {
    prev_vx_ = car_->BodyVx();
    prev_vz_ = car_->BodyVz();
    prev_pitch_ = car_->BodyPitchRad();
    const double v = car_->SpeedMps();
    prev_roll_ = BodyRoll(car_->CentreM(), v);
    prev_vkappa_ = v * CurvatureAt(sc_.curves, car_->CentreM());
    prev_v2kappa_ = v * prev_vkappa_;
  }
  std::array<EventTrack, 4> ev{};
  const double ev_thr = sc_.truth.event_creep;
  const auto ev_min_us = static_cast<std::int64_t>(std::llround(sc_.truth.event_min_s * 1e6));
  auto close_event = [&](std::size_t i, std::int64_t end_us, double front) {
    auto& e = ev[i];
    if (e.active && end_us - e.start_us >= ev_min_us) {
      SlipEvent se;
      se.axle = static_cast<int>(i);
      se.tg_axle = static_cast<int>(i) == sc_.tg.axle;
      se.kind = e.peak > 0.0 ? SlipKind::kSlip : SlipKind::kSlide;
      se.start_ms = e.start_us / 1000;
      se.end_ms = end_us / 1000;
      se.peak_creep = e.peak;
      se.start_front_m = e.start_front;
      se.end_front_m = front;
      run.events.push_back(se);
    }
    e.active = false;
  };

  ra::CycleInput cycle;
  TruthCycle truth;
  int imu_index = 0;
  std::array<double, 4> creep_peak{};
  double prev_front = front0;
  double prev_speed = car_->SpeedMps();
  std::int64_t next_progress_us = total_us / 10;
  std::int64_t prev_cycle_time_ms = 0;

  // The run's time starts at 0; the scenario's time (driver, zone windows, faults) at t0_us,
  // after the lead-in. During the lead-in every scenario time lies before 0.
  constexpr std::int64_t kBeforeScenarioUs = -(std::int64_t{1} << 50);
  std::int64_t t0_us = 0;
  const double lead_s = leading_ ? sc_.lead_in.standstill_s + 4.0 * (sc_.initial_speed_kmh / 3.6 / sc_.lead_in.accel_mps2 +
                                                                      sc_.lead_in.hold_s) + 60.0
                                 : 0.0;
  const auto lead_limit_us = static_cast<std::int64_t>(std::llround(lead_s * 1e6));
  for (std::int64_t step = 0;; ++step) {
    const std::int64_t t_us = step * step_us;
    if (!leading_ && t_us - t0_us >= total_us) {
      break;
    }
    if (leading_ && t_us >= lead_limit_us) {
      throw offline::InputError(sc_.file + ": start: the lead-in did not reach the initial front " +
                                std::to_string(sc_.initial_front_m) + " m within " + std::to_string(lead_s) + " s");
    }
    const double scenario_s =
        leading_ ? static_cast<double>(kBeforeScenarioUs) * 1e-6 : static_cast<double>(t_us - t0_us) * 1e-6;
    car_->Step(static_cast<double>(t_us) * 1e-6, scenario_s, dt, [&](double v) {
      Driver(scenario_s, dt, v);
      return WheelRailDemand{traction_, brake_};
    });
    ++run.steps;
    const std::int64_t now_us = t_us + step_us;
    const std::int64_t scenario_us = leading_ ? kBeforeScenarioUs : now_us - t0_us;
    // truth per step: creep and events
    for (std::size_t i = 0; i < 4; ++i) {
      const double c = car_->Wheelset(static_cast<int>(i)).creep;
      if (std::fabs(c) > std::fabs(creep_peak[i])) {
        creep_peak[i] = c;
      }
      auto& e = ev[i];
      if (std::fabs(c) > ev_thr) {
        if (!e.active) {
          e.active = true;
          e.start_us = now_us;
          e.peak = c;
          e.start_front = car_->FrontM();
        } else if (std::fabs(c) > std::fabs(e.peak)) {
          e.peak = c;
        }
      } else if (e.active) {
        close_event(i, now_us, car_->FrontM());
      }
    }
    if ((step + 1) % steps_per_imu != 0) {
      continue;
    }
    // 10 ms: one IMU sample
    car_->UpdateWheelsets();
    cycle.imu[static_cast<std::size_t>(imu_index)] = ImuSample(now_us);
    ++imu_index;
    if (imu_index < ra::kImuSamplesPerCycle) {
      continue;
    }
    imu_index = 0;
    // 100 ms: the cycle
    const double t_s = static_cast<double>(now_us) * 1e-6;
    const double front = car_->FrontM();
    if (front > sc_.vertical.end_m || front - sc_.vehicle.length_m < sc_.vertical.begin_m) {
      throw offline::InputError(sc_.file + ": vertical: the train left the alignment at t = " + std::to_string(t_s) +
                       " s (front " + std::to_string(front) + " m); extend vertical.begin_m/end_m");
    }
    cycle.time_ms = now_us / 1000;
    cycle.imu_count = static_cast<std::uint8_t>(ra::kImuSamplesPerCycle);
    cycle.balise.reset();
    truth = TruthCycle{};
    for (const auto& b : sc_.balises) {
      if (prev_front < b.position_m && front >= b.position_m) {
        cycle.balise = ra::BaliseFix{std::llround(front * 1000.0)};
        truth.balise = true;
      }
    }
    // TG (true) and faults
    const std::int64_t true_count = car_->TgCount();
    const auto edge_s = car_->TgEdgeS();
    const std::int64_t true_edge_us = edge_s ? std::min(static_cast<std::int64_t>(std::floor(*edge_s * 1e6)), now_us) : 0;
    bool dropout = false, stuck = false;
    std::int64_t burst = 0;
    std::uint32_t mask = 0;
    for (const auto& f : sc_.faults) {
      if (FaultActive(f, scenario_us)) {
        mask |= 1u << static_cast<unsigned>(f.kind);
        dropout = dropout || f.kind == SensorFaultKind::kTgDropout;
        stuck = stuck || f.kind == SensorFaultKind::kTgStuck;
        burst += f.kind == SensorFaultKind::kTgBurst ? f.pulses : 0;
      }
    }
    std::int64_t reported = 0;
    if (dropout) {
      tg_mode_ = TgMode::kDropout;  // power lost: the counter reads 0
    } else if (stuck) {
      if (tg_mode_ != TgMode::kStuck) {
        tg_frozen_ = tg_reported_;
      }
      tg_mode_ = TgMode::kStuck;
      reported = tg_frozen_;
    } else {
      if (tg_mode_ == TgMode::kDropout) {
        tg_offset_ = tg_fault_true_;  // counting restarts from 0
      } else if (tg_mode_ == TgMode::kStuck) {
        tg_offset_ = tg_fault_true_ - tg_frozen_;  // the pulses of the stuck interval are lost
      }
      tg_mode_ = TgMode::kNormal;
      tg_offset_ -= burst;
      reported = true_count - tg_offset_;
    }
    if (dropout || stuck) {
      tg_fault_true_ = true_count;
    }
    if (burst > 0 && !dropout && !stuck) {
      tg_edge_reported_ = now_us - 1;
    } else if (reported > tg_reported_) {
      tg_edge_reported_ = true_edge_us;
    } else if (reported < tg_reported_) {
      tg_edge_reported_ = 0;
    }
    tg_reported_ = reported;
    cycle.tg.time_us = now_us;
    cycle.tg.pulses = reported;
    cycle.tg.last_edge_us = tg_edge_reported_;
    // IMU and cycle faults
    for (const auto& f : sc_.faults) {
      if (!FaultActive(f, scenario_us)) {
        continue;
      }
      switch (f.kind) {
        case SensorFaultKind::kTgEdgeInvalid:
          cycle.tg.last_edge_us = now_us + 500;
          break;
        case SensorFaultKind::kImuNan:
          cycle.imu[4].ax = std::nan("");
          break;
        case SensorFaultKind::kImuGap: {
          // the first `samples` delivered, the rest lost
          cycle.imu_count = static_cast<std::uint8_t>(f.samples);
          for (std::size_t k = static_cast<std::size_t>(f.samples); k < cycle.imu.size(); ++k) {
            cycle.imu[k] = ra::ImuSample{};
          }
          break;
        }
        case SensorFaultKind::kImuTimestamps:
          std::swap(cycle.imu[4], cycle.imu[5]);
          break;
        case SensorFaultKind::kImuOutOfRange:
          cycle.imu[5].ax = f.value;
          break;
        case SensorFaultKind::kCycleTime:
          cycle.time_ms = prev_cycle_time_ms;
          break;
        default:
          break;
      }
    }
    prev_cycle_time_ms = cycle.time_ms;
    // truth
    const double speed = car_->SpeedMps();
    truth.time_ms = now_us / 1000;
    truth.front_m = front;
    truth.distance_m = front - front0;
    truth.speed_mps = speed;
    truth.accel_mps2 = (speed - prev_speed) / (static_cast<double>(kCycleUs) * 1e-6);
    truth.tg_distance_m = static_cast<double>(true_count) * run.pulse_length_m;
    truth.tg_wheel_speed_mps = car_->Wheelset(sc_.tg.axle).omega * car_->WheelRadiusM();
    for (std::size_t i = 0; i < 4; ++i) {
      const WheelsetState& a = car_->Wheelset(static_cast<int>(i));
      truth.creep[i] = a.creep;
      truth.creep_peak[i] = creep_peak[i];
      truth.normal_force_n[i] = a.normal_n;
      truth.creep_force_n[i] = a.force_n;
    }
    creep_peak.fill(0.0);
    const double centre = car_->CentreM();
    truth.gradient_permille = GradientPermilleAt(sc_.vertical, centre);
    truth.pitch_rad = car_->BodyPitchRad();
    truth.roll_rad = BodyRoll(centre, speed);
    truth.curvature_1pm = CurvatureAt(sc_.curves, centre);
    truth.traction = traction_;
    truth.brake = brake_;
    truth.faults = mask;
    run.cycles.push_back(cycle);
    run.truth.push_back(truth);
    prev_front = front;
    prev_speed = speed;
    // rail pieces around the car
    car_->KeepRailAround();
    // the lead-in ends at the first cycle boundary with the front at the initial front
    if (leading_ && front >= sc_.initial_front_m) {
      leading_ = false;
      t0_us = now_us;
      run.lead_in_ms = now_us / 1000;
      next_progress_us = t0_us + total_us / 10;
    }
    if (progress && !leading_ && now_us >= next_progress_us) {
      progress(static_cast<double>(now_us - t0_us) * 1e-6, sc_.duration_s);
      next_progress_us += total_us / 10;
    }
  }
  const double front_end = car_->FrontM();
  for (std::size_t i = 0; i < 4; ++i) {
    close_event(i, t0_us + total_us, front_end);
  }
  std::sort(run.events.begin(), run.events.end(), [](const SlipEvent& a, const SlipEvent& b) {
    return a.start_ms != b.start_ms ? a.start_ms < b.start_ms : a.axle < b.axle;
  });
  run.simulated_s = static_cast<double>(t0_us + total_us) * 1e-6;
  return run;
}

}  // namespace

WheelRailRun SimulateWheelRail(const WheelRailScenario& sc, const WheelRailProgress& progress) {
  auto sim = std::make_unique<Simulator>(sc);
  return sim->Run(progress);
}

}  // namespace railproof::ra::analysis