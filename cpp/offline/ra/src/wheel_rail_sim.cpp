// Wheel-rail simulator: the Box2D vehicle, the creep-force and wheelset-spin model, the
// driver, the sensors and the truth (see wheel_rail.hpp for the model summary).
//
// Integration: Box2D steps the vehicle with a fixed step (default 1 ms, 4 velocity and 2
// position iterations). The wheelset spin J*domega/dt = T_motor - T_brake - r*F(creep) is
// stiff at low speed (time constant J*max(|v|,0.5)/(r^2*N*dmu/dcreep), about 0.1 ms at
// standstill), so it is integrated outside Box2D in double with 10 sub-steps per step, each
// a linearly implicit Euler update (the creep force linearised about the current spin on
// its rising branch): unconditionally stable on the rising branch, explicit on the falling
// branch where the physics itself is unstable (the slip grows). The mean creep force of the
// sub-steps is applied to the wheelset body for the Box2D step (momentum-consistent). The
// brake is a Coulomb torque on the wheelset: it may lock the wheel (omega = 0) but never
// reverse it.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <box2d/box2d.h>

#include "railproof/ra/analysis/wheel_rail.hpp"

namespace railproof::ra::analysis {

namespace {

constexpr double kG = kWheelRailGravity;
constexpr double kPi = 3.14159265358979323846;
constexpr double kWheelLift = 0.005;   // resting wheel centre above r: edge skin 0.01 - linear slop 0.005
constexpr int kSpinSubsteps = 10;
constexpr int kVelocityIterations = 4;  // Box2D solver iterations per step
constexpr int kPositionIterations = 2;
constexpr int kPieceIntervals = 64;    // rail chain piece: 64 table intervals of 1 m
constexpr double kTableStep = 1.0;
constexpr double kTableMargin = 300.0;  // table beyond the alignment ends (constant gradient)
constexpr double kRebaseDistance = 50.0;
constexpr double kPieceReach = 40.0;    // rail pieces kept this far beyond the car's ends
constexpr double kPivotAboveWheel = 0.47;  // secondary suspension pivot above the wheel centres
constexpr double kBogieCogAboveWheel = 0.15;
constexpr double kHoldEnterSpeed = 0.01;   // m/s: a locked, braked wheelset this slow is held by static friction
constexpr double kHoldExitSpeed = 0.05;
constexpr std::int64_t kImuPeriodUs = 10000;
constexpr std::int64_t kCycleUs = 100000;
constexpr double kImuPeriodS = 0.01;

// Arc length -> position on the rail polyline (vertices every 1 m), in double, in a frame
// whose origin is the table start.
class TrackTable {
 public:
  explicit TrackTable(const VerticalAlignment& v) : s0_(v.begin_m - kTableMargin) {
    const auto n = static_cast<std::size_t>(std::ceil((v.end_m + kTableMargin - s0_) / kTableStep)) + 1;
    x_.resize(n);
    z_.resize(n);
    x_[0] = 0.0;
    z_[0] = 0.0;
    for (std::size_t k = 1; k < n; ++k) {
      const double mid = s0_ + (static_cast<double>(k) - 0.5) * kTableStep;
      const double a = std::atan(GradientPermilleAt(v, mid) / 1000.0);
      x_[k] = x_[k - 1] + kTableStep * std::cos(a);
      z_[k] = z_[k - 1] + kTableStep * std::sin(a);
    }
  }
  [[nodiscard]] std::size_t Size() const { return x_.size(); }
  [[nodiscard]] double X(std::size_t k) const { return x_[k]; }
  [[nodiscard]] double Z(std::size_t k) const { return z_[k]; }
  [[nodiscard]] double S(std::size_t k) const { return s0_ + static_cast<double>(k) * kTableStep; }
  [[nodiscard]] std::size_t IndexOfS(double s) const {
    const double f = std::floor((s - s0_) / kTableStep);
    if (f <= 0.0) {
      return 0;
    }
    return std::min(static_cast<std::size_t>(f), x_.size() - 2);
  }
  // Point and unit tangent on the polyline at arc length s.
  void At(double s, double& x, double& z, double& c, double& sn) const {
    const std::size_t k = IndexOfS(s);
    const double f = (s - S(k)) / kTableStep;
    c = (x_[k + 1] - x_[k]) / kTableStep;
    sn = (z_[k + 1] - z_[k]) / kTableStep;
    x = x_[k] + f * (x_[k + 1] - x_[k]);
    z = z_[k] + f * (z_[k + 1] - z_[k]);
  }
  // Arc length of the polyline point with abscissa x.
  [[nodiscard]] double SOfX(double x) const {
    auto it = std::upper_bound(x_.begin(), x_.end(), x);
    std::size_t k = it == x_.begin() ? 0 : static_cast<std::size_t>(it - x_.begin()) - 1;
    k = std::min(k, x_.size() - 2);
    return S(k) + (x - x_[k]) / (x_[k + 1] - x_[k]) * kTableStep;
  }

 private:
  double s0_;
  std::vector<double> x_;
  std::vector<double> z_;
};

// Contact bookkeeping: friction per wheelset (0, or static friction while held) and the
// impulses of the last step.
class ContactListener : public b2ContactListener {
 public:
  std::array<float, kWheelRailAxles> friction{};
  std::array<double, kWheelRailAxles> normal_impulse{};
  std::array<double, kWheelRailAxles> tangent_impulse{};  // on the wheel, along +x of the contact tangent

  void Clear() {
    normal_impulse.fill(0.0);
    tangent_impulse.fill(0.0);
  }
  void PreSolve(b2Contact* contact, const b2Manifold* /*old*/) override {
    const int i = Axle(contact);
    if (i >= 0) {
      contact->SetFriction(friction[static_cast<std::size_t>(i)]);
      contact->SetRestitution(0.0f);
    }
  }
  void PostSolve(b2Contact* contact, const b2ContactImpulse* impulse) override {
    const int i = Axle(contact);
    if (i < 0) {
      return;
    }
    const double sign = contact->GetFixtureB()->GetUserData().pointer != 0 ? 1.0 : -1.0;
    b2WorldManifold wm;
    contact->GetWorldManifold(&wm);
    const double tx = static_cast<double>(wm.normal.y);  // Box2D tangent = cross(normal, 1)
    for (int p = 0; p < impulse->count; ++p) {
      normal_impulse[static_cast<std::size_t>(i)] += static_cast<double>(impulse->normalImpulses[p]);
      tangent_impulse[static_cast<std::size_t>(i)] += sign * tx * static_cast<double>(impulse->tangentImpulses[p]);
    }
  }

 private:
  static int Axle(b2Contact* c) {
    const auto a = c->GetFixtureA()->GetUserData().pointer;
    const auto b = c->GetFixtureB()->GetUserData().pointer;
    const auto v = a != 0 ? a : b;
    return v == 0 ? -1 : static_cast<int>(v) - 1;
  }
};

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

struct AxleState {
  double omega = 0.0;        // rad/s, + rolling forward
  double normal_n = 0.0;     // N from the last step
  double friction_n = 0.0;   // static friction force while held (from the last step)
  double creep = 0.0;
  double force_n = 0.0;      // creep force applied in the last step
  double v = 0.0;            // wheelset speed along the rail
  double s = 0.0;            // rail position of its contact
  double control = 1.0;      // slip-control torque factor
  bool hold = false;         // braked standstill held by static friction
};

struct EventTrack {
  bool active = false;
  std::int64_t start_us = 0;
  double peak = 0.0;
  double start_front = 0.0;
};

class Simulator {
 public:
  explicit Simulator(const WheelRailScenario& sc)
      : sc_(sc), law_(sc.adhesion), table_(sc.vertical), world_(b2Vec2(0.0f, static_cast<float>(-kG))), rng_(sc.seed) {
    const auto& v = sc_.vehicle;
    r_ = v.wheel_diameter_m / 2.0;
    overhang_ = (v.length_m - v.bogie_centres_m - v.axle_spacing_m) / 2.0;
    axle_offset_ = {overhang_, overhang_ + v.axle_spacing_m, overhang_ + v.bogie_centres_m,
                    overhang_ + v.bogie_centres_m + v.axle_spacing_m};
    pulse_angle_ = 2.0 * kPi / sc_.tg.teeth;
    world_.SetAllowSleeping(false);
    world_.SetContinuousPhysics(false);
    world_.SetContactListener(&listener_);
    leading_ = sc_.start == ScenarioStart::kLeadIn;
    InitSensors();
    BuildVehicle();
  }

  WheelRailRun Run(const WheelRailProgress& progress);

 private:
  // ---- setup ---------------------------------------------------------------------------------
  void InitSensors() {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    tg_angle_ = (0.5 + 0.5 * u(rng_)) * pulse_angle_;  // random tooth phase
    if (sc_.imu.enabled) {
      for (int k = 0; k < 3; ++k) {
        accel_bias_[static_cast<std::size_t>(k)] = sc_.imu.accel_bias_mps2 * u(rng_);
      }
      for (int k = 0; k < 3; ++k) {
        rate_bias_[static_cast<std::size_t>(k)] = sc_.imu.rate_bias_deg_s * kPi / 180.0 * u(rng_);
      }
    }
  }

  b2Vec2 Local(double x, double z) const {
    return b2Vec2(static_cast<float>(x - ox_), static_cast<float>(z - oz_));
  }

  void RailPoint(double s, double& x, double& z, double& c, double& sn) const { table_.At(s, x, z, c, sn); }

  void BuildVehicle() {
    const auto& v = sc_.vehicle;
    // a lead-in starts at rest so far back that its speed ramp and hold end at the front
    const double front = leading_ ? sc_.initial_front_m - LeadInDistanceM(sc_.lead_in, sc_.initial_speed_kmh / 3.6)
                                  : sc_.initial_front_m;
    const double v0 = leading_ ? 0.0 : sc_.initial_speed_kmh / 3.6;
    {
      double x, z, c, sn;
      RailPoint(front - v.length_m / 2.0, x, z, c, sn);
      ox_ = std::round(x);
      oz_ = std::round(z);
    }
    UpdatePieces(front - v.length_m, front);

    // Wheel centres.
    std::array<double, 4> wx{}, wz{}, tc{}, ts{};
    for (std::size_t i = 0; i < 4; ++i) {
      double x, z, c, sn;
      RailPoint(front - axle_offset_[i], x, z, c, sn);
      wx[i] = x - sn * (r_ + kWheelLift);
      wz[i] = z + c * (r_ + kWheelLift);
      tc[i] = c;
      ts[i] = sn;
    }
    const double sprung_half = v.body_mass_kg / 2.0;
    const double primary_load = (sprung_half + v.bogie_mass_kg) / 2.0;
    const double k_sec = sprung_half * std::pow(2.0 * kPi * v.secondary_hz, 2.0);
    const double c_sec = 2.0 * v.secondary_damping * std::sqrt(k_sec * sprung_half);
    const double k_pri = primary_load * std::pow(2.0 * kPi * v.primary_hz, 2.0);
    const double c_pri = 2.0 * v.primary_damping * std::sqrt(k_pri * primary_load);

    // Bogies: frame along the chord of its wheel centres.
    std::array<double, 2> qx{}, qz{};
    for (std::size_t b = 0; b < 2; ++b) {
      const std::size_t i0 = 2 * b, i1 = 2 * b + 1;
      const double ang = std::atan2(wz[i0] - wz[i1], wx[i0] - wx[i1]);
      const double ux = -std::sin(ang), uz = std::cos(ang);
      const double mx = (wx[i0] + wx[i1]) / 2.0, mz = (wz[i0] + wz[i1]) / 2.0;
      qx[b] = mx + ux * kPivotAboveWheel;
      qz[b] = mz + uz * kPivotAboveWheel;
      b2BodyDef bd;
      bd.type = b2_dynamicBody;
      bd.position = Local(mx + ux * kBogieCogAboveWheel, mz + uz * kBogieCogAboveWheel);
      bd.angle = static_cast<float>(ang);
      bd.linearVelocity = b2Vec2(static_cast<float>(v0 * std::cos(ang)), static_cast<float>(v0 * std::sin(ang)));
      bogie_[b] = world_.CreateBody(&bd);
      b2MassData md;
      md.mass = static_cast<float>(v.bogie_mass_kg);
      md.center = b2Vec2(0.0f, 0.0f);
      md.I = static_cast<float>(v.bogie_mass_kg * (v.axle_spacing_m * v.axle_spacing_m + 0.25) / 12.0 * 1.5);
      bogie_[b]->SetMassData(&md);
      bogie_angle_[b] = ang;
    }
    // Car body along the chord of the pivots.
    {
      const double ang = std::atan2(qz[0] - qz[1], qx[0] - qx[1]);
      const double ux = -std::sin(ang), uz = std::cos(ang);
      const double above = v.body_cog_height_m - (r_ + kWheelLift + kPivotAboveWheel);
      b2BodyDef bd;
      bd.type = b2_dynamicBody;
      bd.position = Local((qx[0] + qx[1]) / 2.0 + ux * above, (qz[0] + qz[1]) / 2.0 + uz * above);
      bd.angle = static_cast<float>(ang);
      bd.linearVelocity = b2Vec2(static_cast<float>(v0 * std::cos(ang)), static_cast<float>(v0 * std::sin(ang)));
      body_ = world_.CreateBody(&bd);
      b2MassData md;
      md.mass = static_cast<float>(v.body_mass_kg);
      md.center = b2Vec2(0.0f, 0.0f);
      md.I = static_cast<float>(v.body_mass_kg * (v.length_m * v.length_m + 9.0) / 12.0);
      body_->SetMassData(&md);
      // Secondary suspension: pre-loaded so that the design geometry is the equilibrium.
      const double d = sprung_half * kG * std::cos(ang) / k_sec;
      for (std::size_t b = 0; b < 2; ++b) {
        b2WheelJointDef jd;
        jd.bodyA = body_;
        jd.bodyB = bogie_[b];
        const b2Vec2 anchor = Local(qx[b], qz[b]);
        jd.localAnchorA = body_->GetLocalPoint(anchor);
        jd.localAnchorB = bogie_[b]->GetLocalPoint(Local(qx[b] + ux * d, qz[b] + uz * d));
        jd.localAxisA = body_->GetLocalVector(b2Vec2(static_cast<float>(ux), static_cast<float>(uz)));
        jd.stiffness = static_cast<float>(k_sec);
        jd.damping = static_cast<float>(c_sec);
        world_.CreateJoint(&jd);
      }
    }
    // Wheelsets: circles, rotation handled by the spin model (fixed rotation in Box2D).
    for (std::size_t i = 0; i < 4; ++i) {
      b2BodyDef bd;
      bd.type = b2_dynamicBody;
      bd.fixedRotation = true;
      bd.position = Local(wx[i], wz[i]);
      bd.linearVelocity = b2Vec2(static_cast<float>(v0 * tc[i]), static_cast<float>(v0 * ts[i]));
      wheel_[i] = world_.CreateBody(&bd);
      b2CircleShape circle;
      circle.m_radius = static_cast<float>(r_);
      b2FixtureDef fd;
      fd.shape = &circle;
      fd.density = static_cast<float>(v.wheelset_mass_kg / (kPi * r_ * r_));
      fd.friction = 0.0f;
      fd.restitution = 0.0f;
      fd.filter.categoryBits = 0x0002;
      fd.filter.maskBits = 0x0001;
      fd.userData.pointer = i + 1;
      wheel_[i]->CreateFixture(&fd);
      axles_[i].omega = v0 / r_;
      // Primary suspension.
      const std::size_t b = i / 2;
      const double ang = bogie_angle_[b];
      const double ux = -std::sin(ang), uz = std::cos(ang);
      const double d = primary_load * kG * std::cos(ang) / k_pri;
      b2WheelJointDef jd;
      jd.bodyA = bogie_[b];
      jd.bodyB = wheel_[i];
      jd.localAnchorA = bogie_[b]->GetLocalPoint(Local(wx[i], wz[i]));
      jd.localAnchorB = wheel_[i]->GetLocalPoint(Local(wx[i] + ux * d, wz[i] + uz * d));
      jd.localAxisA = bogie_[b]->GetLocalVector(b2Vec2(static_cast<float>(ux), static_cast<float>(uz)));
      jd.stiffness = static_cast<float>(k_pri);
      jd.damping = static_cast<float>(c_pri);
      world_.CreateJoint(&jd);
    }
  }

  // Rail chain pieces covering [lo - reach, hi + reach]; pieces elsewhere are destroyed.
  void UpdatePieces(double lo_s, double hi_s) {
    const long first = static_cast<long>(table_.IndexOfS(lo_s - kPieceReach)) / kPieceIntervals;
    const long last = static_cast<long>(table_.IndexOfS(hi_s + kPieceReach)) / kPieceIntervals;
    for (auto it = pieces_.begin(); it != pieces_.end();) {
      if (it->first < first || it->first > last) {
        world_.DestroyBody(it->second);
        piece_origin_.erase(it->first);
        it = pieces_.erase(it);
      } else {
        ++it;
      }
    }
    for (long p = first; p <= last; ++p) {
      if (pieces_.count(p) == 0) {
        pieces_[p] = CreatePiece(p);
      }
    }
  }

  b2Body* CreatePiece(long p) {
    const std::size_t n = table_.Size();
    const std::size_t lo = static_cast<std::size_t>(p) * kPieceIntervals;
    const std::size_t hi = std::min(lo + kPieceIntervals, n - 1);
    const double px = table_.X(lo), pz = table_.Z(lo);
    b2BodyDef bd;
    bd.type = b2_staticBody;
    bd.position = Local(px, pz);
    b2Body* body = world_.CreateBody(&bd);
    // One-sided chain: the solid side is to the right of the vertex order, so the vertices
    // run against the running direction to have the surface normal pointing up.
    std::vector<b2Vec2> verts;
    for (std::size_t j = hi + 1; j-- > lo;) {
      verts.emplace_back(static_cast<float>(table_.X(j) - px), static_cast<float>(table_.Z(j) - pz));
    }
    // Ghost vertices: the neighbours beyond the piece (the table's margin keeps them inside).
    const std::size_t prev = std::min(hi + 1, n - 1);
    const std::size_t next = lo == 0 ? 0 : lo - 1;
    const b2Vec2 prev_v(static_cast<float>(table_.X(prev) - px), static_cast<float>(table_.Z(prev) - pz));
    const b2Vec2 next_v(static_cast<float>(table_.X(next) - px), static_cast<float>(table_.Z(next) - pz));
    b2ChainShape chain;
    chain.CreateChain(verts.data(), static_cast<int32>(verts.size()), prev_v, next_v);
    b2FixtureDef fd;
    fd.shape = &chain;
    fd.friction = 0.0f;
    fd.filter.categoryBits = 0x0001;
    fd.filter.maskBits = 0x0002;
    body->CreateFixture(&fd);
    piece_origin_[p] = {px, pz};
    return body;
  }

  void Rebase() {
    const b2Vec2 p = body_->GetPosition();
    if (std::fabs(p.x) < kRebaseDistance && std::fabs(p.y) < kRebaseDistance) {
      return;
    }
    const double sx = std::round(static_cast<double>(p.x));
    const double sz = std::round(static_cast<double>(p.y));
    world_.ShiftOrigin(b2Vec2(static_cast<float>(sx), static_cast<float>(sz)));
    ox_ += sx;
    oz_ += sz;
    for (auto& [id, body] : pieces_) {
      const auto& o = piece_origin_[id];
      body->SetTransform(Local(o[0], o[1]), 0.0f);
    }
  }

  // ---- state in line terms ----------------------------------------------------------------------
  // Rail position of wheelset i's contact, its speed along the rail and the tangent.
  void WheelOnRail(std::size_t i, double& s, double& v, double& c, double& sn) const {
    const b2Vec2 p = wheel_[i]->GetPosition();
    const b2Vec2 u = wheel_[i]->GetLinearVelocity();
    const double x = static_cast<double>(p.x) + ox_;
    // first guess from the centre's abscissa, then the contact point below it
    double s1 = table_.SOfX(x);
    double px, pz;
    table_.At(s1, px, pz, c, sn);
    s1 = table_.SOfX(x + sn * (r_ + kWheelLift));
    table_.At(s1, px, pz, c, sn);
    s = s1;
    v = static_cast<double>(u.x) * c + static_cast<double>(u.y) * sn;
  }

  [[nodiscard]] double FrontS() const { return axles_[0].s + overhang_; }
  [[nodiscard]] double MeanSpeed() const {
    double v = 0.0;
    for (const auto& a : axles_) {
      v += a.v;
    }
    return v / 4.0;
  }
  [[nodiscard]] double CentreS() const { return FrontS() - sc_.vehicle.length_m / 2.0; }

  [[nodiscard]] double RailFactor(double s, double t) const {
    double f = sc_.rail.wet ? law_.wet_factor : 1.0;
    for (const auto& z : sc_.rail.zones) {
      if (s >= z.begin_m && s < z.end_m && (!z.from_s || t >= *z.from_s) && (!z.to_s || t < *z.to_s)) {
        f *= z.factor;
      }
    }
    return f;
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

  // ---- one step -----------------------------------------------------------------------------
  // One Box2D step at run time t_run (sensor timing); t the scenario's time (driver, zone
  // windows: before 0 during a lead-in).
  void Step(double t_run, double t, double dt);
  void SpinAxle(std::size_t i, double t, double dt, double motor_torque, double brake_torque, double rail_factor);

  // ---- sensors ------------------------------------------------------------------------------
  ra::ImuSample ImuSample(std::int64_t t_us);
  double Normal() { return normal_(rng_); }

  const WheelRailScenario& sc_;
  AdhesionLaw law_;
  TrackTable table_;
  b2World world_;
  ContactListener listener_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};

  double r_ = 0.43;
  double overhang_ = 0.0;
  std::array<double, 4> axle_offset_{};
  std::array<double, 2> bogie_angle_{};
  double ox_ = 0.0, oz_ = 0.0;
  b2Body* body_ = nullptr;
  std::array<b2Body*, 2> bogie_{};
  std::array<b2Body*, 4> wheel_{};
  std::map<long, b2Body*> pieces_;
  std::map<long, std::array<double, 2>> piece_origin_;
  std::array<AxleState, 4> axles_{};

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

  // TG
  double pulse_angle_ = 0.0;
  double tg_angle_ = 0.0;          // accumulated |rotation| of the TG wheel (rad)
  std::int64_t tg_count_ = 0;      // true count since t = 0 (phase offset excluded)
  enum class TgMode : std::uint8_t { kNormal, kDropout, kStuck };
  TgMode tg_mode_ = TgMode::kNormal;
  std::int64_t tg_offset_ = 0;        // reported = true - offset in normal operation
  std::int64_t tg_frozen_ = 0;
  std::int64_t tg_fault_true_ = 0;    // true count in the last faulty cycle
  std::int64_t tg_reported_ = 0;
  std::int64_t tg_edge_reported_ = 0;
  double tg_edge_s_ = 0.0;
  bool tg_any_edge_ = false;

  // IMU
  std::array<double, 3> accel_bias_{}, rate_bias_{}, accel_drift_{}, rate_drift_{};
  double prev_vx_ = 0.0, prev_vz_ = 0.0, prev_pitch_ = 0.0, prev_roll_ = 0.0, prev_vkappa_ = 0.0, prev_v2kappa_ = 0.0;
};

void Simulator::SpinAxle(std::size_t i, double t, double dt, double motor_torque, double brake_torque,
                         double rail_factor) {
  auto& a = axles_[i];
  const double j = sc_.vehicle.wheelset_inertia_kgm2;
  const double n = a.normal_n;
  const double v = a.v;
  const double denom_v = std::max(std::fabs(v), law_.creep_floor_mps);
  const double mu_peak = CurtiusKnifflerMu(v * 3.6) * rail_factor;
  const double h = dt / kSpinSubsteps;
  const bool tg = static_cast<int>(i) == sc_.tg.axle;
  double w = a.omega;
  double force_sum = 0.0;
  for (int k = 0; k < kSpinSubsteps; ++k) {
    const double creep = (w * r_ - v) / denom_v;
    const double f = mu_peak * CreepCurve(creep, law_) * n;
    // slope of the creep curve at this creep (per unit creep)
    const double ac = std::fabs(creep);
    double slope = 0.0;
    if (ac < law_.peak_creep) {
      slope = 1.0 / law_.peak_creep;
    } else if (ac < law_.tail_creep) {
      slope = -(1.0 - law_.tail_ratio) / (law_.tail_creep - law_.peak_creep);
    }
    const double df_dw = mu_peak * slope * n * r_ / denom_v;
    const double drive = motor_torque - f * r_;
    double w_new = w;
    double f_used = f;
    if (w == 0.0 && std::fabs(drive) <= brake_torque) {
      w_new = 0.0;  // locked: the brake holds the wheelset
    } else {
      const double dir = w != 0.0 ? (w > 0.0 ? 1.0 : -1.0) : (drive > 0.0 ? 1.0 : -1.0);
      const double torque = drive - dir * brake_torque;
      const double stiff = std::max(df_dw, 0.0) * r_;
      w_new = w + h * torque / (j + h * stiff);
      if (brake_torque > 0.0 && w != 0.0 && w_new * w < 0.0) {
        w_new = 0.0;  // the brake stops the wheel, it does not reverse it
      }
      if (df_dw > 0.0) {
        f_used = f + df_dw * (w_new - w);
      }
    }
    force_sum += f_used;
    if (tg) {
      const double before = tg_angle_;
      tg_angle_ += h * 0.5 * (std::fabs(w) + std::fabs(w_new));
      const auto c0 = static_cast<std::int64_t>(std::floor(before / pulse_angle_));
      const auto c1 = static_cast<std::int64_t>(std::floor(tg_angle_ / pulse_angle_));
      if (c1 > c0) {
        const double edge_angle = static_cast<double>(c1) * pulse_angle_;
        const double frac = (edge_angle - before) / (tg_angle_ - before);
        tg_edge_s_ = t + h * (static_cast<double>(k) + frac);
        tg_count_ += c1 - c0;
        tg_any_edge_ = true;
      }
    }
    w = w_new;
  }
  a.omega = w;
  a.force_n = force_sum / kSpinSubsteps;
  a.creep = (w * r_ - v) / denom_v;
}

void Simulator::Step(double t_run, double t, double dt) {
  const auto& veh = sc_.vehicle;
  std::array<double, 4> tc{}, ts{};
  for (std::size_t i = 0; i < 4; ++i) {
    WheelOnRail(i, axles_[i].s, axles_[i].v, tc[i], ts[i]);
    axles_[i].normal_n = listener_.normal_impulse[i] / dt;
    axles_[i].friction_n = listener_.tangent_impulse[i] / dt;
  }
  const double v_mean = MeanSpeed();
  Driver(t, dt, v_mean);
  listener_.Clear();

  // Torque that motor and brake apply to each bogie's wheelsets (forward positive).
  std::array<double, 2> applied{};
  for (std::size_t i = 0; i < 4; ++i) {
    auto& a = axles_[i];
    const double v = a.v;
    const double rail = RailFactor(a.s, t);
    double motor = 0.0;
    if (veh.motored[i] && traction_ > 0.0 && v * 3.6 < veh.max_speed_kmh) {
      // power limit on the motor (wheel) speed, so a spinning wheel loses torque
      motor = traction_ * std::min(veh.max_traction_force_n, veh.max_power_w / std::max(std::fabs(a.omega) * r_, 1.0)) * r_;
    }
    double brake = brake_ * veh.max_brake_force_n * r_;
    if (sc_.slip_control.enabled) {
      const auto& sp = sc_.slip_control;
      const bool slipping =
          (a.creep > sp.creep_threshold && motor > 0.0) || (a.creep < -sp.creep_threshold && brake > 0.0);
      if (slipping) {
        a.control = std::max(sp.min_factor, a.control - sp.reduce_per_s * dt);
      } else if (std::fabs(a.creep) < sp.creep_threshold / 2.0) {
        a.control = std::min(1.0, a.control + sp.recover_per_s * dt);
      }
      motor *= a.control;
      brake *= a.control;
    }
    // Static hold of a locked, braked wheelset at standstill (Box2D contact friction).
    if (a.hold) {
      const double drive = motor - a.friction_n * r_;
      if (std::fabs(drive) > brake || std::fabs(v) > kHoldExitSpeed) {
        a.hold = false;
      }
    } else if (a.omega == 0.0 && std::fabs(v) < kHoldEnterSpeed && brake > std::fabs(motor)) {
      a.hold = true;
    }
    if (a.hold) {
      listener_.friction[i] = static_cast<float>(CurtiusKnifflerMu(0.0) * rail);
      a.force_n = a.friction_n;
      a.creep = CreepOf(0.0, v, law_);
      applied[i / 2] += a.friction_n * r_;  // the wheelset is at rest: motor + brake balance the friction
      continue;
    }
    listener_.friction[i] = 0.0f;
    const double omega_before = a.omega;
    SpinAxle(i, t_run, dt, motor, brake, rail);
    applied[i / 2] += veh.wheelset_inertia_kgm2 * (a.omega - omega_before) / dt + a.force_n * r_;
    wheel_[i]->ApplyForceToCenter(b2Vec2(static_cast<float>(a.force_n * tc[i]), static_cast<float>(a.force_n * ts[i])),
                                  true);
  }
  // A forward torque turns a wheel clockwise (Box2D negative): the bogie takes the opposite.
  for (std::size_t b = 0; b < 2; ++b) {
    bogie_[b]->ApplyTorque(static_cast<float>(applied[b]), true);
  }
  // Running resistance on the car body.
  {
    double c, sn, x, z;
    table_.At(CentreS(), x, z, c, sn);
    const double res = veh.resistance_a_n * std::tanh(v_mean / 0.1) + veh.resistance_b_ns_m * v_mean +
                       veh.resistance_c_ns2_m2 * v_mean * std::fabs(v_mean);
    body_->ApplyForceToCenter(b2Vec2(static_cast<float>(-res * c), static_cast<float>(-res * sn)), true);
  }
  world_.Step(static_cast<float>(dt), kVelocityIterations, kPositionIterations);
  Rebase();
}

ra::ImuSample Simulator::ImuSample(std::int64_t t_us) {
  const b2Vec2 vel = body_->GetLinearVelocity();
  const double vx = static_cast<double>(vel.x), vz = static_cast<double>(vel.y);
  const double pitch = static_cast<double>(body_->GetAngle());
  double v = 0.0;
  for (const auto& a : axles_) {
    v += a.v;
  }
  v /= 4.0;
  const double s = CentreS();
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
  for (std::size_t i = 0; i < 4; ++i) {
    double c, sn;
    WheelOnRail(i, axles_[i].s, axles_[i].v, c, sn);
  }
  const double front0 = FrontS();
  {
    const b2Vec2 vel = body_->GetLinearVelocity();
    prev_vx_ = static_cast<double>(vel.x);
    prev_vz_ = static_cast<double>(vel.y);
    prev_pitch_ = static_cast<double>(body_->GetAngle());
    const double v = MeanSpeed();
    prev_roll_ = BodyRoll(CentreS(), v);
    prev_vkappa_ = v * CurvatureAt(sc_.curves, CentreS());
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
  double prev_speed = MeanSpeed();
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
    Step(static_cast<double>(t_us) * 1e-6,
         leading_ ? static_cast<double>(kBeforeScenarioUs) * 1e-6 : static_cast<double>(t_us - t0_us) * 1e-6, dt);
    ++run.steps;
    const std::int64_t now_us = t_us + step_us;
    const std::int64_t scenario_us = leading_ ? kBeforeScenarioUs : now_us - t0_us;
    // truth per step: creep and events
    for (std::size_t i = 0; i < 4; ++i) {
      const double c = axles_[i].creep;
      if (std::fabs(c) > std::fabs(creep_peak[i])) {
        creep_peak[i] = c;
      }
      auto& e = ev[i];
      if (std::fabs(c) > ev_thr) {
        if (!e.active) {
          e.active = true;
          e.start_us = now_us;
          e.peak = c;
          e.start_front = FrontS();
        } else if (std::fabs(c) > std::fabs(e.peak)) {
          e.peak = c;
        }
      } else if (e.active) {
        close_event(i, now_us, FrontS());
      }
    }
    if ((step + 1) % steps_per_imu != 0) {
      continue;
    }
    // 10 ms: one IMU sample
    for (std::size_t i = 0; i < 4; ++i) {
      double c, sn;
      WheelOnRail(i, axles_[i].s, axles_[i].v, c, sn);
    }
    cycle.imu[static_cast<std::size_t>(imu_index)] = ImuSample(now_us);
    ++imu_index;
    if (imu_index < ra::kImuSamplesPerCycle) {
      continue;
    }
    imu_index = 0;
    // 100 ms: the cycle
    const double t_s = static_cast<double>(now_us) * 1e-6;
    const double front = FrontS();
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
    const std::int64_t true_count = tg_count_;
    const std::int64_t true_edge_us =
        tg_any_edge_ ? std::min(static_cast<std::int64_t>(std::floor(tg_edge_s_ * 1e6)), now_us) : 0;
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
    const double speed = MeanSpeed();
    truth.time_ms = now_us / 1000;
    truth.front_m = front;
    truth.distance_m = front - front0;
    truth.speed_mps = speed;
    truth.accel_mps2 = (speed - prev_speed) / (static_cast<double>(kCycleUs) * 1e-6);
    truth.tg_distance_m = static_cast<double>(true_count) * run.pulse_length_m;
    truth.tg_wheel_speed_mps = axles_[static_cast<std::size_t>(sc_.tg.axle)].omega * r_;
    for (std::size_t i = 0; i < 4; ++i) {
      truth.creep[i] = axles_[i].creep;
      truth.creep_peak[i] = creep_peak[i];
      truth.normal_force_n[i] = axles_[i].normal_n;
      truth.creep_force_n[i] = axles_[i].force_n;
    }
    creep_peak.fill(0.0);
    truth.gradient_permille = GradientPermilleAt(sc_.vertical, CentreS());
    truth.pitch_rad = static_cast<double>(body_->GetAngle());
    truth.roll_rad = BodyRoll(CentreS(), speed);
    truth.curvature_1pm = CurvatureAt(sc_.curves, CentreS());
    truth.traction = traction_;
    truth.brake = brake_;
    truth.faults = mask;
    run.cycles.push_back(cycle);
    run.truth.push_back(truth);
    prev_front = front;
    prev_speed = speed;
    // rail pieces around the car
    UpdatePieces(front - sc_.vehicle.length_m, front);
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
  const double front_end = FrontS();
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
