// Odometry study on the Box2D wheel-rail scenarios (odometry_study.hpp): simulate, replay
// the odometry in three configurations (IMU with the configured start points, IMU with one,
// the former max/min-acceleration method) and check the results.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "railproof/ra/analysis/odometry_study.hpp"
#include "railproof/generated/ra_params.hpp"

namespace railproof::ra::analysis {

namespace rp = params::ra;
using ra::InputError;
using ra::Method;
using ra::Mode;
using ra::StopReason;

namespace {

std::string Fmt(const char* fmt, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, a);
  return buf;
}

double SumErrorsM(const ra::OdometryOutput& o) {
  return static_cast<double>(o.front_error_mm + o.rear_error_mm) / 1000.0;
}

// Steepest section gradient (permille) over the sections overlapping [rear, front].
double GradientUnder(const std::vector<ra::OdometrySection>& sections, double front_m, std::int64_t length_mm) {
  const auto front = static_cast<std::int64_t>(std::llround(front_m * 1000.0));
  const std::int64_t rear = front - length_mm;
  std::int32_t g = 0;
  for (const auto& s : sections) {
    if (s.begin_mm <= front && s.end_mm > rear) {
      g = std::max(g, s.gradient_permille_x10);
    }
  }
  return static_cast<double>(g) / 10.0;
}

std::string CauseOf(const StudyRun& r, std::size_t episode) {
  const int c = episode < r.episode_event.size() ? r.episode_event[episode] : -1;
  return c < 0 ? "no simulated slip/slide (spurious detection)" : "slip/slide phase " + std::to_string(c);
}

}  // namespace

InputError ExpectedInputError(ra::analysis::SensorFaultKind k) noexcept {
  switch (k) {
    case ra::analysis::SensorFaultKind::kTgDropout: return InputError::kTgPulsesDecreasing;
    case ra::analysis::SensorFaultKind::kTgStuck: return InputError::kNone;
    case ra::analysis::SensorFaultKind::kTgBurst: return InputError::kTgImplausibleRate;
    case ra::analysis::SensorFaultKind::kTgEdgeInvalid: return InputError::kTgEdgeInvalid;
    case ra::analysis::SensorFaultKind::kImuNan: return InputError::kImuNotFinite;
    case ra::analysis::SensorFaultKind::kImuGap: return InputError::kImuSampleCount;
    case ra::analysis::SensorFaultKind::kImuTimestamps: return InputError::kImuTimestamps;
    case ra::analysis::SensorFaultKind::kImuOutOfRange: return InputError::kImuOutOfRange;
    case ra::analysis::SensorFaultKind::kCycleTime: return InputError::kCycleTimeGap;
  }
  return InputError::kNone;
}

std::vector<SlipPhase> GroupSlipEvents(const std::vector<ra::analysis::SlipEvent>& events, std::int64_t gap_ms) {
  std::vector<int> order(events.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    order[i] = static_cast<int>(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return events[static_cast<std::size_t>(a)].start_ms < events[static_cast<std::size_t>(b)].start_ms;
  });
  std::vector<SlipPhase> phases;
  for (const int i : order) {
    const ra::analysis::SlipEvent& e = events[static_cast<std::size_t>(i)];
    const char* kind = ToString(e.kind);
    if (phases.empty() || e.start_ms > phases.back().end_ms + gap_ms) {
      SlipPhase p;
      p.id = static_cast<int>(phases.size());
      p.start_ms = e.start_ms;
      p.end_ms = e.end_ms;
      p.kind = kind;
      phases.push_back(p);
    }
    SlipPhase& p = phases.back();
    p.end_ms = std::max(p.end_ms, e.end_ms);
    if (p.kind != kind && p.kind != "slip+slide") {
      p.kind = "slip+slide";
    }
    p.events.push_back(i);
    if (std::find(p.axles.begin(), p.axles.end(), e.axle) == p.axles.end()) {
      p.axles.push_back(e.axle);
      std::sort(p.axles.begin(), p.axles.end());
    }
    p.tg_axle = p.tg_axle || e.tg_axle;
    if (std::abs(e.peak_creep) > std::abs(p.peak_creep)) {
      p.peak_creep = e.peak_creep;
    }
  }
  return phases;
}

std::vector<StudyCycle> ReplayOdometry(const ra::analysis::WheelRailRun& sim, const ra::OdometryConfig& cfg,
                                       const std::vector<ra::OdometrySection>& sections,
                                       const std::string& where) {
  if (sim.cycles.size() != sim.truth.size()) {
    throw offline::InputError(where + ": simulated run: " + std::to_string(sim.cycles.size()) + " cycles but " +
                          std::to_string(sim.truth.size()) + " truth records");
  }
  auto odo = std::make_unique<ra::Odometry>();  // ~128 KiB of fixed storage
  const ra::ConfigError err = ra::Odometry::Create(cfg, *odo);
  if (err != ra::ConfigError::kNone) {
    throw offline::InputError(where + ": odometry configuration: " + ra::ToString(err));
  }
  std::vector<StudyCycle> run;
  run.reserve(sim.cycles.size());
  for (std::size_t k = 0; k < sim.cycles.size(); ++k) {
    const ra::analysis::TruthCycle& t = sim.truth[k];
    StudyCycle c;
    c.time_ms = t.time_ms;
    c.true_front_m = t.front_m;
    c.true_speed_m_s = t.speed_mps;
    c.gradient_permille = GradientUnder(sections, t.front_m, cfg.train_length_mm);
    c.balise = sim.cycles[k].balise.has_value();
    c.out = odo->Step(sim.cycles[k]);
    c.machine = odo->machine().state();
    run.push_back(c);
  }
  return run;
}

StudyRun AnalyseRun(std::string label, const ra::OdometryConfig& cfg, std::vector<StudyCycle> cycles,
                    const ra::analysis::WheelRailRun& sim, const std::vector<TruthEvent>& events) {
  StudyRun r;
  r.label = std::move(label);
  r.config = cfg;
  r.config.sections = nullptr;  // the table belongs to the caller; count kept for the report
  r.cycles = std::move(cycles);
  r.episodes = FindEpisodes(r.cycles);
  std::vector<double> tg(r.cycles.size());
  for (std::size_t k = 0; k < tg.size() && k < sim.truth.size(); ++k) {
    tg[k] = sim.truth[k].tg_distance_m;
  }
  const double rate = static_cast<double>(cfg.imu_rate_error_udeg_s) / 1e6;
  for (const Episode& ep : r.episodes) {
    r.errors.push_back(EvaluateEpisode(r.cycles, ep, rate, tg));
    const EpisodeError& e = r.errors.back();
    if (cfg.method == Method::kImu && e.valid && ep.outcome == EpisodeOutcome::kAdopted &&
        (r.worst_episode < 0 || e.ratio > r.worst_ratio)) {
      r.worst_ratio = e.ratio;
      r.worst_episode = ep.index;
    }
  }
  r.event_episode = MatchEvents(events, r.cycles, r.episodes, DefaultMatchWindowMs());
  r.episode_event = EpisodeCauses(events, r.cycles, r.episodes, DefaultMatchWindowMs());
  r.envelope = CheckEnvelope(r.cycles);
  if (cfg.method == Method::kMaxMinAcceleration) {
    for (const Episode& ep : r.episodes) {
      BaselineEpisode b;
      const double before = SumErrorsM(r.cycles[ep.detect > 0 ? ep.detect - 1 : 0].out);
      std::size_t last_valid = ep.end;  // a stop invalidates the position in the end cycle
      while (last_valid > ep.detect && !r.cycles[last_valid].out.position_valid) {
        --last_valid;
      }
      b.extension_at_end_m = SumErrorsM(r.cycles[last_valid].out) - before;
      std::size_t stop = ep.end + 1;
      while (stop < r.cycles.size() && !r.cycles[stop].balise) {
        ++stop;
      }
      const std::vector<StudyCycle> window(r.cycles.begin() + static_cast<std::ptrdiff_t>(ep.detect),
                                           r.cycles.begin() + static_cast<std::ptrdiff_t>(stop));
      for (const StudyCycle& c : window) {
        if (c.out.position_valid) {
          b.max_extension_m = std::max(b.max_extension_m, SumErrorsM(c.out) - before);
        }
      }
      const EnvelopeCheck env = CheckEnvelope(window);
      b.cycles_checked = env.cycles_checked;
      b.violations = env.violations;
      b.worst_excess_m = env.worst_excess_m;
      r.baseline.push_back(b);
    }
  }
  return r;
}

namespace {

void CheckBound(ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  ScenarioCheck chk{"error_bound", true, ""};
  int evaluated = 0;
  for (std::size_t i = 0; i < r.episodes.size(); ++i) {
    const EpisodeError& e = r.errors[i];
    // REQ-RA-008: the error after compensation, i.e. at re-adhesion; a timeout or a sensor
    // failure invalidates the position instead (the envelope check covers its cycles)
    if (!e.valid || r.episodes[i].outcome != EpisodeOutcome::kAdopted) {
      continue;
    }
    ++evaluated;
    if (!(e.ratio <= 1.0)) {
      chk.ok = false;
      char buf[512];
      std::snprintf(buf, sizeof buf,
                    "%s: run %s: episode %zu (%s, detected at %lld ms, %s): true distance error "
                    "%.3f m exceeds the error bound %.3f m (t = %.1f s, g = %.1f permille), ratio %.3f",
                    st.scenario.name.c_str(), r.label.c_str(), i, CauseOf(r, i).c_str(),
                    static_cast<long long>(r.cycles[r.episodes[i].detect].time_ms), ToString(r.episodes[i].outcome),
                    e.error_m, e.bound_m, e.comp_time_s, e.gradient_permille, e.ratio);
      st.failures.emplace_back(buf);
    }
  }
  chk.detail = std::to_string(evaluated) + " re-adhesion(s) evaluated, worst ratio " + Fmt("%.4f", r.worst_ratio);
  st.checks.push_back(chk);
}

void CheckEnvelopeOf(ScenarioStudy& st, const StudyRun& r) {
  ScenarioCheck chk{"envelope_" + r.label, r.envelope.violations == 0, ""};
  chk.detail = std::to_string(r.envelope.cycles_checked) + " cycle(s) checked, " +
               std::to_string(r.envelope.violations) + " violation(s)";
  if (!chk.ok) {
    char buf[512];
    std::snprintf(buf, sizeof buf,
                  "%s: run %s: true front outside the reported envelope in %d of %d cycle(s), worst by %.3f m, "
                  "first at %lld ms",
                  st.scenario.name.c_str(), r.label.c_str(), r.envelope.violations, r.envelope.cycles_checked,
                  r.envelope.worst_excess_m, static_cast<long long>(r.envelope.first_violation_ms));
    st.failures.emplace_back(buf);
  }
  st.checks.push_back(chk);
}

// The start-up (REQ-RA-015), from the truth: no valid position before the end of the warm-up
// at standstill (moving averages plus the TG window). A train that stood through it (moved,
// and turned its TG wheel, less than one TG pulse) has its position from the warm-up's last
// cycle on; a train that moved or spun its TG wheel before (a start in motion) has none until
// it has stood for a warm-up and then read a balise, and its stop reason is START_IN_MOTION
// meanwhile. (A train that moved with its TG wheel locked through the warm-up, which ASM-031
// excludes, fails the check.)
void CheckStartUp(ScenarioStudy& st, const StudyRun& r) {
  constexpr std::size_t kWarmup = static_cast<std::size_t>((rp::moving_average_ms + rp::tg_window_ms) / rp::cycle_ms);
  ScenarioCheck chk{"start_up_" + r.label, false, ""};
  const auto& truth = st.sim.truth;
  const auto& cy = r.cycles;
  std::size_t first_valid = cy.size();
  for (std::size_t k = 0; k < cy.size(); ++k) {
    if (cy[k].out.position_valid) {
      first_valid = k;
      break;
    }
  }
  if (cy.size() < kWarmup || truth.size() != cy.size()) {
    chk.detail = "run shorter than the warm-up";
  } else if (truth[kWarmup - 1].distance_m < st.sim.pulse_length_m &&
             truth[kWarmup - 1].tg_distance_m - truth[0].tg_distance_m < st.sim.pulse_length_m) {
    // at standstill through the warm-up
    chk.ok = first_valid == kWarmup - 1 && cy[0].out.stop_reason == StopReason::kStartUp;
    chk.detail = "at standstill through the warm-up; first valid position at " +
                 (first_valid < cy.size() ? std::to_string(cy[first_valid].time_ms) + " ms" : std::string("none")) +
                 " (expected at the warm-up's end, " + std::to_string(cy[kWarmup - 1].time_ms) + " ms)";
  } else {
    // a start in motion: valid only at a balise after kWarmup cycles at standstill
    bool in_motion_reason = false;
    std::size_t rest = 0;
    bool rested = false;
    for (std::size_t k = 0; k < first_valid; ++k) {
      in_motion_reason = in_motion_reason || cy[k].out.stop_reason == StopReason::kStartInMotion;
      rest = truth[k].speed_mps == 0.0 || (k > 0 && truth[k].distance_m - truth[k - 1].distance_m < 1e-6) ? rest + 1 : 0;
      rested = rested || rest >= kWarmup;
    }
    chk.ok = in_motion_reason && (first_valid == cy.size() || (rested && cy[first_valid].balise));
    chk.detail = std::string("a start in motion (the train moved ") + Fmt("%.2f", truth[kWarmup - 1].distance_m) +
                 " m, its TG wheel " + Fmt("%.2f", truth[kWarmup - 1].tg_distance_m - truth[0].tg_distance_m) +
                 " m during the warm-up): " + (in_motion_reason ? "START_IN_MOTION" : "no START_IN_MOTION") +
                 ", first valid position " +
                 (first_valid < cy.size() ? "at " + std::to_string(cy[first_valid].time_ms) + " ms" +
                                                (cy[first_valid].balise ? " (balise)" : " (no balise)") +
                                                (rested ? ", after a standstill warm-up" : ", without a standstill warm-up")
                                          : std::string("never"));
  }
  if (!chk.ok) {
    st.failures.push_back(st.scenario.name + ": run " + r.label + ": start-up: " + chk.detail);
  }
  st.checks.push_back(chk);
}

void CheckSafeReaction(ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  if (!st.scenario.expect_safe_reaction) {
    return;
  }
  ScenarioCheck chk{"safe_reaction", false, ""};
  const Episode* timeout = nullptr;
  for (const Episode& ep : r.episodes) {
    if (ep.outcome == EpisodeOutcome::kTimeout) {
      timeout = &ep;
      break;
    }
  }
  std::string cause;
  if (timeout != nullptr) {
    const auto i = static_cast<std::size_t>(timeout->index);
    if (r.episode_event[i] >= 0) {
      cause = "; detection caused by slip/slide phase " + std::to_string(r.episode_event[i]);
    } else {
      cause = "; detection without a simulated slip/slide (spurious)";
      for (std::size_t e = 0; e < r.event_episode.size(); ++e) {
        if (r.event_episode[e] == timeout->index) {
          cause += ", phase " + std::to_string(e) + " began during the compensation";
        }
      }
    }
  }
  if (timeout == nullptr) {
    chk.detail = "no compensation reached the maximum compensation time";
  } else {
    const std::size_t k = timeout->end;
    bool held = true;
    std::size_t last = k;
    for (std::size_t j = k; j < r.cycles.size(); ++j) {
      if (j > k && r.cycles[j].balise) {
        break;  // re-established at a balise (ASM-026)
      }
      last = j;
      const auto& o = r.cycles[j].out;
      held = held && o.stop_demand && !o.position_valid;
    }
    const auto& o = r.cycles[k].out;
    chk.ok = o.stop_demand && !o.position_valid && o.stop_reason == StopReason::kMaxCompensationTime && held;
    chk.detail = "timeout at " + std::to_string(r.cycles[k].time_ms) + " ms (t_max " +
                 std::to_string(timeout->max_compensation_ms) + " ms): stop demand " + (o.stop_demand ? "yes" : "no") +
                 ", position " + (o.position_valid ? "valid" : "invalid") + ", reason " + ToString(o.stop_reason) +
                 ", held until " + std::to_string(r.cycles[last].time_ms) + " ms: " + (held ? "yes" : "no") + cause;
  }
  if (!chk.ok) {
    st.failures.push_back(st.scenario.name + ": expect_safe_reaction: " + chk.detail);
  }
  st.checks.push_back(chk);
}

// A scenario without injected sensor faults must not raise a detection that no simulated
// slip/slide caused (with two start points, the configured method). A spurious detection
// is not unsafe in itself (the envelope check covers that) but each one compensates from
// the IMU and moves the position; the check guards against the odometry's own signal
// processing creating deviations (e.g. a TG-history step coming back through A_p).
void CheckNoSpuriousDetection(ScenarioStudy& st) {
  if (!st.scenario.faults.empty()) {
    return;  // injected faults (a stuck TG) are detected as slides by design
  }
  const StudyRun& r = st.primary;
  ScenarioCheck chk{"no_spurious_detection", true, ""};
  int spurious = 0;
  std::string first;
  for (std::size_t i = 0; i < r.episode_event.size(); ++i) {
    if (r.episode_event[i] < 0) {
      if (spurious++ == 0) first = ", first at " + std::to_string(r.cycles[r.episodes[i].detect].time_ms) + " ms";
    }
  }
  chk.ok = spurious == 0;
  chk.detail = std::to_string(r.episodes.size()) + " detection(s), " + std::to_string(spurious) +
               " without a simulated slip/slide" + first;
  if (!chk.ok) {
    st.failures.push_back(st.scenario.name + ": spurious detection: " + chk.detail);
  }
  st.checks.push_back(chk);
}

void CheckSensorFaults(ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  for (std::size_t f = 0; f < st.scenario.faults.size(); ++f) {
    const ra::analysis::SensorFault& fault = st.scenario.faults[f];
    const InputError expected = ExpectedInputError(fault.kind);
    if (expected == InputError::kNone) {
      continue;  // not a validation failure (e.g. a stuck TG: detected as a slide)
    }
    const std::uint32_t bit = 1U << static_cast<unsigned>(fault.kind);
    ScenarioCheck chk{"sensor_fault_" + std::to_string(f) + "_" + ToString(fault.kind), false, ""};
    // the fault's first cycle: the first the simulator marks as affected (a fault is active
    // at the cycle instants inside [from_s, to_s))
    std::size_t first = r.cycles.size();
    for (std::size_t k = 0; k < st.sim.truth.size(); ++k) {
      if ((st.sim.truth[k].faults & bit) != 0U) {
        first = k;
        break;
      }
    }
    if (first >= r.cycles.size()) {
      chk.detail = "fault never active in the simulated run (no cycle instant inside [from_s, to_s))";
    } else {
      // the rejection is in the fault's first cycle or the next (a fault starting inside a
      // cycle shows in the cycle that contains it)
      std::size_t k = first;
      while (k < r.cycles.size() && k <= first + 1 && r.cycles[k].out.input_error == InputError::kNone) {
        ++k;
      }
      if (k >= r.cycles.size() || k > first + 1) {
        chk.detail = "no rejection within one cycle of the fault's start at " +
                     std::to_string(st.sim.truth[first].time_ms) + " ms";
      } else {
        const auto& o = r.cycles[k].out;
        const bool imu = ra::IsImuError(o.input_error);
        const StopReason want = imu ? StopReason::kImuFailure : StopReason::kTgFailure;
        const bool reason_ok = o.input_error == expected;
        const bool stop_ok = o.stop_reason == want ||
                             (expected == InputError::kCycleTimeGap && o.stop_reason != StopReason::kNone &&
                              o.stop_reason != StopReason::kMaxCompensationTime);
        chk.ok = reason_ok && stop_ok && o.stop_demand && !o.position_valid;
        chk.detail = "at " + std::to_string(o.time_ms) + " ms: input_error " + ra::ToString(o.input_error) +
                     " (expected " + ra::ToString(expected) + "), stop reason " + ToString(o.stop_reason) +
                     ", stop demand " + (o.stop_demand ? "yes" : "no") + ", position " +
                     (o.position_valid ? "valid" : "invalid");
      }
    }
    if (!chk.ok) {
      st.failures.push_back(st.scenario.name + ": fault " + std::to_string(f) + " (" + ToString(fault.kind) +
                            "): " + chk.detail);
    }
    st.checks.push_back(chk);
  }
}

}  // namespace

ScenarioStudy StudyScenario(const ra::analysis::WheelRailScenario& sc, const ra::analysis::WheelRailProgress& progress) {
  ScenarioStudy st;
  st.scenario = sc;
  st.sim = ra::analysis::SimulateWheelRail(sc, progress);
  st.sections = OdometrySectionsOf(sc);
  st.phases = GroupSlipEvents(st.sim.events, kPhaseGapMs);
  for (const SlipPhase& p : st.phases) {
    st.events.push_back(TruthEvent{p.id, p.kind, p.start_ms, p.end_ms});
  }
  ra::OdometryConfig base = OdometryConfigOf(sc, st.sections);
  // The odometry takes its initial front as the position at its first cycle (the initial
  // balise fix is read there), not at the scenario's t = 0.
  if (!st.sim.truth.empty()) base.initial_front_mm = std::llround(st.sim.truth.front().front_m * 1000.0);
  ra::OdometryConfig primary = base;
  primary.method = Method::kImu;
  ra::OdometryConfig single = primary;
  single.start_points = 1;
  ra::OdometryConfig baseline = primary;
  baseline.method = Method::kMaxMinAcceleration;
  const std::string where = sc.file;
  st.primary = AnalyseRun("imu_" + std::to_string(primary.start_points) + "sp", primary,
                          ReplayOdometry(st.sim, primary, st.sections, where), st.sim, st.events);
  st.single = AnalyseRun("imu_1sp", single, ReplayOdometry(st.sim, single, st.sections, where), st.sim, st.events);
  st.baseline =
      AnalyseRun("baseline", baseline, ReplayOdometry(st.sim, baseline, st.sections, where), st.sim, st.events);
  CheckBound(st);
  CheckEnvelopeOf(st, st.primary);
  CheckEnvelopeOf(st, st.single);
  CheckStartUp(st, st.primary);
  CheckStartUp(st, st.single);
  CheckSafeReaction(st);
  CheckSensorFaults(st);
  CheckNoSpuriousDetection(st);
  return st;
}

}  // namespace railproof::ra::analysis
