// A scenario train on the Box2D wheel-rail vehicle (wheel_rail_train.hpp).
#include "railproof/sim/wheel_rail_train.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::sim {

namespace {

namespace wr = ra::analysis;

// The wheel-rail simulator's fixed step (the default of its scenarios, spec/wheelrail).
constexpr std::int64_t kVehicleStepUs = 1000;
constexpr double kEventCreep = wr::TruthSpec{}.event_creep;
// A slip or slide lasts until the measured axle's creep has stayed within kEventCreep this
// long (the slip control lets it dip below between its cycles).
constexpr double kAxleQuietS = 1.0;
// Below this the car stands: a car held by its brakes settles on its suspension, and that
// jitter is not a motion the train makes (ra's kHoldEnterSpeed).
constexpr double kStandstillMps = 0.01;

// The simulator's car with the train's traction, brakes and running resistance per unit mass.
wr::VehicleSpec ScaledCar(const TrainPerformance& p) {
  wr::VehicleSpec v;
  const double r = v.wheel_diameter_m / 2.0;
  const double mass = v.body_mass_kg + 2.0 * v.bogie_mass_kg + wr::kWheelRailAxles * v.wheelset_mass_kg;
  // the rotating wheelsets take their share of every force, as the train's masses do
  const double inertial = mass + wr::kWheelRailAxles * v.wheelset_inertia_kgm2 / (r * r);
  const auto motored = static_cast<double>(std::count(v.motored.begin(), v.motored.end(), true));
  v.max_traction_force_n = p.accel_mps2 * inertial / motored;
  // constant power above constant_power_from_mps (MaxTraction); without it none within reach
  v.max_power_w = v.max_traction_force_n * (p.constant_power_from_mps > 0.0 ? p.constant_power_from_mps : 1e6);
  v.max_brake_force_n = p.service_decel_mps2 * inertial / wr::kWheelRailAxles;
  // Davis terms in N/kN of the weight, v in km/h (dynamics.hpp) -> N, v in m/s
  const double weight_kn = mass * wr::kWheelRailGravity / 1000.0;
  v.resistance_a_n = p.resistance.a0 * weight_kn;
  v.resistance_b_ns_m = p.resistance.a1 * 3.6 * weight_kn;
  v.resistance_c_ns2_m2 = p.resistance.a2 * 3.6 * 3.6 * weight_kn;
  v.max_speed_kmh = p.max_speed_mps * 3.6;
  return v;
}

wr::WheelRailVehicleConfig CarConfig(const Scenario& sc, const TrainSpec& train, const RunningLine& line,
                                     double front_m) {
  wr::WheelRailVehicleConfig c;
  c.vehicle = ScaledCar(train.performance);
  c.vertical.begin_m = 0.0;
  c.vertical.end_m = static_cast<double>(line.length_mm) / 1000.0;
  for (const auto& g : line.gradients) {
    c.vertical.gradients.push_back(wr::GradientPoint{static_cast<double>(g.section.begin_mm) / 1000.0,
                                                     static_cast<double>(g.permille_x10) / 10.0, train.entry});
  }
  for (const auto& a : sc.low_adhesion) {
    wr::AdhesionZone z;
    z.begin_m = static_cast<double>(a.begin_mm) / 1000.0;
    z.end_m = static_cast<double>(a.end_mm) / 1000.0;
    z.factor = (a.wet ? c.adhesion.wet_factor : 1.0) * a.factor;
    z.entry = a.entry;
    c.rail.zones.push_back(z);
  }
  c.slip_control.enabled = true;  // wheel-slide protection and traction anti-slip
  c.front_m = front_m;
  return c;
}

class BoxTrain final : public WheelRailTrain {
 public:
  BoxTrain(const Scenario& sc, const TrainSpec& train, const RunningLine& line, double front_m)
      : perf_(train.performance), car_(CarConfig(sc, train, line, front_m)), tg_axle_(wr::TgSpec{}.axle) {
    car_.UpdateWheelsets();
    // the car's front stands where the train's is (the built car sits within a millimetre)
    offset_m_ = front_m - car_.FrontM();
    speed_ = 0.0;
    wheel_ = 0.0;
  }

  WheelRailStep Step(double applied_mps2, double t_s, double dt_s) override {
    const wr::WheelRailDemand d = applied_mps2 >= 0.0 ? wr::WheelRailDemand{applied_mps2 / perf_.accel_mps2, 0.0}
                                                      : wr::WheelRailDemand{0.0, -applied_mps2 / perf_.service_decel_mps2};
    const std::int64_t steps = std::max<std::int64_t>(1, std::llround(dt_s * 1e6) / kVehicleStepUs);
    const double h = static_cast<double>(kVehicleStepUs) * 1e-6;
    const auto demand = [&d](double /*speed*/) { return d; };
    for (std::int64_t k = 0; k < steps; ++k) {
      const double t = t_s + static_cast<double>(k) * h;
      car_.Step(t, t, h, demand);
    }
    car_.UpdateWheelsets();
    car_.KeepRailAround();
    const wr::WheelsetState& tg = car_.Wheelset(tg_axle_);
    WheelRailStep out;
    const double v = car_.SpeedMps();
    out.end = offline::Motion{car_.FrontM() + offset_m_, v < kStandstillMps ? 0.0 : v};
    const double wheel = std::max(0.0, tg.omega * car_.WheelRadiusM());
    out.accel_mps2 = (out.end.speed - speed_) / dt_s;
    out.axle = AxleMotion{wheel_, (wheel - wheel_) / dt_s};
    out.creep = tg.creep;
    if (std::fabs(tg.creep) > kEventCreep) {
      state_ = tg.creep > 0.0 ? AxleState::kSlip : AxleState::kSlide;
      quiet_s_ = 0.0;
    } else if ((quiet_s_ += dt_s) >= kAxleQuietS) {
      state_ = AxleState::kRolling;
    }
    out.state = state_;
    speed_ = out.end.speed;
    wheel_ = wheel;
    return out;
  }

  [[nodiscard]] double CarLengthM() const override { return wr::VehicleSpec{}.length_m; }

 private:
  TrainPerformance perf_;
  wr::WheelRailVehicle car_;
  int tg_axle_;
  double offset_m_ = 0.0;
  double speed_ = 0.0;  // body speed and measured axle's surface speed at the end of the last step
  double wheel_ = 0.0;
  AxleState state_ = AxleState::kRolling;
  double quiet_s_ = 0.0;  // time the measured axle's creep has stayed within kEventCreep
};

}  // namespace

std::unique_ptr<WheelRailTrain> MakeWheelRailTrain(const Scenario& sc, const TrainSpec& train, const RunningLine& line,
                                                   double front_m) {
  return std::make_unique<BoxTrain>(sc, train, line, front_m);
}

}  // namespace railproof::sim
