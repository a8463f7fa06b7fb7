// Bounded NLP solved by Ipopt (nlp.hpp).
#include "railproof/offline/nlp.hpp"

#include <coin/IpIpoptApplication.hpp>
#include <coin/IpSolveStatistics.hpp>
#include <coin/IpTNLP.hpp>

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <utility>

namespace railproof::offline {

namespace {

using Ipopt::Index;
using Ipopt::Number;

class BoxTnlp : public Ipopt::TNLP {
 public:
  explicit BoxTnlp(const BoxNlp& nlp) : nlp_(nlp) {}

  const std::vector<double>& solution() const { return x_; }
  double objective() const { return f_; }

  bool get_nlp_info(Index& n, Index& m, Index& nnz_jac_g, Index& nnz_h_lag, IndexStyleEnum& style) override {
    n = static_cast<Index>(nlp_.start.size());
    m = 0;
    nnz_jac_g = 0;
    nnz_h_lag = 0;
    style = C_STYLE;
    return true;
  }
  bool get_bounds_info(Index n, Number* x_l, Number* x_u, Index, Number*, Number*) override {
    for (Index i = 0; i < n; ++i) {
      x_l[i] = nlp_.lower[static_cast<std::size_t>(i)];
      x_u[i] = nlp_.upper[static_cast<std::size_t>(i)];
    }
    return true;
  }
  bool get_starting_point(Index n, bool init_x, Number* x, bool init_z, Number*, Number*, Index, bool init_lambda,
                          Number*) override {
    if (!init_x || init_z || init_lambda) {
      return false;
    }
    std::copy(nlp_.start.begin(), nlp_.start.begin() + n, x);
    return true;
  }
  bool eval_f(Index n, const Number* x, bool, Number& obj) override {
    obj = nlp_.objective(std::vector<double>(x, x + n));
    return true;
  }
  // Central differences, one-sided where a bound leaves no room (the objective is only
  // evaluated inside the box).
  bool eval_grad_f(Index n, const Number* x, bool, Number* grad) override {
    std::vector<double> p(x, x + n);
    for (Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double h = nlp_.difference_step;
      const double hi = std::min(p[k] + h, nlp_.upper[k]);
      const double lo = std::max(p[k] - h, nlp_.lower[k]);
      const double x0 = p[k];
      p[k] = hi;
      const double f_hi = nlp_.objective(p);
      p[k] = lo;
      const double f_lo = nlp_.objective(p);
      p[k] = x0;
      grad[i] = hi > lo ? (f_hi - f_lo) / (hi - lo) : 0.0;
    }
    return true;
  }
  bool eval_g(Index, const Number*, bool, Index, Number*) override { return true; }
  bool eval_jac_g(Index, const Number*, bool, Index, Index, Index*, Index*, Number*) override { return true; }
  void finalize_solution(Ipopt::SolverReturn, Index n, const Number* x, const Number*, const Number*, Index,
                         const Number*, const Number*, Number obj_value, const Ipopt::IpoptData*,
                         Ipopt::IpoptCalculatedQuantities*) override {
    x_.assign(x, x + n);
    f_ = obj_value;
  }

 private:
  const BoxNlp& nlp_;
  std::vector<double> x_;
  double f_ = 0.0;
};

}  // namespace

std::mutex& IpoptMutex() {
  static std::mutex mu;
  return mu;
}

BoxNlpResult SolveBoxNlp(const BoxNlp& nlp) {
  const std::size_t n = nlp.start.size();
  if (n == 0 || nlp.lower.size() != n || nlp.upper.size() != n || !nlp.objective) {
    throw std::invalid_argument("SolveBoxNlp: the start, the bounds and the objective must be given for every variable");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(nlp.lower[i] <= nlp.start[i] && nlp.start[i] <= nlp.upper[i])) {
      throw std::invalid_argument("SolveBoxNlp: the start lies outside the bounds");
    }
  }
  Ipopt::SmartPtr<BoxTnlp> tnlp = new BoxTnlp(nlp);
  Ipopt::ApplicationReturnStatus st = Ipopt::Internal_Error;
  BoxNlpResult r;
  {
    const std::lock_guard<std::mutex> lock(IpoptMutex());
    Ipopt::SmartPtr<Ipopt::IpoptApplication> app = IpoptApplicationFactory();
    app->RethrowNonIpoptException(true);
    Ipopt::SmartPtr<Ipopt::OptionsList> o = app->Options();
    o->SetIntegerValue("print_level", 0);
    o->SetStringValue("sb", "yes");
    o->SetStringValue("hessian_approximation", "limited-memory");
    o->SetNumericValue("tol", nlp.tolerance);
    o->SetIntegerValue("max_iter", nlp.max_iterations);
    if (app->Initialize() != Ipopt::Solve_Succeeded) {
      throw std::runtime_error("Ipopt initialisation failed");
    }
    st = app->OptimizeTNLP(tnlp);
    if (Ipopt::SmartPtr<Ipopt::SolveStatistics> stats = app->Statistics(); Ipopt::IsValid(stats)) {
      r.iterations = stats->IterationCount();
    }
  }
  r.solved = st == Ipopt::Solve_Succeeded || st == Ipopt::Solved_To_Acceptable_Level;
  r.status = r.solved ? (st == Ipopt::Solve_Succeeded ? "solved" : "acceptable")
                      : "failed (" + std::to_string(static_cast<int>(st)) + ")";
  r.x = tnlp->solution();
  r.objective = tnlp->objective();
  if (r.x.size() != n) {
    r.x = nlp.start;
    r.objective = nlp.objective(r.x);
    r.solved = false;
  }
  return r;
}

}  // namespace railproof::offline
