// Buffers, speed-limit positions and the corridor (follower.hpp; spec/design/fc.md §2-§3).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

#include "railproof/fc/follower.hpp"
#include "railproof/generated/fc_params.hpp"

namespace railproof::fc {

namespace fcp = railproof::params::fc;

// The D2 10-car EMU's consist (D2 §3: motor cars 170 t, trailers 125 t in all; ASM-032).
constexpr offline::Consist kD2Consist{10, 170.0, 125.0};

BufferParams MakeBufferParams(const offline::TrainType& train) {
  return BufferParams{static_cast<double>(train.odometry_ppm) * 1e-6, static_cast<double>(fcp::radio_delay_ms) / 1000.0,
                      static_cast<double>(fcp::resolution_margin_mm) / 1000.0};
}

double LastBalise(const std::vector<double>& balises_m, double x) {
  double last = 0.0;
  for (const double b : balises_m) {
    if (b > x) {
      break;
    }
    last = b;
  }
  return last;
}

double FrontBuffer(const BufferParams& b, double x, double v, double x_m) {
  return b.rate * (x - x_m) + v * b.tau_s + b.lc_m;
}

double RearBuffer(const BufferParams& b, double x, double x_m) { return b.rate * (x - x_m) + b.lc_m; }

namespace {

// The largest candidate position over the balises (and the line start) for which the balise
// lies at or before it: `at(x_m)` is the position computed with x_m.
template <typename At>
double LargestOverBalises(const std::vector<double>& balises_m, double before, const At& at) {
  double best = at(0.0);
  for (const double m : balises_m) {
    if (m >= before) {
      break;
    }
    const double x = at(m);
    if (m <= x) {
      best = std::max(best, x);
    }
  }
  return best;
}

}  // namespace

double LimitStartFront(const BufferParams& b, double x_s, double v, const std::vector<double>& balises_m) {
  return LargestOverBalises(balises_m, x_s, [&](double x_m) {
    return (x_s - (v * b.tau_s + b.lc_m) + b.rate * x_m) / (1.0 + b.rate);
  });
}

double LimitEndFront(const BufferParams& b, double x_e, double length_m, const std::vector<double>& balises_m) {
  // The rear buffer shrinks with a later balise: the one the train has last passed where its
  // buffered rear reaches x_e (the latest balise at or before the position it gives).
  auto at = [&](double x_m) { return (x_e + length_m + b.lc_m - b.rate * x_m) / (1.0 - b.rate); };
  double x = at(0.0);
  for (const double m : balises_m) {
    if (m <= at(m)) {
      x = at(m);
    }
  }
  return x;
}

const char* CaseName(Case c) {
  switch (c) {
    case Case::kLevelNoLimits:
      return "level_no_limits";
    case Case::kSpeedLimits:
      return "speed_limits";
    case Case::kGradients:
      return "gradients";
  }
  return "?";
}

Train MakeD2Train(const offline::TrainType& type) {
  Train t;
  t.perf.length_m = static_cast<double>(type.length_mm) / 1000.0;
  t.perf.max_speed_mps = static_cast<double>(type.max_speed_kmh) / 3.6;
  t.perf.accel_mps2 = static_cast<double>(type.accel_max_mm_s2) / 1000.0;
  t.perf.service_decel_mps2 = static_cast<double>(type.service_pattern_mm_s2) / 1000.0;
  t.perf.emergency_decel_mps2 = static_cast<double>(type.emergency_pattern_mm_s2) / 1000.0;
  t.perf.resistance = offline::ConsistResistance(kD2Consist);
  t.perf.constant_power_from_mps = static_cast<double>(fcp::traction_base_speed_kmh) / 3.6;
  t.beta = t.perf.service_decel_mps2;
  t.buffers = MakeBufferParams(type);
  return t;
}

Corridor::Corridor(const offline::RunningLine& rl, double from_m, double to_m, const Train& train, Case c)
    : train_(train), from_(from_m), to_(to_m) {
  for (const offline::Balise& b : rl.balises) {
    balises_.push_back(static_cast<double>(b.position_mm) / 1000.0);
  }
  std::sort(balises_.begin(), balises_.end());
  const auto n = static_cast<std::size_t>(std::ceil((to_ - from_) / kGridM)) + 1;
  const double length = train.perf.length_m;
  gradient_.assign(n, 0.0);
  limit_.assign(n, train.perf.max_speed_mps);
  brake_.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = from_ + static_cast<double>(i) * kGridM;
    if (c == Case::kGradients) {
      gradient_[i] = rl.MeanGradientPermille((x - length) * 1000.0, x * 1000.0);
    }
  }
  if (c == Case::kSpeedLimits) {
    for (const offline::SpeedLimit& l : rl.speed_limits) {
      const double v = std::min(static_cast<double>(l.kmh) / 3.6, train.perf.max_speed_mps);
      const double start = LimitStartFront(train.buffers, static_cast<double>(l.section.begin_mm) / 1000.0, v, balises_);
      const double end = LimitEndFront(train.buffers, static_cast<double>(l.section.end_mm) / 1000.0, length, balises_);
      for (std::size_t i = 0; i < n; ++i) {
        const double x = from_ + static_cast<double>(i) * kGridM;
        if (start <= x && x < end) {
          limit_[i] = std::min(limit_[i], v);
        }
      }
    }
  }
  for (std::size_t i = 1; i < n; ++i) {
    const double g = 0.5 * (gradient_[i - 1] + gradient_[i]);
    brake_[i] = brake_[i - 1] + (train.beta + offline::GradeDecel(g)) * kGridM;
  }
  ceiling_ = limit_;
  for (std::size_t i = n - 1; i-- > 0;) {
    const double w = ceiling_[i + 1] * ceiling_[i + 1] + 2.0 * (brake_[i + 1] - brake_[i]);
    ceiling_[i] = std::min(ceiling_[i], std::sqrt(w));
  }
}

double Corridor::Sample(const std::vector<double>& v, double x) const {
  const double u = std::clamp((x - from_) / kGridM, 0.0, static_cast<double>(v.size() - 1));
  const auto i = std::min(static_cast<std::size_t>(u), v.size() - 2);
  const double f = u - static_cast<double>(i);
  return v[i] + f * (v[i + 1] - v[i]);
}

double Corridor::Gradient(double x) const { return Sample(gradient_, x); }
double Corridor::StaticCeiling(double x) const { return Sample(ceiling_, x); }
double Corridor::BrakeIntegral(double x) const {
  // beyond the corridor's ends the last braking capability continues
  if (x > to_) {
    return brake_.back() + (train_.beta + offline::GradeDecel(gradient_.back())) * (x - to_);
  }
  if (x < from_) {
    return brake_.front() - (train_.beta + offline::GradeDecel(gradient_.front())) * (from_ - x);
  }
  return Sample(brake_, x);
}

double Corridor::Limit(double x) const {
  // the limit is piecewise constant: the sample at the grid node at or before x
  const double u = std::clamp((x - from_) / kGridM, 0.0, static_cast<double>(limit_.size() - 1));
  return limit_[static_cast<std::size_t>(u)];
}

double Corridor::CurveTo(double x, double target, double v_end) const {
  const double w = v_end * v_end + 2.0 * (BrakeIntegral(target) - BrakeIntegral(x));
  return w > 0.0 ? std::sqrt(w) : 0.0;
}

double Corridor::SafeSpeed(double x, double stop_limit) const {
  const double x_m = LastBalise(balises_, x);
  auto fits = [&](double v) {
    const double front = x + FrontBuffer(train_.buffers, x, v, x_m);
    return front <= stop_limit && v <= CurveTo(front, stop_limit);
  };
  if (!fits(0.0)) {
    return 0.0;
  }
  double lo = 0.0;
  double hi = train_.perf.max_speed_mps + 1.0;
  if (fits(hi)) {
    return hi;
  }
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    (fits(mid) ? lo : hi) = mid;
  }
  return lo;
}

std::vector<double> Corridor::LimitChanges(double a, double b) const {
  std::vector<double> out;
  for (std::size_t i = 1; i < limit_.size(); ++i) {
    const double x = from_ + static_cast<double>(i) * kGridM;
    if (x > a && x < b && limit_[i] != limit_[i - 1]) {
      out.push_back(x);
    }
  }
  return out;
}

}  // namespace railproof::fc
