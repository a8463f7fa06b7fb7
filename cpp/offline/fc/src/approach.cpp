// Stepping under the ceilings, the approach point and the optimal outside-station stop
// (follower.hpp; spec/design/fc.md §4).
#include <algorithm>
#include <cmath>
#include <limits>

#include "railproof/fc/follower.hpp"
#include "railproof/offline/nlp.hpp"

namespace railproof::fc {

State StepTrain(const Corridor& c, const State& s, double u, double dt) {
  offline::Control control;
  if (u >= 0.0) {
    control.traction_mps2 = u;
  } else {
    control.brake_mps2 = -u;
  }
  const double a = offline::NetAcceleration(c.train().perf, control, s.v, c.Gradient(s.x));
  const offline::Motion m = offline::Advance({s.x, s.v}, a, dt);
  return {s.t + dt, m.position, m.speed};
}

double ChooseDemand(const Corridor& c, const State& s, double u_wanted, double dt, const Ceiling& ok) {
  auto fits = [&](double u) {
    const State n = StepTrain(c, s, u, dt);
    return ok(n.x, n.v);
  };
  if (fits(u_wanted)) {
    return u_wanted;
  }
  double lo = -c.train().beta;
  if (!fits(lo)) {
    return lo;
  }
  double hi = u_wanted;
  for (int i = 0; i < 24; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(mid) ? lo : hi) = mid;
  }
  return lo;
}

namespace {

// The run of full traction from (x0, v0) over [x0, x1] on n nodes of position, within the
// static ceiling and, with `stop`, the braking curve to it: d(v^2)/dx = 2 a(v, x) (midpoint
// rule). Returns the time and fills the speed at x1.
double EnvelopeTime(const Corridor& c, double x0, double v0, double x1, int n, bool stop, double* v_end) {
  const offline::TrainPerformance& perf = c.train().perf;
  auto accel = [&](double x, double w) {
    const double v = std::sqrt(std::max(w, 0.0));
    return offline::MaxTraction(perf, v) - offline::ResistanceDecel(perf.resistance, v) -
           offline::GradeDecel(c.Gradient(x));
  };
  auto cap = [&](double x, double w) {
    const double ceiling = c.StaticCeiling(x);
    double m = std::min(w, ceiling * ceiling);
    if (stop) {
      const double b = c.CurveTo(x, x1);
      m = std::min(m, b * b);
    }
    return std::max(m, 0.0);
  };
  const double dx = (x1 - x0) / n;
  double w = cap(x0, v0 * v0);
  double t = 0.0;
  for (int i = 0; i < n; ++i) {
    const double xa = x0 + dx * i;
    const double xb = xa + dx;
    const double w_mid = w + accel(xa, w) * dx;
    const double w_next = cap(xb, w + 2.0 * accel(xa + 0.5 * dx, w_mid) * dx);
    const double vs = std::sqrt(w) + std::sqrt(w_next);
    if (vs <= 0.0) {
      return std::numeric_limits<double>::infinity();
    }
    t += offline::TimeOver(dx, std::sqrt(w), std::sqrt(w_next));
    w = w_next;
  }
  if (v_end != nullptr) {
    *v_end = std::sqrt(w);
  }
  return t;
}

}  // namespace

double ApproachPosition(const ApproachProblem& p, double v) {
  const Corridor& c = *p.corridor;
  // the buffered front y where braking at β from v ends at the entry: E(y) = E(entry) - v^2/2
  const double e = c.BrakeIntegral(p.entry) - 0.5 * v * v;
  double lo = c.from() - 2000.0;
  double hi = p.entry;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (c.BrakeIntegral(mid) < e ? lo : hi) = mid;
  }
  return LimitStartFront(c.train().buffers, lo, v, c.balises());
}

double TimeFromApproach(const ApproachProblem& p, double v) {
  return EnvelopeTime(*p.corridor, ApproachPosition(p, v), v, p.stop, 4000, true, nullptr);
}

ApproachPoint FindApproachPoint(const ApproachProblem& p, double grid_step_mps) {
  const Corridor& c = *p.corridor;
  constexpr double kLowest = 1.0;
  // the highest approach speed the static ceiling admits at its own approach position
  double v_hi = kLowest;
  while (v_hi + grid_step_mps <= c.train().perf.max_speed_mps &&
         v_hi + grid_step_mps <= c.StaticCeiling(ApproachPosition(p, v_hi + grid_step_mps))) {
    v_hi += grid_step_mps;
  }
  ApproachPoint a;
  a.grid_time_s = std::numeric_limits<double>::infinity();
  for (double v = kLowest; v <= v_hi + 1e-9; v += grid_step_mps) {
    const double t = TimeFromApproach(p, v);
    if (t < a.grid_time_s) {
      a.grid_time_s = t;
      a.grid_v = v;
    }
  }
  offline::BoxNlp nlp;
  nlp.objective = [&](const std::vector<double>& x) { return TimeFromApproach(p, x[0]); };
  nlp.lower = {kLowest};
  nlp.upper = {v_hi};
  nlp.start = {0.5 * (kLowest + v_hi)};
  nlp.difference_step = 1e-4;
  nlp.tolerance = 1e-7;
  const offline::BoxNlpResult r = offline::SolveBoxNlp(nlp);
  a.v = r.x[0];
  a.time_s = r.objective;
  a.x = ApproachPosition(p, a.v);
  a.status = r.status;
  a.solved = r.solved;
  a.iterations = r.iterations;
  return a;
}

OutsideStop FindOutsideStop(const Corridor& c, const ApproachPoint& a) {
  // the speed full traction from rest at x0 reaches at the approach point falls as x0 nears it
  auto reached = [&](double x0) {
    double v = 0.0;
    EnvelopeTime(c, x0, 0.0, a.x, 2000, false, &v);
    return v;
  };
  double lo = std::max(c.from(), a.x - 3000.0);  // reaches at least v there
  double hi = a.x;
  for (int i = 0; i < 50; ++i) {
    const double mid = 0.5 * (lo + hi);
    (reached(mid) >= a.v ? lo : hi) = mid;
  }
  OutsideStop o;
  o.x = lo;
  // from rest the first node's speed is 0: the time of the first interval is the exact one of
  // constant acceleration, which TimeOver gives
  o.time_to_approach_s = EnvelopeTime(c, lo, 0.0, a.x, 2000, false, nullptr);
  return o;
}

}  // namespace railproof::fc
