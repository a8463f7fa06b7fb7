// Ipopt NLP of the worst-case stopping point (margins.hpp; spec/design/br.md §5).
//
// Continuous model of one location (SI units: m, s, m/s; positions relative to L):
//   variables  x_m (measured front), e (position error), v_m (measured speed), e_v (speed
//              error, fraction of the linear envelope c0 + c1 v of dV), beta, t_f, dg
//              (gradient error, fraction), phi (cycle part of the run-up), x1 (brake
//              start), x2 (stop), run-up nodes w_i = v^2 and t_i, braking nodes wb_j = v^2.
//   run-up     position is the independent variable: nodes X_i = x0 + (i/N)(x1 - x0),
//              x0 = x_m + e; d(v^2)/dx = 2 a(x), a = accel_max - g (G(x) + dg), imposed in
//              integral form w_{i+1} - w_i = 2 int_{X_i}^{X_{i+1}} a (exact for the smoothed
//              gradient, whatever the mesh); dt/dx = 1 / v by the trapezoidal rule;
//              t_0 = 0, t_N = phi + reaction + t_f.
//   braking    nodes Y_j = x1 + (j/M)(x2 - x1): wb_{j+1} - wb_j = -2 int (beta + g (G + dg)),
//              wb_0 = w_N, wb_M = 0 (x2 is the stop).
//   admissible the continuous emergency pattern (design note §3 without integer rounding,
//              which only lowers the runtime pattern): with v_s = k v_m + abs,
//              y = x_m + E + v_s T + a_p T^2 / 2:  W(y) - (v_s + a_p T)^2 >= 0,
//              W(y) = 2 (B(0) - B(y)), B' = beta_e + g (G - gradient_error);
//              ceiling  C(x_m + E) - (v_s + a_p T) >= 0; true speed <= train maximum.
//              a_p is the smallest runtime run-up acceleration over the approach and the
//              restriction targets ahead are dropped: both only ENLARGE the admissible set
//              (a relaxation), so the NLP's worst case is never less conservative than the
//              runtime's.
//   smoothing  G(x) (most falling gradient under the train) is piecewise constant; steps are
//              replaced by logistic steps of width eps, int G by softplus terms (the
//              antiderivative differs from the exact one by at most |step| eps ln 2 near a step).
//              The ceiling's steps are shifted by 4 eps to the side where the smoothed
//              ceiling stays above the exact one (relaxation again).
//   objective  minimise -(x2) = -(x_stop - L) in metres (scaled: 1 unit = 1 m).
// Exact first and second derivatives below (checked by Ipopt's derivative checker in
// test_margins.cpp). The reported margin re-evaluates the NLP's worst state with the exact
// piecewise physics (MarginModel::Simulate).
#include <coin/IpIpoptApplication.hpp>
#include <coin/IpSolveStatistics.hpp>
#include <coin/IpTNLP.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

#include "railproof/offline/nlp.hpp"
#include "railproof/br/analysis/margins.hpp"

namespace railproof::br::analysis {

namespace {

using Ipopt::Index;
using Ipopt::Number;

double Sigmoid(double u) {
  if (u >= 0.0) {
    return 1.0 / (1.0 + std::exp(-u));
  }
  const double e = std::exp(u);
  return e / (1.0 + e);
}
double Softplus(double u) { return std::max(u, 0.0) + std::log1p(std::exp(-std::abs(u))); }

// `iterations` bisection steps on [lo, hi] towards the boundary of `below` (true at lo, false
// at hi); the final bracket.
template <typename Below>
std::pair<double, double> Bisect(double lo, double hi, int iterations, const Below& below) {
  for (int i = 0; i < iterations; ++i) {
    const double mid = 0.5 * (lo + hi);
    (below(mid) ? lo : hi) = mid;
  }
  return {lo, hi};
}

// A piecewise-constant function with logistic steps of width eps: level + sum over k of
// change[k] * Sigmoid((x - at[k]) / eps).
struct SmoothSteps {
  double level = 0.0;
  std::vector<double> at, change;

  // The function (order 0) or its first or second derivative (order 1, 2) at x.
  [[nodiscard]] double Value(double x, double eps, int order) const {
    double s = order == 0 ? level : 0.0;
    for (std::size_t k = 0; k < at.size(); ++k) {
      const double q = Sigmoid((x - at[k]) / eps);
      if (order == 0) {
        s += change[k] * q;
      } else if (order == 1) {
        s += change[k] * q * (1.0 - q) / eps;
      } else {
        s += change[k] * q * (1.0 - q) * (1.0 - 2.0 * q) / (eps * eps);
      }
    }
    return s;
  }
};

// Continuous model of one location.
struct ContModel {
  double eps = 0.2;
  double xref = 0.0;
  SmoothSteps gradient;  // gradient steps (position m, change as a fraction)
  SmoothSteps ceiling;   // ceiling steps (position m, change m/s), already shifted
  double grav = 9.807, am = 0.0, ap = 0.0, tp = 0.0, beta_e = 0.0, ge = 0.0;
  double kk = 1.0, abs0 = 0.0, sc0 = 0.0, sc1 = 0.0, vtrain = 0.0, e_max = 0.0, d = 0.0;
  double react = 0.0, cycle = 0.0, beta_lo = 0.0, beta_hi = 0.0, tf_lo = 0.0, tf_hi = 0.0;
  double v_floor = 0.01;

  [[nodiscard]] double G(double x) const { return gradient.Value(x, eps, 0); }
  [[nodiscard]] double DG(double x) const { return gradient.Value(x, eps, 1); }
  [[nodiscard]] double IG(double x) const {
    double s = gradient.level * (x - xref);
    for (std::size_t k = 0; k < gradient.at.size(); ++k) {
      s += gradient.change[k] * eps * Softplus((x - gradient.at[k]) / eps);
    }
    return s;
  }
  [[nodiscard]] double C(double y) const { return ceiling.Value(y, eps, 0); }
  [[nodiscard]] double DC(double y) const { return ceiling.Value(y, eps, 1); }
  [[nodiscard]] double DDC(double y) const { return ceiling.Value(y, eps, 2); }
  // W(y) of the continuous emergency pattern and its derivatives.
  [[nodiscard]] double W(double y) const {
    return -2.0 * (beta_e - grav * ge) * y + 2.0 * grav * (IG(0.0) - IG(y));
  }
  [[nodiscard]] double DW(double y) const { return -2.0 * (beta_e - grav * ge) - 2.0 * grav * G(y); }
  [[nodiscard]] double DDW(double y) const { return -2.0 * grav * DG(y); }
  // Pattern check value at measured front x_m and speed v_m.
  [[nodiscard]] double Pattern(double xm, double vm) const {
    const double vs = kk * vm + abs0;
    const double y = xm + e_max + vs * tp + 0.5 * ap * tp * tp;
    const double u = vs + ap * tp;
    return W(y) - u * u;
  }
  [[nodiscard]] double Ceiling(double xm, double vm) const { return C(xm + e_max) - (kk * vm + abs0 + ap * tp); }
  // Largest v_m admissible at x_m (bisection; -1 if none >= v_floor).
  [[nodiscard]] double MaxVm(double xm) const {
    auto ok = [&](double v) {
      const double vt = (v + sc0) / (1.0 - sc1);
      return Pattern(xm, v) >= 0.0 && Ceiling(xm, v) >= 0.0 && vt <= vtrain;
    };
    if (!ok(v_floor)) {
      return -1.0;
    }
    if (ok(vtrain)) {
      return vtrain;
    }
    return Bisect(v_floor, vtrain, 60, ok).first;
  }
};

// Parameters of one evaluation of the continuous model.
struct ContParams {
  double xm, e, vm, ev, beta, tf, dg, ph;
};

double TrueSpeed(const ContModel& c, double vm, double ev) { return (vm + ev * c.sc0) / (1.0 - ev * c.sc1); }

// Run-up collocation nodes in [0, 1]: quadratic, so the intervals are short at the start
// where the speed (and the trapezoidal rule's error in 1/v) is smallest / largest.
double RunUpNode(int i, int n) {
  const double r = static_cast<double>(i) / n;
  return r * r;
}

// The NLP's discretised model evaluated for fixed parameters: returns x2 (stop, m rel L) and
// fills the node values. x1 solves t_N(x1) = T_r by bisection.
struct ContTraj {
  double x0 = 0.0, x1 = 0.0, x2 = 0.0;
  std::vector<double> w, t, wb;
  bool ok = false;
};

ContTraj ContEvaluate(const ContModel& c, const ContParams& p, int n, int mb) {
  ContTraj tr;
  tr.x0 = p.xm + p.e;
  const double v0 = TrueSpeed(c, p.vm, p.ev);
  const double w0 = v0 * v0;
  const double tr_total = p.ph + c.react + p.tf;
  const double ig0 = c.IG(tr.x0);
  auto wat = [&](double x) {
    return w0 + 2.0 * (c.am * (x - tr.x0) - c.grav * (c.IG(x) - ig0) - c.grav * p.dg * (x - tr.x0));
  };
  auto time_to = [&](double x1, std::vector<double>* w, std::vector<double>* t) -> double {
    double tt = 0.0;
    double prev_w = w0;
    if (w) {
      w->assign(static_cast<std::size_t>(n + 1), 0.0);
      t->assign(static_cast<std::size_t>(n + 1), 0.0);
      (*w)[0] = w0;
    }
    for (int i = 1; i <= n; ++i) {
      const double xi = tr.x0 + (x1 - tr.x0) * RunUpNode(i, n);
      const double wi = wat(xi);
      if (wi <= 0.0) {
        return std::numeric_limits<double>::infinity();
      }
      tt += (x1 - tr.x0) * (RunUpNode(i, n) - RunUpNode(i - 1, n)) * 0.5 * (1.0 / std::sqrt(prev_w) + 1.0 / std::sqrt(wi));
      prev_w = wi;
      if (w) {
        (*w)[static_cast<std::size_t>(i)] = wi;
        (*t)[static_cast<std::size_t>(i)] = tt;
      }
    }
    return tt;
  };
  double lo = tr.x0;
  double hi = tr.x0 + (v0 + c.am * 2.0 * tr_total + 1.0) * tr_total + 1.0;
  if (!(time_to(hi, nullptr, nullptr) >= tr_total)) {
    // cannot happen with positive run-up speeds; widen once
    hi = tr.x0 + 4.0 * (hi - tr.x0);
  }
  const auto [x_lo, x_hi] = Bisect(lo, hi, 80, [&](double x) { return time_to(x, nullptr, nullptr) < tr_total; });
  tr.x1 = 0.5 * (x_lo + x_hi);
  time_to(tr.x1, &tr.w, &tr.t);
  const double wn = tr.w.back();
  const double ig1 = c.IG(tr.x1);
  auto wbat = [&](double x) {
    return wn - 2.0 * (p.beta * (x - tr.x1) + c.grav * (c.IG(x) - ig1) + c.grav * p.dg * (x - tr.x1));
  };
  double blo = tr.x1;
  double bhi = tr.x1 + wn / (2.0 * std::max(0.05, p.beta - c.grav * 0.1)) + 1.0;
  for (int i = 0; i < 80; ++i) {
    const double mid = 0.5 * (blo + bhi);
    (wbat(mid) > 0.0 ? blo : bhi) = mid;
  }
  tr.x2 = 0.5 * (blo + bhi);
  tr.wb.assign(static_cast<std::size_t>(mb + 1), 0.0);
  for (int j = 0; j <= mb; ++j) {
    tr.wb[static_cast<std::size_t>(j)] = std::max(0.0, wbat(tr.x1 + (tr.x2 - tr.x1) * j / mb));
  }
  tr.wb[static_cast<std::size_t>(mb)] = 0.0;
  tr.ok = true;
  return tr;
}

// ---- the TNLP ------------------------------------------------------------------------
class MarginTnlp : public Ipopt::TNLP {
 public:
  enum : int { kXm = 0, kE, kVm, kEv, kBeta, kTf, kDg, kPh, kX1, kX2, kFirstNode };

  MarginTnlp(const ContModel& c, int n, int mb, std::vector<double> start) : c_(c), n_(n), m_(mb), start_(std::move(start)) {}

  [[nodiscard]] double S(int i) const { return RunUpNode(i, n_); }
  [[nodiscard]] int W(int i) const { return kFirstNode + i; }
  [[nodiscard]] int T(int i) const { return kFirstNode + n_ + 1 + i; }
  [[nodiscard]] int WB(int j) const { return j == 0 ? W(n_) : kFirstNode + 2 * (n_ + 1) + j - 1; }
  [[nodiscard]] int NumVars() const { return kFirstNode + 2 * (n_ + 1) + m_; }
  [[nodiscard]] int NumCons() const { return 2 * n_ + 7 + m_; }

  const std::vector<double>& solution() const { return sol_; }
  double objective() const { return obj_; }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag, IndexStyleEnum& index_style) override {
    n = NumVars();
    m = NumCons();
    BuildStructure();
    nnz_jac_g = static_cast<Index>(jr_.size());
    nnz_h_lag = static_cast<Index>(hr_.size());
    index_style = C_STYLE;
    return true;
  }

  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index m, Number* g_l, Number* g_u) override {
    const double inf = 1e19;
    for (Index i = 0; i < n; ++i) {
      x_l[i] = -inf;
      x_u[i] = inf;
    }
    x_l[kXm] = -c_.d - c_.e_max;
    x_u[kXm] = -c_.e_max;
    x_l[kE] = -c_.e_max;
    x_u[kE] = c_.e_max;
    x_l[kVm] = c_.v_floor;
    x_u[kVm] = c_.vtrain;
    x_l[kEv] = -1.0;
    x_u[kEv] = 1.0;
    x_l[kBeta] = c_.beta_lo;
    x_u[kBeta] = c_.beta_hi;
    x_l[kTf] = c_.tf_lo;
    x_u[kTf] = c_.tf_hi;
    x_l[kDg] = -c_.ge;
    x_u[kDg] = c_.ge;
    x_l[kPh] = 0.0;
    x_u[kPh] = c_.cycle;
    x_l[kX1] = -c_.d - 2.0 * c_.e_max - 10.0;
    x_u[kX1] = c_.d + 10.0;
    x_l[kX2] = -c_.d - 2.0 * c_.e_max - 10.0;
    x_u[kX2] = 2.0 * c_.d + 10.0;
    for (int i = 0; i <= n_; ++i) {
      x_l[W(i)] = 0.0025;
      x_l[T(i)] = 0.0;
      x_u[T(i)] = 100.0;
    }
    x_u[T(0)] = 0.0;
    for (int j = 1; j <= m_; ++j) {
      x_l[WB(j)] = 0.0;
    }
    x_u[WB(m_)] = 0.0;
    for (Index r = 0; r < m; ++r) {
      g_l[r] = 0.0;
      g_u[r] = 0.0;
    }
    const int r_tend = 2 * n_ + 1;
    g_l[r_tend] = c_.react;
    g_u[r_tend] = c_.react;
    for (int r = 2 * n_ + 2 + m_; r < NumCons(); ++r) {  // inequalities >= 0
      g_u[r] = inf;
    }
    g_l[2 * n_ + 5 + m_] = 1e-3;  // x1 - x0 >= 1 mm
    return true;
  }

  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number*, Number*, Index, bool init_lambda,
                          Number*) override {
    if (!init_x || init_z || init_lambda) {
      return false;
    }
    for (Index i = 0; i < n; ++i) {
      x[i] = start_[static_cast<std::size_t>(i)];
    }
    return true;
  }

  bool eval_f(Index, const Number* x, bool, Number& obj) override {
    obj = -x[kX2];
    return true;
  }
  bool eval_grad_f(Index n, const Number*, bool, Number* grad) override {
    for (Index i = 0; i < n; ++i) {
      grad[i] = 0.0;
    }
    grad[kX2] = -1.0;
    return true;
  }
  bool eval_g(Index, const Number* x, bool, Index m, Number* g) override {
    for (Index r = 0; r < m; ++r) {
      g[r] = 0.0;
    }
    Acc acc{Mode::kValue, g, nullptr, nullptr, nullptr, 0};
    Eval(x, acc);
    return true;
  }
  bool eval_jac_g(Index, const Number* x, bool, Index, Index nele, Index* irow, Index* jcol, Number* values) override {
    if (values == nullptr) {
      return CopyStructure(jr_, jc_, nele, irow, jcol);
    }
    Acc acc{Mode::kJac, nullptr, values, nullptr, nullptr, 0};
    Eval(x, acc);
    return true;
  }
  bool eval_h(Index, const Number* x, bool, Number, Index, const Number* lambda, bool, Index nele, Index* irow,
              Index* jcol, Number* values) override {
    if (values == nullptr) {
      return CopyStructure(hr_, hc_, nele, irow, jcol);
    }
    Acc acc{Mode::kHess, nullptr, nullptr, values, lambda, 0};
    Eval(x, acc);
    return true;
  }
  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number obj_value, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    sol_.assign(x, x + n);
    obj_ = obj_value;
  }

 private:
  enum class Mode { kStructure, kValue, kJac, kHess };
  struct Acc {
    Mode mode;
    Number* g;
    Number* jac;
    Number* hess;
    const Number* lambda;
    std::size_t k;  // running index of jac / hess entries
  };

  // The first nele entries of a structure (the rows and columns of the Jacobian or Hessian
  // entries) for Ipopt.
  static bool CopyStructure(const std::vector<Index>& rows, const std::vector<Index>& cols, Index nele, Index* irow,
                            Index* jcol) {
    for (Index k = 0; k < nele; ++k) {
      irow[k] = rows[static_cast<std::size_t>(k)];
      jcol[k] = cols[static_cast<std::size_t>(k)];
    }
    return true;
  }

  // Structure: every Jac / Hess add call is one triplet entry, in a fixed order (Ipopt sums
  // duplicate entries), independent of the values.
  void BuildStructure() {
    jr_.clear();
    jc_.clear();
    hr_.clear();
    hc_.clear();
    std::vector<double> x(start_);
    Acc acc{Mode::kStructure, nullptr, nullptr, nullptr, nullptr, 0};
    Eval(x.data(), acc);
  }
  void Val(Acc& a, int row, double v) const {
    if (a.mode == Mode::kValue) {
      a.g[row] += v;
    }
  }
  void Jac(Acc& a, int row, int col, double v) {
    if (a.mode == Mode::kStructure) {
      jr_.push_back(row);
      jc_.push_back(col);
    } else if (a.mode == Mode::kJac) {
      a.jac[a.k++] = v;
    }
  }
  // Adds weight * lambda[row] * v to the Hessian entry (i, j) (and (j, i)).
  void Hess(Acc& a, int row, int i, int j, double v) {
    if (a.mode == Mode::kStructure) {
      hr_.push_back(std::max(i, j));
      hc_.push_back(std::min(i, j));
    } else if (a.mode == Mode::kHess) {
      // an off-diagonal second derivative d2/didj appears once in the lower triangle
      a.hess[a.k++] = a.lambda[row] * v;
    }
  }

  void Eval(const double* z, Acc& a) {
    const double xm = z[kXm], e = z[kE], vm = z[kVm], ev = z[kEv];
    const double beta = z[kBeta], dg = z[kDg], x1 = z[kX1], x2 = z[kX2];
    const double g = c_.grav;
    const double x0 = xm + e;
    int row = 0;
    // r0: w0 = V(vm, ev)^2
    {
      const double nn = vm + ev * c_.sc0;
      const double dd = 1.0 - ev * c_.sc1;
      const double v = nn / dd;
      const double v_vm = 1.0 / dd;
      const double v_ev = (c_.sc0 * dd + c_.sc1 * nn) / (dd * dd);
      const double v_vmev = c_.sc1 / (dd * dd);
      const double v_evev = 2.0 * c_.sc1 * v_ev / dd;
      Val(a, row, z[W(0)] - v * v);
      Jac(a, row, W(0), 1.0);
      Jac(a, row, kVm, -2.0 * v * v_vm);
      Jac(a, row, kEv, -2.0 * v * v_ev);
      Hess(a, row, kVm, kVm, -2.0 * v_vm * v_vm);
      Hess(a, row, kEv, kVm, -2.0 * (v_ev * v_vm + v * v_vmev));
      Hess(a, row, kEv, kEv, -2.0 * (v_ev * v_ev + v * v_evev));
      ++row;
    }
    // run-up w defects (mesh s_i = (i/N)^2: dense where the speed is low)
    for (int i = 0; i < n_; ++i, ++row) {
      const double si = S(i), sj = S(i + 1);
      const double hh = sj - si;
      const double xi = x0 + si * (x1 - x0), xj = x0 + sj * (x1 - x0);
      const double dx = xj - xi;
      const double gi = c_.G(xi), gj = c_.G(xj);
      Val(a, row, z[W(i + 1)] - z[W(i)] - 2.0 * c_.am * dx + 2.0 * g * (c_.IG(xj) - c_.IG(xi)) + 2.0 * g * dg * dx);
      Jac(a, row, W(i + 1), 1.0);
      Jac(a, row, W(i), -1.0);
      const double dfdxj = -2.0 * c_.am + 2.0 * g * gj + 2.0 * g * dg;  // d/dX_{i+1}
      const double dfdxi = 2.0 * c_.am - 2.0 * g * gi - 2.0 * g * dg;   // d/dX_i
      const double ui = 1.0 - si, uj = 1.0 - sj;
      Jac(a, row, kXm, dfdxj * uj + dfdxi * ui);
      Jac(a, row, kE, dfdxj * uj + dfdxi * ui);
      Jac(a, row, kX1, dfdxj * sj + dfdxi * si);
      Jac(a, row, kDg, 2.0 * g * dx);
      const double hj = 2.0 * g * c_.DG(xj), hi = -2.0 * g * c_.DG(xi);
      const double cxm = hj * uj * uj + hi * ui * ui;
      const double cx1 = hj * sj * sj + hi * si * si;
      const double cmix = hj * uj * sj + hi * ui * si;
      Hess(a, row, kXm, kXm, cxm);
      Hess(a, row, kE, kXm, cxm);
      Hess(a, row, kE, kE, cxm);
      Hess(a, row, kX1, kXm, cmix);
      Hess(a, row, kX1, kE, cmix);
      Hess(a, row, kX1, kX1, cx1);
      // d dx / d(xm, e, x1) = (-hh, -hh, hh)
      Hess(a, row, kDg, kXm, -2.0 * g * hh);
      Hess(a, row, kDg, kE, -2.0 * g * hh);
      Hess(a, row, kDg, kX1, 2.0 * g * hh);
    }
    // run-up time defects
    for (int i = 0; i < n_; ++i, ++row) {
      const double h = S(i + 1) - S(i);
      const double dx = h * (x1 - x0);
      const double wi = z[W(i)], wj = z[W(i + 1)];
      const double ri = 1.0 / std::sqrt(wi), rj = 1.0 / std::sqrt(wj);
      const double q = 0.5 * (ri + rj);
      Val(a, row, z[T(i + 1)] - z[T(i)] - dx * q);
      Jac(a, row, T(i + 1), 1.0);
      Jac(a, row, T(i), -1.0);
      Jac(a, row, kXm, h * q);
      Jac(a, row, kE, h * q);
      Jac(a, row, kX1, -h * q);
      Jac(a, row, W(i), 0.25 * dx * ri / wi);
      Jac(a, row, W(i + 1), 0.25 * dx * rj / wj);
      Hess(a, row, W(i), W(i), -0.375 * dx * ri / (wi * wi));
      Hess(a, row, W(i + 1), W(i + 1), -0.375 * dx * rj / (wj * wj));
      Hess(a, row, W(i), kXm, -0.25 * h * ri / wi);
      Hess(a, row, W(i), kE, -0.25 * h * ri / wi);
      Hess(a, row, W(i), kX1, 0.25 * h * ri / wi);
      Hess(a, row, W(i + 1), kXm, -0.25 * h * rj / wj);
      Hess(a, row, W(i + 1), kE, -0.25 * h * rj / wj);
      Hess(a, row, W(i + 1), kX1, 0.25 * h * rj / wj);
    }
    // t_N - phi - t_f = reaction
    Val(a, row, z[T(n_)] - z[kPh] - z[kTf]);
    Jac(a, row, T(n_), 1.0);
    Jac(a, row, kPh, -1.0);
    Jac(a, row, kTf, -1.0);
    ++row;
    // braking defects
    const double hb = 1.0 / m_;
    for (int j = 0; j < m_; ++j, ++row) {
      const double sj0 = j * hb, sj1 = (j + 1) * hb;
      const double y0 = x1 + sj0 * (x2 - x1), y1 = x1 + sj1 * (x2 - x1);
      const double dy = y1 - y0;
      Val(a, row, z[WB(j + 1)] - z[WB(j)] + 2.0 * beta * dy + 2.0 * g * (c_.IG(y1) - c_.IG(y0)) + 2.0 * g * dg * dy);
      Jac(a, row, WB(j + 1), 1.0);
      Jac(a, row, WB(j), -1.0);
      const double d1 = 2.0 * beta + 2.0 * g * c_.G(y1) + 2.0 * g * dg;   // d/dY_{j+1}
      const double d0 = -2.0 * beta - 2.0 * g * c_.G(y0) - 2.0 * g * dg;  // d/dY_j
      Jac(a, row, kX1, d1 * (1.0 - sj1) + d0 * (1.0 - sj0));
      Jac(a, row, kX2, d1 * sj1 + d0 * sj0);
      Jac(a, row, kBeta, 2.0 * dy);
      Jac(a, row, kDg, 2.0 * g * dy);
      const double h1 = 2.0 * g * c_.DG(y1), h0 = -2.0 * g * c_.DG(y0);
      Hess(a, row, kX1, kX1, h1 * (1.0 - sj1) * (1.0 - sj1) + h0 * (1.0 - sj0) * (1.0 - sj0));
      Hess(a, row, kX2, kX1, h1 * (1.0 - sj1) * sj1 + h0 * (1.0 - sj0) * sj0);
      Hess(a, row, kX2, kX2, h1 * sj1 * sj1 + h0 * sj0 * sj0);
      // d dy / d(x1, x2) = (-hb, hb)
      Hess(a, row, kBeta, kX1, -2.0 * hb);
      Hess(a, row, kBeta, kX2, 2.0 * hb);
      Hess(a, row, kDg, kX1, -2.0 * g * hb);
      Hess(a, row, kDg, kX2, 2.0 * g * hb);
    }
    // pattern: W(y) - (v_s + a_p T)^2 >= 0
    {
      const double vs = c_.kk * vm + c_.abs0;
      const double y = xm + c_.e_max + vs * c_.tp + 0.5 * c_.ap * c_.tp * c_.tp;
      const double u = vs + c_.ap * c_.tp;
      const double w1 = c_.DW(y), w2 = c_.DDW(y);
      Val(a, row, c_.W(y) - u * u);
      Jac(a, row, kXm, w1);
      Jac(a, row, kVm, w1 * c_.kk * c_.tp - 2.0 * u * c_.kk);
      Hess(a, row, kXm, kXm, w2);
      Hess(a, row, kVm, kXm, w2 * c_.kk * c_.tp);
      Hess(a, row, kVm, kVm, w2 * c_.kk * c_.kk * c_.tp * c_.tp - 2.0 * c_.kk * c_.kk);
      ++row;
    }
    // ceiling
    {
      const double ys = xm + c_.e_max;
      Val(a, row, c_.C(ys) - (c_.kk * vm + c_.abs0 + c_.ap * c_.tp));
      Jac(a, row, kXm, c_.DC(ys));
      Jac(a, row, kVm, -c_.kk);
      Hess(a, row, kXm, kXm, c_.DDC(ys));
      ++row;
    }
    // train maximum speed: vtrain - V >= 0
    {
      const double nn = vm + ev * c_.sc0;
      const double dd = 1.0 - ev * c_.sc1;
      const double v = nn / dd;
      const double v_ev = (c_.sc0 * dd + c_.sc1 * nn) / (dd * dd);
      Val(a, row, c_.vtrain - v);
      Jac(a, row, kVm, -1.0 / dd);
      Jac(a, row, kEv, -v_ev);
      Hess(a, row, kEv, kVm, -c_.sc1 / (dd * dd));
      Hess(a, row, kEv, kEv, -2.0 * c_.sc1 * v_ev / dd);
      ++row;
    }
    // x1 - x0 >= 1 mm ; x2 - x1 >= 0
    Val(a, row, x1 - x0);
    Jac(a, row, kX1, 1.0);
    Jac(a, row, kXm, -1.0);
    Jac(a, row, kE, -1.0);
    ++row;
    Val(a, row, x2 - x1);
    Jac(a, row, kX2, 1.0);
    Jac(a, row, kX1, -1.0);
    ++row;
  }

  ContModel c_;
  int n_;
  int m_;
  std::vector<double> start_;
  std::vector<double> sol_;
  double obj_ = 0.0;
  std::vector<Index> jr_, jc_, hr_, hc_;
};

// Builds the continuous model of a location from the margin model (SI, relative to L).
ContModel MakeContModel(const MarginModel& m, const Location& loc, const NlpOptions& opt) {
  ContModel c;
  const double l = static_cast<double>(loc.stop_limit_mm);
  const auto& tt = m.train();
  const auto& pr = m.params();
  c.eps = opt.smoothing_mm / 1000.0;
  c.grav = static_cast<double>(pr.gravity_mm_s2) / 1000.0;
  c.e_max = static_cast<double>(m.position_error_mm()) / 1000.0;
  c.d = static_cast<double>(m.approach_mm()) / 1000.0;
  const double lo = -c.d - 2.0 * c.e_max - 50.0;
  const double hi = c.d + 50.0;
  c.xref = lo;
  // gradient steps in [lo, hi]
  const auto& ps = m.piece_start();
  const auto& pg = m.piece_gradient();
  c.gradient.level = static_cast<double>(pg[0]) / 10000.0;
  for (std::size_t k = 1; k < ps.size(); ++k) {
    const double p = (ps[k] - l) / 1000.0;
    const double dlt = static_cast<double>(pg[k] - pg[k - 1]) / 10000.0;
    if (p < lo) {
      c.gradient.level += dlt;  // fully passed: absorbed in the level (IG's constant is irrelevant)
    } else if (p <= hi) {
      c.gradient.at.push_back(p);
      c.gradient.change.push_back(dlt);
    }
  }
  // ceiling steps (sampled from the runtime's ceiling semantics at its breakpoints)
  std::vector<double> cuts;
  const double ext = static_cast<double>(tt.length_mm + 2 * m.position_error_mm());
  for (const auto& s : m.running_line().speed_limits) {
    cuts.push_back(static_cast<double>(s.section.begin_mm));
    cuts.push_back(static_cast<double>(s.section.end_mm) + ext);
  }
  std::sort(cuts.begin(), cuts.end());
  c.ceiling.level = m.EmergencyCeilingMmS(l + lo * 1000.0) / 1000.0;
  double prev = c.ceiling.level;
  for (const double cut : cuts) {
    const double p = (cut - l) / 1000.0;
    if (p <= lo || p > hi) {
      continue;
    }
    const double v = m.EmergencyCeilingMmS(cut) / 1000.0;
    if (v != prev) {
      // rise: start early; drop: finish late (smoothed ceiling >= exact ceiling)
      c.ceiling.at.push_back(v > prev ? p - 4.0 * c.eps : p + 4.0 * c.eps);
      c.ceiling.change.push_back(v - prev);
      prev = v;
    }
  }
  const auto& calc = m.patterns();
  std::int64_t ap = std::numeric_limits<std::int64_t>::max();
  for (std::int64_t x = loc.stop_limit_mm - m.approach_mm(); x <= loc.stop_limit_mm; x += 1000) {
    ap = std::min(ap, calc.RunUpAcceleration(br::Pattern::kEmergency, x));
  }
  c.ap = static_cast<double>(ap) / 1000.0;
  c.tp = static_cast<double>(calc.RunUpTimeMs(br::Pattern::kEmergency)) / 1000.0;
  c.am = static_cast<double>(tt.accel_max_mm_s2) / 1000.0;
  c.beta_e = static_cast<double>(tt.emergency_pattern_mm_s2) / 1000.0;
  c.ge = static_cast<double>(pr.gradient_error_x10) / 10000.0;
  c.kk = 1.0 + static_cast<double>(tt.speed_error_ppm) / 1e6;
  c.abs0 = static_cast<double>(tt.speed_error_abs_mm_s) / 1000.0;
  c.sc0 = m.speed_error().c0_mm_s / 1000.0;
  c.sc1 = m.speed_error().c1;
  c.vtrain = static_cast<double>(m.train_max_speed_mm_s()) / 1000.0;
  c.react = static_cast<double>(pr.reaction_ms) / 1000.0;
  c.cycle = static_cast<double>(pr.cycle_ms) / 1000.0;
  c.beta_lo = static_cast<double>(tt.emergency_deceleration_mm_s2.min) / 1000.0;
  c.beta_hi = static_cast<double>(tt.emergency_deceleration_mm_s2.max) / 1000.0;
  c.tf_lo = static_cast<double>(tt.emergency_free_running_ms.min) / 1000.0;
  c.tf_hi = static_cast<double>(tt.emergency_free_running_ms.max) / 1000.0;
  return c;
}

ContParams WorstParams(const ContModel& c, double xm, double vm) {
  return ContParams{xm, c.e_max, vm, 1.0, c.beta_lo, c.tf_hi, -c.ge, c.cycle};
}

std::vector<double> StartVector(const MarginTnlp& nlp, const ContModel& c, const ContParams& p, int n, int mb) {
  const ContTraj tr = ContEvaluate(c, p, n, mb);
  std::vector<double> z(static_cast<std::size_t>(nlp.NumVars()), 0.0);
  z[MarginTnlp::kXm] = p.xm;
  z[MarginTnlp::kE] = p.e;
  z[MarginTnlp::kVm] = p.vm;
  z[MarginTnlp::kEv] = p.ev;
  z[MarginTnlp::kBeta] = p.beta;
  z[MarginTnlp::kTf] = p.tf;
  z[MarginTnlp::kDg] = p.dg;
  z[MarginTnlp::kPh] = p.ph;
  z[MarginTnlp::kX1] = tr.x1;
  z[MarginTnlp::kX2] = tr.x2;
  for (int i = 0; i <= n; ++i) {
    z[static_cast<std::size_t>(nlp.W(i))] = std::max(0.0026, tr.w[static_cast<std::size_t>(i)]);
    z[static_cast<std::size_t>(nlp.T(i))] = tr.t[static_cast<std::size_t>(i)];
  }
  for (int j = 1; j <= mb; ++j) {
    z[static_cast<std::size_t>(nlp.WB(j))] = tr.wb[static_cast<std::size_t>(j)];
  }
  return z;
}

}  // namespace

// @implements REQ-BR-009 REQ-BR-014 REQ-BR-005 REQ-BR-007
NlpResult NlpWorstCase(const MarginModel& m, const Location& loc, const std::vector<NlpSeed>& seeds,
                       const NlpOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const ContModel c = MakeContModel(m, loc, opt);
  const double l = static_cast<double>(loc.stop_limit_mm);
  NlpResult best;
  best.objective_m = -std::numeric_limits<double>::infinity();
  best.margin_mm = std::numeric_limits<double>::infinity();
  int total_iterations = 0;
  for (const NlpSeed& s : seeds) {
    const double xm = std::clamp((s.check_front_mm - l) / 1000.0 - c.e_max, -c.d - c.e_max + 1e-3, -c.e_max - 1e-3);
    double vm = s.measured_speed_mm_s / 1000.0;
    const double vmax = c.MaxVm(xm);
    if (vmax < 0.0) {
      continue;  // not admissible in the continuous model either (standstill region)
    }
    vm = std::clamp(vm, c.v_floor, vmax);
    ContParams p = WorstParams(c, xm, vm);
    if (opt.derivative_test) {  // an interior point exercises every derivative
      p = ContParams{xm, 0.5 * c.e_max, vm, 0.5, 0.5 * (c.beta_lo + c.beta_hi), 0.5 * (c.tf_lo + c.tf_hi), -0.3 * c.ge,
                     0.5 * c.cycle};
    }
    Ipopt::SmartPtr<MarginTnlp> nlp = new MarginTnlp(c, opt.run_up_intervals, opt.braking_intervals, {});
    const auto z0 = StartVector(*nlp, c, p, opt.run_up_intervals, opt.braking_intervals);
    nlp = new MarginTnlp(c, opt.run_up_intervals, opt.braking_intervals, z0);
    Ipopt::ApplicationReturnStatus st;
    int iterations = 0;
    {
      std::lock_guard<std::mutex> lock(offline::IpoptMutex());  // one Ipopt solve at a time in the process
      Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
      app->RethrowNonIpoptException(true);
      auto o = app->Options();
      o->SetIntegerValue("print_level", opt.print_level);
      o->SetStringValue("sb", "yes");
      o->SetNumericValue("tol", 1e-9);
      o->SetNumericValue("acceptable_tol", 1e-6);
      o->SetIntegerValue("max_iter", opt.max_iter);
      // the seeds are feasible, near-optimal points: a small initial barrier parameter
      // keeps the interior-point iterations in the seed's basin
      o->SetStringValue("mu_strategy", "monotone");
      o->SetNumericValue("mu_init", 1e-5);
      o->SetNumericValue("bound_push", 1e-6);
      o->SetNumericValue("bound_frac", 1e-6);
      if (!opt.output_file.empty()) {
        o->SetStringValue("output_file", opt.output_file);
        o->SetIntegerValue("file_print_level", 5);
      }
      if (opt.derivative_test) {
        o->SetStringValue("derivative_test", "second-order");
        o->SetNumericValue("derivative_test_perturbation", opt.derivative_test_perturbation);
        o->SetIntegerValue("max_iter", 0);
      }
      if (app->Initialize() != Ipopt::Solve_Succeeded) {
        throw std::runtime_error("Ipopt initialisation failed");
      }
      st = app->OptimizeTNLP(nlp);
      iterations = IsValid(app->Statistics()) ? app->Statistics()->IterationCount() : 0;
    }
    const auto& z = nlp->solution();
    if (z.empty()) {
      continue;
    }
    NlpResult r;
    r.solved = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
    r.status = r.solved ? (st == Ipopt::Solve_Succeeded ? "solved" : "acceptable") : "failed (" + std::to_string(static_cast<int>(st)) + ")";
    if (opt.derivative_test) {
      r.status = "derivative test";
    }
    r.objective_m = -nlp->objective();
    // exact physics from the NLP's worst state
    Adversary adv;
    adv.beta_mm_s2 = z[MarginTnlp::kBeta] * 1000.0;
    adv.free_running_ms = z[MarginTnlp::kTf] * 1000.0;
    adv.gradient_error_x10 = z[MarginTnlp::kDg] * 10000.0;
    adv.runup_cycle_ms = z[MarginTnlp::kPh] * 1000.0;
    adv.traction = 1.0;
    adv.position_error_mm = z[MarginTnlp::kE] * 1000.0;
    adv.speed_error_sign = z[MarginTnlp::kEv];
    const double v_true = TrueSpeed(c, z[MarginTnlp::kVm], z[MarginTnlp::kEv]) * 1000.0;
    const double x_true = l + (z[MarginTnlp::kXm] + z[MarginTnlp::kE]) * 1000.0;
    r.worst = m.Simulate(x_true, v_true, adv, true);
    r.worst.check_front_mm = l + (z[MarginTnlp::kXm] + c.e_max) * 1000.0;
    r.worst.measured_speed_mm_s = static_cast<std::int64_t>(std::floor(z[MarginTnlp::kVm] * 1000.0));
    r.worst.supervised_speed_mm_s = m.patterns().SupervisedSpeed(r.worst.measured_speed_mm_s);
    r.worst.pattern_speed_mm_s = m.patterns().EmergencyPatternSpeed(static_cast<std::int64_t>(std::floor(r.worst.check_front_mm)),
                                                                    loc.stop_limit_mm, m.position_error_mm(),
                                                                    m.position_error_mm());
    r.runtime_admissible = r.worst.supervised_speed_mm_s <= r.worst.pattern_speed_mm_s;
    r.margin_mm = l - r.worst.stop_mm;
    r.iterations = iterations;
    total_iterations += iterations;
    if ((r.solved || opt.derivative_test) && (best.status.empty() || r.objective_m > best.objective_m)) {
      best = r;
    }
  }
  best.iterations = total_iterations;
  best.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return best;
}

ContinuousGridResult ContinuousGridWorstCase(const MarginModel& m, const Location& loc, double step_mm,
                                             int params_per_axis, const NlpOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const ContModel c = MakeContModel(m, loc, opt);
  ContinuousGridResult out;
  out.objective_m = -std::numeric_limits<double>::infinity();
  const double step = step_mm / 1000.0;
  const int k = std::max(1, params_per_axis);
  auto axis = [&](double worst, double other, int i) { return k == 1 ? worst : other + (worst - other) * i / (k - 1); };
  for (double xs = -c.d; xs <= 0.0; xs += step) {
    const double xm = xs - c.e_max;
    const double vmax = c.MaxVm(xm);
    if (vmax < 0.0) {
      continue;
    }
    for (int ib = 0; ib < k; ++ib) {
      for (int it = 0; it < k; ++it) {
        for (int ig = 0; ig < k; ++ig) {
          for (int ip = 0; ip < k; ++ip) {
            for (int ie = 0; ie < k; ++ie) {
              for (int iv = 0; iv < k; ++iv) {
                ContParams p{xm,
                             axis(c.e_max, -c.e_max, ie),
                             vmax,
                             axis(1.0, -1.0, iv),
                             axis(c.beta_lo, c.beta_hi, ib),
                             axis(c.tf_hi, c.tf_lo, it),
                             axis(-c.ge, c.ge, ig),
                             axis(c.cycle, 0.0, ip)};
                if (TrueSpeed(c, p.vm, p.ev) > c.vtrain) {
                  p.ev = (c.vtrain * 1.0 - p.vm) / (c.sc0 + c.sc1 * c.vtrain);
                }
                const ContTraj tr = ContEvaluate(c, p, opt.run_up_intervals, opt.braking_intervals);
                ++out.evaluations;
                out.objective_m = std::max(out.objective_m, tr.x2);
              }
            }
          }
        }
      }
    }
  }
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace railproof::br::analysis
