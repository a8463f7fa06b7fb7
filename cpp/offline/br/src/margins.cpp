// Worst-case braking margins: locations, uncertainty set, exact piecewise physics and the
// corner + grid method over the runtime patterns (margins.hpp, spec/design/br.md §5).
#include "railproof/br/analysis/margins.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

#include "railproof/generated/mb_params.hpp"
#include "railproof/offline/dynamics.hpp"

namespace railproof::br::analysis {

namespace mb = params::mb;

const char* ToString(LocationClass c) noexcept {
  switch (c) {
    case LocationClass::kPrecedingTrain: return "preceding_train";
    case LocationClass::kPlatform: return "platform";
    case LocationClass::kRouteEnd: return "route_end";
    case LocationClass::kHandover: return "handover";
    case LocationClass::kSystemBoundary: return "system_boundary";
    case LocationClass::kPossession: return "possession";
    case LocationClass::kLevelCrossing: return "level_crossing";
    case LocationClass::kEndOfTrack: return "end_of_track";
  }
  return "invalid";
}

namespace {

std::string Metres(std::int64_t mm) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f m", static_cast<double>(mm) / 1000.0);
  return buf;
}

}  // namespace

// @implements REQ-BR-009 REQ-BR-011
LocationSet EnumerateLocations(const offline::RunningLine& rl, std::int64_t train_length_mm,
                               std::int64_t min_approach_mm) {
  std::vector<Location> all;
  auto add = [&](LocationClass cls, std::string id, std::int64_t obstruction, std::int64_t margin) {
    all.push_back(Location{cls, std::move(id), obstruction, margin, obstruction - margin});
  };
  for (const auto& st : rl.stations) {
    if (st.fixed_block) {
      add(LocationClass::kPlatform, st.name + " fixed-block entry", st.platform.begin_mm, mb::margin_fixed_block_mm);
    }
    add(LocationClass::kPlatform, st.name + " stop", st.stop_mm, 0);
  }
  for (const auto& r : rl.routes) {
    add(LocationClass::kRouteEnd, "route " + std::to_string(r.id) + " entrance", r.section.begin_mm,
        mb::margin_route_end_mm);
  }
  for (const auto& h : rl.handovers) {
    add(LocationClass::kHandover, "handover " + h.id, h.position_mm, mb::margin_handover_mm);
  }
  if (rl.system_boundary_mm) {
    add(LocationClass::kSystemBoundary, "system boundary", *rl.system_boundary_mm, mb::margin_system_boundary_mm);
  }
  for (const auto& lc : rl.level_crossings) {
    // The protection pattern ends at the crossing itself (D5 §5.3).
    add(LocationClass::kLevelCrossing, "level crossing " + lc.id, lc.position_mm, 0);
  }
  add(LocationClass::kEndOfTrack, "end of track", rl.length_mm, mb::margin_end_of_track_mm);
  // Possession start and preceding-train rear may be anywhere: virtual-block boundaries and
  // every gradient / speed-limit change, at the change and one train length either side.
  std::map<std::int64_t, std::string> anywhere;
  for (const std::int64_t b : rl.blocks_mm) {
    anywhere.emplace(b, "block boundary at " + Metres(b));
  }
  auto change = [&](std::int64_t c, const char* what) {
    anywhere.emplace(c, std::string(what) + " change at " + Metres(c));
    anywhere.emplace(c - train_length_mm, std::string(what) + " change at " + Metres(c) + " - train length");
    anywhere.emplace(c + train_length_mm, std::string(what) + " change at " + Metres(c) + " + train length");
  };
  for (std::size_t i = 1; i < rl.gradients.size(); ++i) {
    change(rl.gradients[i].section.begin_mm, "gradient");
  }
  for (std::size_t i = 1; i < rl.speed_limits.size(); ++i) {
    change(rl.speed_limits[i].section.begin_mm, "speed limit");
  }
  for (const auto& [pos, id] : anywhere) {
    if (pos <= 0 || pos > rl.length_mm) {
      continue;
    }
    add(LocationClass::kPossession, "possession start: " + id, pos, mb::margin_possession_mm);
    add(LocationClass::kPrecedingTrain, "preceding train rear: " + id, pos, mb::margin_preceding_train_mm);
  }
  LocationSet out;
  for (auto& l : all) {
    (l.stop_limit_mm < min_approach_mm ? out.skipped : out.analysed).push_back(std::move(l));
  }
  return out;
}

std::int64_t SpeedErrorModel::Bound(std::int64_t true_speed_mm_s) const {
  return SpeedErrorBoundMmS(design, std::max<std::int64_t>(true_speed_mm_s, 0));
}

SpeedErrorModel ReferenceSpeedErrorModel() {
  SpeedErrorModel m;
  m.design = OptimumSpeedCheckDesign(ReferenceSpeedCheckInputs());
  // dV(v) = ceil(v / n_1F + dynamic): slope 1 / n_1F; the offset is the largest excess over
  // that slope at any integer speed up to 1000 km/h (an upper envelope for the NLP).
  m.c1 = 1.0 / static_cast<double>(m.design.n_1f);
  double c0 = 0.0;
  for (std::int64_t v = 0; v <= 280'000; ++v) {
    c0 = std::max(c0, static_cast<double>(m.Bound(v)) - m.c1 * static_cast<double>(v));
  }
  m.c0_mm_s = c0;
  return m;
}

// @implements REQ-SC-005 REQ-BR-007
std::string SpeedAllowanceFinding(const TrainType& t, const SpeedErrorModel& m) {
  const AllowanceCheck c = AllowanceCovers(m.design, t.speed_error_ppm, t.speed_error_abs_mm_s, t.MaxSpeedMmS());
  if (c.Covered()) {
    return "";
  }
  return t.file + ": supervision: the allowance (speed_error_ppm " + std::to_string(t.speed_error_ppm) +
         ", speed_error_abs_mm_s " + std::to_string(t.speed_error_abs_mm_s) +
         ") does not cover the D3 speed-error bound: short by " + std::to_string(c.worst_shortfall_mm_s) +
         " mm/s at " + std::to_string(c.at_speed_mm_s) + " mm/s (REQ-SC-005)";
}

// ---------------------------------------------------------------------------------------
MarginModel::MarginModel(const offline::RunningLine& rl, const TrainType& train, const SpeedErrorModel& speed_error)
    : rl_(&rl), train_(train), speed_error_(speed_error), params_(br::DefaultSupervisionParams()) {
  // Position error (D1 §3 item 7): length correction over the longest balise spacing
  // (line ends included) plus the permanent re-adhesion margin.
  std::int64_t spacing = 0;
  std::int64_t prev = 0;
  for (const auto& b : rl.balises) {
    spacing = std::max(spacing, b.position_mm - prev);
    prev = b.position_mm;
  }
  spacing = std::max(spacing, rl.length_mm - prev);
  balise_spacing_mm_ = spacing;
  position_error_mm_ = (train.odometry_ppm * spacing + 999'999) / 1'000'000 + train.readhesion_margin_mm;

  // Runtime pattern calculator with the whole running line as its profile.
  const std::vector<br::GradientSegment> grads = GradientProfile(rl);
  restrictions_ = PermittedProfile(rl, 0);
  const std::size_t cap = std::max<std::size_t>({grads.size(), restrictions_.size(), 1}) + 1;
  auto created = br::PatternCalculator::Create(ToTrainData(train), params_, cap);
  if (created.error != br::CreateError::kNone) {
    throw offline::InputError(train.file + ": train data refused by the runtime pattern calculator: " +
                          br::ToString(created.error));
  }
  calc_.emplace(std::move(*created.calculator));
  const br::ProfileResult pr = calc_->SetProfile(grads, restrictions_);
  if (pr.verdict != br::ProfileVerdict::kAccept) {
    throw offline::InputError("running line " + rl.id + ": profile refused by the runtime pattern calculator: " +
                          br::ToString(pr.verdict) + " at " + (pr.in_restrictions ? "speed_limits[" : "gradients[") +
                          std::to_string(pr.entry) + "] (train " + train.name + ")");
  }

  // Most falling data gradient under the train (front - length, front]: a segment [b, e)
  // acts on fronts in [b, e + length). Before the line the first gradient continues, after
  // it the last.
  std::set<std::int64_t> cuts;
  for (const auto& g : grads) {
    cuts.insert(g.begin_mm);
    cuts.insert(g.end_mm + train.length_mm);
  }
  piece_start_.push_back(-std::numeric_limits<double>::infinity());
  piece_g_.push_back(grads.empty() ? 0 : grads.front().permille_x10);
  for (const std::int64_t c : cuts) {
    std::int64_t g_min = std::numeric_limits<std::int64_t>::max();
    for (const auto& g : grads) {
      if (g.begin_mm <= c && c < g.end_mm + train.length_mm) {
        g_min = std::min(g_min, g.permille_x10);
      }
    }
    if (g_min == std::numeric_limits<std::int64_t>::max()) {
      g_min = grads.empty() ? 0 : grads.back().permille_x10;
    }
    if (g_min != piece_g_.back()) {
      piece_start_.push_back(static_cast<double>(c));
      piece_g_.push_back(g_min);
    }
  }

  // Approach: the farthest check position from which a train at its maximum speed could
  // still reach L (run-up and braking at the steepest falling gradient of the line).
  std::int64_t g_low = 0;
  for (const auto g : piece_g_) {
    g_low = std::min(g_low, g);
  }
  const double grade = GradeDecel(static_cast<double>(g_low - params_.gradient_error_x10) / 10.0, Gravity());
  const double t = static_cast<double>(params_.cycle_ms + params_.reaction_ms + train.emergency_free_running_ms.max) / 1000.0;
  const double b = static_cast<double>(train.emergency_deceleration_mm_s2.min) + grade;
  if (b <= 0.0) {
    throw offline::InputError(train.file + ": uncertainty.emergency_deceleration_mm_s2: the lowest real deceleration " +
                          "does not stop the train on the steepest falling gradient of running line " + rl.id);
  }
  const Motion run_up = Advance({0.0, static_cast<double>(train.MaxSpeedMmS())},
                                static_cast<double>(train.accel_max_mm_s2) - grade, t);
  approach_mm_ = static_cast<std::int64_t>(std::ceil(run_up.position + StoppingDistance(run_up.speed, b, 0.0))) + 1000;
}

double MarginModel::Gravity() const { return static_cast<double>(params_.gravity_mm_s2); }

double MarginModel::Grade(std::size_t piece, const Adversary& adv) const {
  return GradeDecel((static_cast<double>(piece_g_[piece]) + adv.gradient_error_x10) / 10.0, Gravity());
}

double MarginModel::GradientUnderTrain(double front_mm) const {
  const auto it = std::upper_bound(piece_start_.begin(), piece_start_.end(), front_mm);
  return static_cast<double>(piece_g_[static_cast<std::size_t>(it - piece_start_.begin()) - 1]);
}

double MarginModel::EmergencyCeilingMmS(double y) const {
  const double ext = static_cast<double>(train_.length_mm + 2 * position_error_mm_);
  const double over = static_cast<double>(SpeedKmhToMmS(train_.emergency_overspeed_kmh));
  double c = static_cast<double>(params_.max_speed_mm_s);
  for (const auto& r : restrictions_) {
    if (static_cast<double>(r.begin_mm) <= y && y < static_cast<double>(r.end_mm) + ext) {
      c = std::min(c, static_cast<double>(r.limit_mm_s) + over);
    }
  }
  return c;
}

Adversary MarginModel::WorstCorner() const {
  Adversary a;
  a.beta_mm_s2 = static_cast<double>(train_.emergency_deceleration_mm_s2.min);
  a.free_running_ms = static_cast<double>(train_.emergency_free_running_ms.max);
  a.gradient_error_x10 = -static_cast<double>(params_.gradient_error_x10);
  a.runup_cycle_ms = static_cast<double>(params_.cycle_ms);
  a.traction = 1.0;
  a.position_error_mm = static_cast<double>(position_error_mm_);
  a.speed_error_sign = 1.0;
  return a;
}

double MarginModel::TrueSpeedMax(std::int64_t v_m) const {
  if (v_m <= 0) {
    return 0.0;
  }
  std::int64_t v = v_m;
  for (int i = 0; i < 64; ++i) {
    const std::int64_t next = v_m + speed_error_.Bound(v);
    if (next == v) {
      break;
    }
    v = next;
  }
  return static_cast<double>(std::min(v, train_max_speed_mm_s()));
}

std::optional<std::int64_t> MarginModel::MaxMeasuredSpeed(std::int64_t v_e) const {
  const std::int64_t abs = train_.speed_error_abs_mm_s;
  if (v_e < calc_->SupervisedSpeed(1)) {
    return std::nullopt;
  }
  std::int64_t v = std::max<std::int64_t>(1, (v_e - abs) * 1'000'000 / (1'000'000 + train_.speed_error_ppm));
  while (calc_->SupervisedSpeed(v + 1) <= v_e) {
    ++v;
  }
  while (v > 1 && calc_->SupervisedSpeed(v) > v_e) {
    --v;
  }
  return v;
}

// Exact integration over the piecewise-constant gradient under the train (the offline
// train-motion model, dynamics.hpp).
Trajectory MarginModel::Simulate(double true_front_mm, double true_speed_mm_s, const Adversary& adv,
                                 bool keep_points) const {
  Trajectory tr;
  tr.true_front_mm = true_front_mm;
  tr.true_speed_mm_s = true_speed_mm_s;
  tr.adversary = adv;
  const double amax = static_cast<double>(train_.accel_max_mm_s2) * adv.traction;
  const double t_run = (adv.runup_cycle_ms + static_cast<double>(params_.reaction_ms) + adv.free_running_ms) / 1000.0;
  tr.run_up_ms = t_run * 1000.0;
  Motion m{true_front_mm, std::max(0.0, true_speed_mm_s)};
  std::size_t k = static_cast<std::size_t>(std::upper_bound(piece_start_.begin(), piece_start_.end(), m.position) -
                                           piece_start_.begin()) - 1;
  const std::size_t n = piece_start_.size();
  const auto piece_end = [&] { return k + 1 < n ? piece_start_[k + 1] : std::numeric_limits<double>::infinity(); };
  auto point = [&](const Motion& p) {
    if (keep_points) {
      tr.points.emplace_back(p.position, p.speed);
    }
  };
  point(m);
  // run-up: traction against the gradient for t_run (a train that stops on a rise stands)
  for (double t = 0.0; t < t_run;) {
    const double a = amax - Grade(k, adv);
    const double end = piece_end();
    const Motion next = Advance(m, a, t_run - t);
    if (next.position <= end) {
      if (keep_points) {
        for (int i = 1; i < 8; ++i) {
          point(Advance(m, a, (t_run - t) * i / 8.0));
        }
      }
      m = next;
      point(m);
      break;
    }
    const double v_end = SpeedAfter(m.speed, a, end - m.position);
    t += TimeOver(end - m.position, m.speed, v_end);
    m = {end, v_end};
    ++k;
    point(m);
  }
  tr.brake_front_mm = m.position;
  tr.brake_speed_mm_s = m.speed;
  // braking with beta on the gradient until standstill
  while (m.speed > 0.0) {
    const double b = adv.beta_mm_s2 + Grade(k, adv);
    const double end = piece_end();
    if (b <= 0.0 && std::isinf(end)) {  // never stops
      m.position = std::numeric_limits<double>::infinity();
      break;
    }
    const double s = b > 0.0 ? StoppingDistance(m.speed, b, 0.0) : std::numeric_limits<double>::infinity();
    if (m.position + s <= end) {
      if (keep_points) {
        for (int i = 1; i < 16; ++i) {
          const double si = s * i / 16.0;
          point({m.position + si, SpeedAfter(m.speed, -b, si)});
        }
      }
      m = {m.position + s, 0.0};
      point(m);
      break;
    }
    m = {end, SpeedAfter(m.speed, -b, end - m.position)};
    ++k;
    point(m);
  }
  tr.stop_mm = m.position;
  return tr;
}

// ---------------------------------------------------------------------------------------
// @implements REQ-BR-009 REQ-BR-011 REQ-BR-014
GridResult GridWorstCase(const MarginModel& m, const Location& loc, std::int64_t resolution_mm) {
  if (resolution_mm <= 0) {
    throw std::invalid_argument("grid resolution must be positive");
  }
  const br::PatternCalculator& calc = m.patterns();
  const std::int64_t e = m.position_error_mm();
  const std::int64_t l = loc.stop_limit_mm;
  const Adversary adv = m.WorstCorner();
  // standstill start: the state v_m = 0 with standstill (v_s = 0) passes the check whenever
  // V_e >= 0; its reach (run-up from rest plus braking) is a few metres, so only check
  // positions within 100 m of L are evaluated for it.
  const double reach_mm = 100000.0;
  GridResult out;
  out.margin_mm = std::numeric_limits<double>::infinity();
  std::vector<std::tuple<double, std::int64_t, double>> curve;  // (x_s, v_m, margin)
  double best_x = static_cast<double>(l);
  std::int64_t best_vm = 0;
  bool best_standstill = false;
  double best_moving_x = static_cast<double>(l);
  std::int64_t best_moving_vm = 0;
  out.moving_margin_mm = std::numeric_limits<double>::infinity();
  out.standstill_margin_mm = std::numeric_limits<double>::infinity();
  const std::int64_t n = m.approach_mm() / resolution_mm;
  for (std::int64_t i = 0; i <= n; ++i) {
    const std::int64_t xs = l - i * resolution_mm;
    const std::int64_t ve = calc.EmergencyPatternSpeed(xs, l, e, e);
    double margin = std::numeric_limits<double>::infinity();
    std::int64_t vm_used = 0;
    bool standstill = false;
    if (const auto vm = m.MaxMeasuredSpeed(ve)) {
      const Trajectory t = m.Simulate(static_cast<double>(xs), m.TrueSpeedMax(*vm), adv, false);
      margin = static_cast<double>(l) - t.stop_mm;
      vm_used = *vm;
      if (margin < out.moving_margin_mm) {
        out.moving_margin_mm = margin;
        best_moving_x = static_cast<double>(xs);
        best_moving_vm = *vm;
      }
    }
    if (ve >= 0 && static_cast<double>(l - xs) <= reach_mm) {
      const Trajectory t = m.Simulate(static_cast<double>(xs), 0.0, adv, false);
      const double ms = static_cast<double>(l) - t.stop_mm;
      out.standstill_margin_mm = std::min(out.standstill_margin_mm, ms);
      if (ms < margin) {
        margin = ms;
        vm_used = 0;
        standstill = true;
      }
    }
    ++out.checks;
    curve.emplace_back(static_cast<double>(xs), vm_used, margin);
    if (margin < out.margin_mm) {
      out.margin_mm = margin;
      best_x = static_cast<double>(xs);
      best_vm = vm_used;
      best_standstill = standstill;
    }
  }
  // local minima (seeds of the NLP), worst first, at least 20 m apart
  std::vector<std::tuple<double, std::int64_t, double>> minima;
  for (std::size_t i = 0; i < curve.size(); ++i) {
    const double mi = std::get<2>(curve[i]);
    const bool left = i == 0 || mi <= std::get<2>(curve[i - 1]);
    const bool right = i + 1 == curve.size() || mi <= std::get<2>(curve[i + 1]);
    if (left && right && std::get<1>(curve[i]) > 0 && std::isfinite(mi)) {
      minima.push_back(curve[i]);
    }
  }
  std::sort(minima.begin(), minima.end(), [](const auto& a, const auto& b) { return std::get<2>(a) < std::get<2>(b); });
  for (const auto& c : minima) {
    bool far = true;
    for (const auto& k : out.minima) {
      far = far && std::abs(std::get<0>(k) - std::get<0>(c)) > 20000.0;
    }
    if (far) {
      out.minima.push_back(c);
    }
    if (out.minima.size() >= 4) {
      break;
    }
  }
  const double v0 = best_standstill ? 0.0 : m.TrueSpeedMax(best_vm);
  out.worst = m.Simulate(best_x, v0, adv, true);
  out.worst.check_front_mm = best_x;
  out.worst.measured_speed_mm_s = best_vm;
  out.worst.supervised_speed_mm_s = calc.SupervisedSpeed(best_vm, best_standstill);
  out.worst.pattern_speed_mm_s = calc.EmergencyPatternSpeed(static_cast<std::int64_t>(best_x), l, e, e);
  out.worst.standstill_start = best_standstill;
  out.worst_moving = m.Simulate(best_moving_x, m.TrueSpeedMax(best_moving_vm), adv, true);
  out.worst_moving.check_front_mm = best_moving_x;
  out.worst_moving.measured_speed_mm_s = best_moving_vm;
  out.worst_moving.supervised_speed_mm_s = calc.SupervisedSpeed(best_moving_vm);
  out.worst_moving.pattern_speed_mm_s = calc.EmergencyPatternSpeed(static_cast<std::int64_t>(best_moving_x), l, e, e);
  return out;
}

}  // namespace railproof::br::analysis
