// Simple longitudinal train dynamics and the braking-supervision stand-in of the line
// simulation (offline; SI units in double: m, s, m/s, m/s^2).
//
// Dynamics (one point mass per train, per unit mass):
//   a = traction - brake - g/1000 * (r(v) + i)
//   traction in [0, accel_max] while v < max speed (constant maximum, no power limit),
//   brake in [0, service_decel], or emergency_decel alone when the emergency brake is on,
//   r(v) = a0 + a1*v + a2*v^2   specific running resistance in N/kN (= per mille of the
//                                train's weight), v in km/h (Davis form),
//   i = mean gradient in per mille under the train (+ rising), g = 9.81 m/s^2.
// The acceleration is constant over one step (exact integration of a piecewise-constant
// acceleration); a braking or coasting train stops at v = 0 and does not roll back (a
// standing train holds its brake). Brakes act without delay: the free-running time is
// accounted for in the supervision curves instead.
//
// Braking supervision (stand-in until the braking issue; ASM-013 is what it discharges):
// the on-board unit supervises its stop limit L with its safe front x (estimated front +
// length correction) and d = L - x:
//   service curve  v_s(d) = speed from which the train stops within d - margin with
//                  deceleration beta_s' after free_running_s at constant speed,
//   emergency curve v_e(d) = the same with beta_e', emergency_free_running_s and no margin,
//   beta' = nominal deceleration minus g/1000 * (steepest falling gradient up to L).
// The driving controller never aims above v_s (service brake follows it); if v > v_e the
// emergency brake is applied and held until standstill. An unusable authority (no limit,
// expired, or radio link down) means standstill: emergency brake.
#pragma once

#include <cstdint>

namespace railproof::offline {

inline constexpr double kGravity = 9.81;

// Running resistance r(v) = a0 + a1 v + a2 v^2 in N/kN, v in km/h. Default: a typical
// electric multiple unit (about 6.5 N/kN at 100 km/h).
struct Resistance {
  double a0 = 1.5;
  double a1 = 0.02;
  double a2 = 0.0003;
};

struct TrainPerformance {
  double length_m = 0.0;
  double max_speed_mps = 0.0;
  double accel_mps2 = 0.0;
  double service_decel_mps2 = 0.0;
  double emergency_decel_mps2 = 0.0;
  Resistance resistance;
};

// Commands for one step.
struct Control {
  double traction_mps2 = 0.0;  // 0 .. accel_mps2
  double brake_mps2 = 0.0;     // 0 .. service_decel_mps2
  bool emergency = false;      // overrides both
};

struct Motion {
  double position_m = 0.0;  // true front
  double speed_mps = 0.0;   // >= 0
};

// Resistance deceleration g*r(v)/1000 in m/s^2.
double ResistanceDecel(const Resistance& r, double speed_mps);

// Net acceleration for a control, speed and mean gradient (per mille, + rising).
double NetAcceleration(const TrainPerformance& perf, const Control& control, double speed_mps,
                       double gradient_permille);

// Advances the motion by dt seconds with constant net acceleration; stops at v = 0 (no
// rolling back); a standing train with net acceleration <= 0 stays.
Motion Advance(const Motion& m, double net_accel_mps2, double dt_s);

// Largest speed from which a train stops within `distance_m` with deceleration `decel`
// after `free_running_s` at constant speed: v t + v^2 / (2 b) = d, v = b (sqrt(t^2 + 2d/b) - t).
// 0 for d <= 0 or b <= 0.
double CurveSpeed(double distance_m, double decel_mps2, double free_running_s);

// Distance to stop from v: v t + v^2 / (2 b).
double StoppingDistance(double speed_mps, double decel_mps2, double free_running_s);

}  // namespace railproof::offline
