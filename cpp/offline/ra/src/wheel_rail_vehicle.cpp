// Wheel-rail simulator: the Box2D vehicle and the creep-force and wheelset-spin model, one
// step at a time (see wheel_rail.hpp for the model summary).
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
#include <utility>
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

}  // namespace

struct WheelRailVehicle::Impl {
  explicit Impl(const WheelRailVehicleConfig& config)
      : cfg_(config), law_(config.adhesion), table_(config.vertical), world_(b2Vec2(0.0f, static_cast<float>(-kG))) {
    const auto& v = cfg_.vehicle;
    r_ = v.wheel_diameter_m / 2.0;
    overhang_ = (v.length_m - v.bogie_centres_m - v.axle_spacing_m) / 2.0;
    axle_offset_ = {overhang_, overhang_ + v.axle_spacing_m, overhang_ + v.bogie_centres_m,
                    overhang_ + v.bogie_centres_m + v.axle_spacing_m};
    pulse_angle_ = 2.0 * kPi / cfg_.tg_teeth;
    tg_angle_ = cfg_.tg_phase * pulse_angle_;
    world_.SetAllowSleeping(false);
    world_.SetContinuousPhysics(false);
    world_.SetContactListener(&listener_);
    BuildVehicle();
  }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  Impl(Impl&&) = delete;
  Impl& operator=(Impl&&) = delete;
  ~Impl() = default;

  b2Vec2 Local(double x, double z) const {
    return b2Vec2(static_cast<float>(x - ox_), static_cast<float>(z - oz_));
  }

  void RailPoint(double s, double& x, double& z, double& c, double& sn) const { table_.At(s, x, z, c, sn); }

  void BuildVehicle() {
    const auto& v = cfg_.vehicle;
    const double front = cfg_.front_m;
    const double v0 = cfg_.speed_mps;
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
  [[nodiscard]] double CentreS() const { return FrontS() - cfg_.vehicle.length_m / 2.0; }

  [[nodiscard]] double RailFactor(double s, double t) const {
    double f = cfg_.rail.wet ? law_.wet_factor : 1.0;
    for (const auto& z : cfg_.rail.zones) {
      if (s >= z.begin_m && s < z.end_m && (!z.from_s || t >= *z.from_s) && (!z.to_s || t < *z.to_s)) {
        f *= z.factor;
      }
    }
    return f;
  }


  void Step(double t_run, double t, double dt, const Demand& demand);
  void SpinAxle(std::size_t i, double t, double dt, double motor_torque, double brake_torque, double rail_factor);

  WheelRailVehicleConfig cfg_;
  AdhesionLaw law_;
  TrackTable table_;
  b2World world_;
  ContactListener listener_;

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
  std::array<WheelsetState, 4> axles_{};
  WheelRailDemand last_;

  // TG axle
  double pulse_angle_ = 0.0;
  double tg_angle_ = 0.0;          // accumulated |rotation| of the TG wheel (rad)
  std::int64_t tg_count_ = 0;      // true count since the start (phase offset excluded)
  double tg_edge_s_ = 0.0;
  bool tg_any_edge_ = false;
};

void WheelRailVehicle::Impl::SpinAxle(std::size_t i, double t, double dt, double motor_torque, double brake_torque,
                         double rail_factor) {
  auto& a = axles_[i];
  const double j = cfg_.vehicle.wheelset_inertia_kgm2;
  const double n = a.normal_n;
  const double v = a.v;
  const double denom_v = std::max(std::fabs(v), law_.creep_floor_mps);
  const double mu_peak = CurtiusKnifflerMu(v * 3.6) * rail_factor;
  const double h = dt / kSpinSubsteps;
  const bool tg = static_cast<int>(i) == cfg_.tg_axle;
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

void WheelRailVehicle::Impl::Step(double t_run, double t, double dt, const Demand& demand) {
  const auto& veh = cfg_.vehicle;
  std::array<double, 4> tc{}, ts{};
  for (std::size_t i = 0; i < 4; ++i) {
    WheelOnRail(i, axles_[i].s, axles_[i].v, tc[i], ts[i]);
    axles_[i].normal_n = listener_.normal_impulse[i] / dt;
    axles_[i].friction_n = listener_.tangent_impulse[i] / dt;
  }
  const double v_mean = MeanSpeed();
  last_ = demand(v_mean);
  const double traction = last_.traction;
  const double brake_level = last_.brake;
  listener_.Clear();

  // Torque that motor and brake apply to each bogie's wheelsets (forward positive).
  std::array<double, 2> applied{};
  for (std::size_t i = 0; i < 4; ++i) {
    auto& a = axles_[i];
    const double v = a.v;
    const double rail = RailFactor(a.s, t);
    double motor = 0.0;
    if (veh.motored[i] && traction > 0.0 && v * 3.6 < veh.max_speed_kmh) {
      // power limit on the motor (wheel) speed, so a spinning wheel loses torque
      motor = traction * std::min(veh.max_traction_force_n, veh.max_power_w / std::max(std::fabs(a.omega) * r_, 1.0)) * r_;
    }
    double brake = brake_level * veh.max_brake_force_n * r_;
    if (cfg_.slip_control.enabled) {
      const auto& sp = cfg_.slip_control;
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

WheelRailVehicle::WheelRailVehicle(const WheelRailVehicleConfig& config) : impl_(std::make_unique<Impl>(config)) {}
WheelRailVehicle::~WheelRailVehicle() = default;
WheelRailVehicle::WheelRailVehicle(WheelRailVehicle&&) noexcept = default;
WheelRailVehicle& WheelRailVehicle::operator=(WheelRailVehicle&&) noexcept = default;

void WheelRailVehicle::Step(double t_run_s, double t_s, double dt_s, const Demand& demand) {
  impl_->Step(t_run_s, t_s, dt_s, demand);
}

void WheelRailVehicle::UpdateWheelsets() {
  for (std::size_t i = 0; i < 4; ++i) {
    double c, sn;
    impl_->WheelOnRail(i, impl_->axles_[i].s, impl_->axles_[i].v, c, sn);
  }
}

void WheelRailVehicle::KeepRailAround() {
  const double front = impl_->FrontS();
  impl_->UpdatePieces(front - impl_->cfg_.vehicle.length_m, front);
}

double WheelRailVehicle::FrontM() const { return impl_->FrontS(); }
double WheelRailVehicle::CentreM() const { return impl_->CentreS(); }
double WheelRailVehicle::SpeedMps() const { return impl_->MeanSpeed(); }
const WheelsetState& WheelRailVehicle::Wheelset(int axle) const { return impl_->axles_.at(static_cast<std::size_t>(axle)); }
double WheelRailVehicle::WheelRadiusM() const { return impl_->r_; }
double WheelRailVehicle::BodyVx() const { return static_cast<double>(impl_->body_->GetLinearVelocity().x); }
double WheelRailVehicle::BodyVz() const { return static_cast<double>(impl_->body_->GetLinearVelocity().y); }
double WheelRailVehicle::BodyPitchRad() const { return static_cast<double>(impl_->body_->GetAngle()); }
std::int64_t WheelRailVehicle::TgCount() const { return impl_->tg_count_; }
std::optional<double> WheelRailVehicle::TgEdgeS() const {
  return impl_->tg_any_edge_ ? std::optional<double>(impl_->tg_edge_s_) : std::nullopt;
}
const WheelRailDemand& WheelRailVehicle::LastDemand() const { return impl_->last_; }

WheelRailVehicleConfig VehicleConfigOf(const WheelRailScenario& sc, double front_m, double speed_mps, double tg_phase) {
  WheelRailVehicleConfig c;
  c.vehicle = sc.vehicle;
  c.vertical = sc.vertical;
  c.rail = sc.rail;
  c.adhesion = sc.adhesion;
  c.slip_control = sc.slip_control;
  c.tg_axle = sc.tg.axle;
  c.tg_teeth = sc.tg.teeth;
  c.tg_phase = tg_phase;
  c.front_m = front_m;
  c.speed_mps = speed_mps;
  return c;
}

}  // namespace railproof::ra::analysis
