// The one train-motion model of the offline tools: a point mass moving along the track.
//
// Forces per unit mass (accelerations, + forward; any length unit with seconds, the unit of
// the gravity given):
//   a = applied - r(v) - g i / 1000
//   applied   traction in [0, MaxTraction(v)] while v < max speed (constant accel_max, or with
//             constant_power_from_mps > 0 falling as accel_max v_b / v above that speed v_b),
//             or minus a braking deceleration (service, or the emergency brake alone),
//   r(v)      running resistance a0 + a1 v + a2 v^2 in N/kN (= per mille of the train's
//             weight), v in km/h (Davis form; SI only); an electric multiple unit's from its
//             consist by ConsistResistance,
//   g i/1000  gravity on a gradient of i per mille (+ rising): GradeDecel; curve resistance
//             enters the same term as an equivalent rising gradient (CurveResistancePermille,
//             ASM-034), averaged over the train like the gradient (RunningLine's
//             MeanGradientPermille and MeanCurveResistancePermille, line.hpp).
// Motion under a constant acceleration is exact: Advance over a time, SpeedAfter and TimeOver
// over a distance, TimeToCover a distance; a braking or coasting train stops at v = 0 and does
// not roll back (a standing train holds its brake). Braking curves: StoppingDistance and its
// inverse CurveSpeed (a deceleration after a free-running time at constant speed). Speed
// limits act on the whole train: RunningLine::ForEachLimitActing (line.hpp).
//
// Every offline train motion is this model, each integrated the way its purpose needs:
//   system simulator (sim)    fixed 100 ms steps (Advance of NetAcceleration) with the driver
//                             and the real on-board unit in the loop (its brake demand acts on
//                             the applied acceleration); mean gradient and mean curve
//                             resistance under the train, running resistance; SI units,
//                             gravity kGravity; the sensor model
//                             derives the odometry's TG and IMU streams from the same motion;
//   margin verification (br)  the worst case integrated exactly over the pieces of the most
//                             falling gradient under the train: run-up under traction
//                             (Advance, SpeedAfter, TimeOver), then braking to a stop
//                             (SpeedAfter, StoppingDistance); the falsifier in 10 ms steps
//                             (Advance) with the runtime supervision in the loop; no running
//                             resistance (it would only help); mm, the runtime's gravity. The
//                             braking patterns the margins are measured against are the
//                             RUNTIME's integer patterns (br::PatternCalculator), called as they
//                             are: they are what is verified, not part of this model;
//   warning-time study (lc)   the run between two stops on a 1 m grid: the speed envelope of
//                             accelerating at accel_max, the limits under the train and braking
//                             at the service deceleration ahead of lower limits and the stop
//                             (SpeedAfter), times by TimeOver, positions in time by Advance and
//                             TimeToCover; gradients and resistance not modelled (its
//                             documented model); mm;
//   headway study (fc)        fixed time steps (Advance of NetAcceleration, D2 §3) for the leader
//                             and the follower, with the D2 consist's resistance
//                             (ConsistResistance) and a constant-power traction region; mean
//                             gradient under the train; no curve resistance (D2's equation of
//                             motion has none); SI units, gravity kGravity.
// Not this model: the Box2D wheel-rail simulator (ra) is multi-body creep physics (car body,
// bogies, wheelsets, slip-dependent adhesion per wheelset): slip and slide, its subject, do
// not exist for a point mass. The system simulator puts a scenario's trains on it where the
// scenario declares low adhesion (ra::analysis::WheelRailVehicle, spec/design/sim.md).
//
// Offline module.
#pragma once

namespace railproof::offline {

// Gravity of the line simulation (m/s^2). The margin verification uses the runtime's
// (spec/parameters/br.yaml gravity_mm_s2), the quantity its patterns are computed with.
inline constexpr double kGravity = 9.81;

// Running resistance r(v) = a0 + a1 v + a2 v^2 in N/kN, v in km/h. Default: a typical
// electric multiple unit (about 6.5 N/kN at 100 km/h).
struct Resistance {
  double a0 = 1.5;
  double a1 = 0.02;
  double a2 = 0.0003;
};

// An electric multiple unit's consist: car count and the total masses of its motor cars and
// its trailers (t).
struct Consist {
  int cars = 0;
  double motor_mass_t = 0.0;
  double trailer_mass_t = 0.0;
};

// Running resistance of an electric multiple unit from its consist, the usual handbook form in
// kgf (W in t, v in km/h): (1.65 + 0.0247 v) W_motor + (0.78 + 0.0028 v) W_trailer +
// (0.028 + 0.0078 (cars - 1)) v^2, per unit weight: since 1 kgf/t = 1 N/kN it is a Davis form
// in N/kN. The coefficients are ASM-032's (the handbook D2 cites is not available).
Resistance ConsistResistance(const Consist& consist);

struct TrainPerformance {
  double length_m = 0.0;
  double max_speed_mps = 0.0;
  double accel_mps2 = 0.0;
  double service_decel_mps2 = 0.0;
  double emergency_decel_mps2 = 0.0;
  Resistance resistance;
  // Above this speed the traction falls as accel_mps2 * v_b / v (constant power); 0: the
  // constant maximum up to the maximum speed.
  double constant_power_from_mps = 0.0;
};

// The largest traction acceleration at a speed (accel_mps2, or lower in the constant-power
// region).
double MaxTraction(const TrainPerformance& perf, double speed_mps);

// Commands for one step.
struct Control {
  double traction_mps2 = 0.0;  // 0 .. accel_mps2
  double brake_mps2 = 0.0;     // 0 .. service_decel_mps2
  bool emergency = false;      // overrides both
};

// Front position and speed (m and m/s, or mm and mm/s).
struct Motion {
  double position = 0.0;
  double speed = 0.0;  // >= 0
};

// Resistance deceleration g r(v) / 1000 in m/s^2.
double ResistanceDecel(const Resistance& r, double speed_mps);

// Curve resistance of a curve of `radius_m` (> 0) in N/kN, that is per mille of the train's
// weight, the same unit as a rising gradient: 800 / R, the narrow-gauge handbook form
// (ASM-034). Inline: the line loader's mean under the train uses it, and the loaders are also
// built alone for fuzzing.
inline double CurveResistancePermille(double radius_m) { return radius_m > 0.0 ? 800.0 / radius_m : 0.0; }

// Deceleration by gravity on a gradient of `gradient_permille` (+ rising; negative on a
// falling gradient) in the unit of `gravity`: gravity * i / 1000.
double GradeDecel(double gradient_permille, double gravity = kGravity);

// Net acceleration (m/s^2) for a control, speed and mean gradient (per mille, + rising).
double NetAcceleration(const TrainPerformance& perf, const Control& control, double speed_mps,
                       double gradient_permille);

// Advances the motion by dt seconds with constant acceleration a; stops at v = 0 (no rolling
// back); a standing train with a <= 0 stays.
Motion Advance(const Motion& m, double a, double dt_s);

// Speed after `distance` at constant acceleration a from `speed`: sqrt(v^2 + 2 a d), 0 if the
// train stops before.
double SpeedAfter(double speed, double a, double distance);

// Time (s) to run `distance` at constant acceleration from speed v0 to speed v1:
// 2 d / (v0 + v1) (v0 + v1 > 0).
double TimeOver(double distance, double v0, double v1);

// Time (s) at which a train at `speed` with constant acceleration a has run `distance`
// (>= 0); +infinity if it stops before.
double TimeToCover(double speed, double a, double distance);

// Distance to stop from v: v t + v^2 / (2 b).
double StoppingDistance(double speed, double decel, double free_running_s);

// Largest speed from which a train stops within `distance` with deceleration `decel`
// after `free_running_s` at constant speed: v t + v^2 / (2 b) = d, v = b (sqrt(t^2 + 2d/b) - t).
// 0 for d <= 0 or b <= 0.
double CurveSpeed(double distance, double decel, double free_running_s);

}  // namespace railproof::offline
