// Small bounded nonlinear programmes for the offline analyses, solved by Ipopt: minimise f(x)
// over a box lo <= x <= hi (a few variables), first derivatives by central differences and
// the Hessian by Ipopt's limited-memory quasi-Newton update, so a caller gives the objective
// alone. What an Ipopt solve of the project needs everywhere is here once: one solve at a time
// (MUMPS, Ipopt's linear solver, is not thread-safe: IpoptMutex), no banner, the return status
// as text. The worst-case margin NLP (br, margins_nlp.cpp) states its own exact derivatives.
// Offline module (may allocate and throw).
#pragma once

#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace railproof::offline {

// The lock every Ipopt solve of a process holds.
std::mutex& IpoptMutex();

struct BoxNlp {
  std::function<double(const std::vector<double>&)> objective;
  std::vector<double> lower, upper, start;
  double difference_step = 1e-6;  // central-difference step, in the unit of x
  double tolerance = 1e-8;        // Ipopt's tol
  int max_iterations = 200;
};

struct BoxNlpResult {
  std::vector<double> x;
  double objective = 0.0;
  bool solved = false;  // solved or solved to the acceptable level
  std::string status;   // "solved", "acceptable" or "failed (<Ipopt status>)"
  int iterations = 0;
};

// Minimises the programme; throws std::invalid_argument for inconsistent sizes or bounds.
BoxNlpResult SolveBoxNlp(const BoxNlp& nlp);

}  // namespace railproof::offline
