// Odometry study: analysis of recorded odometry runs — compensation episodes, event
// matching, true distance error against the error bound, envelope check
// (odometry_study.hpp; spec/design/ra.md §5, §6, §8).
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "railproof/ra/analysis/odometry_study.hpp"
#include "railproof/generated/ra_params.hpp"

namespace railproof::ra::analysis {

namespace rp = params::ra;
using ra::Mode;
using ra::StopReason;

const char* ToString(EpisodeOutcome o) noexcept {
  switch (o) {
    case EpisodeOutcome::kAdopted: return "adopted";
    case EpisodeOutcome::kTimeout: return "timeout";
    case EpisodeOutcome::kSensorFailure: return "sensor_failure";
    case EpisodeOutcome::kOpen: return "open";
  }
  return "invalid";
}

namespace {

// Lowest-index active candidate of a machine state, -1 if none (the nominal front's source).
int NominalCandidate(const ra::MachineState& m) {
  for (int c = 0; c < ra::kMaxStartPoints; ++c) {
    if (m.candidates[static_cast<std::size_t>(c)].active) {
      return c;
    }
  }
  return -1;
}

double Mm(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }

double MaxGradient(const std::vector<StudyCycle>& run, std::size_t a, std::size_t b) {
  double g = 0.0;
  for (std::size_t k = a; k <= b && k < run.size(); ++k) {
    g = std::max(g, std::abs(run[k].gradient_permille));
  }
  return g;
}

double Ratio(double err, double bound) {
  if (bound > 0.0) {
    return std::abs(err) / bound;
  }
  return err == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
}

}  // namespace

std::vector<Episode> FindEpisodes(const std::vector<StudyCycle>& run) {
  std::vector<Episode> eps;
  for (std::size_t i = 0; i < run.size(); ++i) {
    if (!run[i].machine.detected) {
      continue;
    }
    Episode ep;
    ep.index = static_cast<int>(eps.size());
    ep.detect = i;
    ep.start_age_cycles = run[i].out.start_age_cycles;
    std::size_t j = i;
    if (run[i].machine.mode == Mode::kCompensating) {
      j = i + 1;
      while (j < run.size() && run[j].machine.mode == Mode::kCompensating) {
        ++j;
      }
    }
    if (j >= run.size()) {
      ep.end = run.size() - 1;
      ep.outcome = EpisodeOutcome::kOpen;
    } else {
      ep.end = j;
      const ra::MachineState& m = run[j].machine;
      if (m.adopted != ra::kNoCandidate) {
        ep.outcome = EpisodeOutcome::kAdopted;
        ep.adopted = m.adopted;
      } else if (m.mode == Mode::kStopped && m.stop_reason == StopReason::kMaxCompensationTime) {
        ep.outcome = EpisodeOutcome::kTimeout;
      } else if (m.mode == Mode::kStopped) {
        ep.outcome = EpisodeOutcome::kSensorFailure;
      } else {
        ep.outcome = EpisodeOutcome::kOpen;  // not reachable by the machine (left without adoption)
      }
    }
    // compensation time: of the adopted candidate at adoption, else of the nominal candidate
    // in the last compensating cycle
    if (ep.outcome == EpisodeOutcome::kAdopted) {
      const auto c = static_cast<std::size_t>(ep.adopted);
      ep.candidate = ep.adopted;
      ep.comp_cycles = run[ep.end - 1].machine.candidates[c].age_cycles + 1;
    } else {
      const std::size_t last = ep.outcome == EpisodeOutcome::kOpen ? ep.end : (ep.end > i ? ep.end - 1 : i);
      const int c = NominalCandidate(run[last].machine);
      ep.candidate = std::max(c, 0);
      ep.comp_cycles = c >= 0 ? run[last].machine.candidates[static_cast<std::size_t>(c)].age_cycles
                              : ep.start_age_cycles;
    }
    ep.max_compensation_ms =
        static_cast<std::int64_t>(run[ep.end].machine.max_compensation_cycles) * rp::cycle_ms;
    eps.push_back(ep);
    i = ep.end;  // detection happens only in kTg, never inside an episode or in its last cycle
  }
  return eps;
}

std::int64_t DefaultMatchWindowMs() noexcept {
  return rp::moving_average_ms + (rp::confirm_cycles + 1) * rp::cycle_ms;
}

std::vector<int> MatchEvents(const std::vector<TruthEvent>& events, const std::vector<StudyCycle>& run,
                             const std::vector<Episode>& episodes, std::int64_t match_window_ms) {
  std::vector<int> match(events.size(), -1);
  for (std::size_t e = 0; e < events.size(); ++e) {
    const TruthEvent& ev = events[e];
    // already compensating when the event starts: the running episode covers it
    for (const Episode& ep : episodes) {
      if (run[ep.detect].time_ms <= ev.start_ms && ev.start_ms <= run[ep.end].time_ms) {
        match[e] = ep.index;
        break;
      }
    }
    if (match[e] >= 0) {
      continue;
    }
    for (const Episode& ep : episodes) {
      const std::int64_t t = run[ep.detect].time_ms;
      if (t >= ev.start_ms && t <= ev.end_ms + match_window_ms) {
        match[e] = ep.index;
        break;
      }
    }
  }
  return match;
}

std::vector<int> EpisodeCauses(const std::vector<TruthEvent>& events, const std::vector<StudyCycle>& run,
                               const std::vector<Episode>& episodes, std::int64_t match_window_ms) {
  std::vector<int> cause(episodes.size(), -1);
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    const std::int64_t t = run[episodes[i].detect].time_ms;
    std::int64_t best_start = 0;
    for (std::size_t e = 0; e < events.size(); ++e) {
      const TruthEvent& ev = events[e];
      if (t >= ev.start_ms && t <= ev.end_ms + match_window_ms && (cause[i] < 0 || ev.start_ms >= best_start)) {
        cause[i] = static_cast<int>(e);
        best_start = ev.start_ms;
      }
    }
  }
  return cause;
}

std::size_t ErrorReference(const std::vector<StudyCycle>& run, std::size_t s, std::size_t k) {
  std::size_t ref = s;
  for (std::size_t j = s + 1; j <= k && j < run.size(); ++j) {
    if (run[j].balise && run[j].out.position_valid) {
      ref = j;
    }
  }
  return ref;
}

EpisodeError EvaluateEpisode(const std::vector<StudyCycle>& run, const Episode& ep, double rate_error_deg_s,
                             const std::vector<double>& tg_distance_m) {
  EpisodeError r;
  const double cycle_s = static_cast<double>(rp::cycle_ms) / 1000.0;
  // worst ratio of the nominal candidate over the compensating cycles
  for (std::size_t k = ep.detect; k <= ep.end && k < run.size(); ++k) {
    const ra::MachineState& m = run[k].machine;
    if (m.mode != Mode::kCompensating) {
      continue;
    }
    const int c = NominalCandidate(m);
    if (c < 0) {
      continue;
    }
    const std::int32_t age = m.candidates[static_cast<std::size_t>(c)].age_cycles;
    if (age < 1 || static_cast<std::size_t>(age) > k) {
      continue;
    }
    const std::size_t s = k - static_cast<std::size_t>(age);
    const std::size_t ref = ErrorReference(run, s, k);
    const double err = (Mm(run[k].out.front_mm) - Mm(run[ref].out.front_mm)) -
                       (run[k].true_front_m - run[ref].true_front_m);
    const double bound =
        ra::ErrorBoundM(static_cast<double>(age) * cycle_s, MaxGradient(run, s, k), rate_error_deg_s);
    r.worst_ratio_during = std::max(r.worst_ratio_during, Ratio(err, bound));
  }
  // the interval of the episode's result
  std::size_t e = 0;
  if (ep.outcome == EpisodeOutcome::kAdopted || ep.outcome == EpisodeOutcome::kOpen) {
    e = ep.end;
  } else if (ep.end > ep.detect) {
    e = ep.end - 1;  // last compensating cycle before the stop
  } else {
    return r;  // timed out at detection: no compensating cycle
  }
  if (ep.comp_cycles < 1 || static_cast<std::size_t>(ep.comp_cycles) > e) {
    return r;
  }
  const std::size_t s = e - static_cast<std::size_t>(ep.comp_cycles);
  r.valid = true;
  r.start = s;
  r.stop = e;
  r.comp_time_s = static_cast<double>(ep.comp_cycles) * cycle_s;
  r.gradient_permille = MaxGradient(run, s, e);
  const std::size_t ref = ErrorReference(run, s, e);
  r.balise_in_interval = ref != s;
  r.reference = ref;
  r.odometry_distance_m = Mm(run[e].out.front_mm) - Mm(run[ref].out.front_mm);
  r.true_distance_m = run[e].true_front_m - run[ref].true_front_m;
  r.error_m = r.odometry_distance_m - r.true_distance_m;
  r.bound_m = ra::ErrorBoundM(r.comp_time_s, r.gradient_permille, rate_error_deg_s);
  r.ratio = Ratio(r.error_m, r.bound_m);
  if (tg_distance_m.size() == run.size()) {
    r.tg_error_m = (tg_distance_m[e] - tg_distance_m[s]) - (run[e].true_front_m - run[s].true_front_m);
  }
  return r;
}

EnvelopeCheck CheckEnvelope(const std::vector<StudyCycle>& run) {
  EnvelopeCheck c;
  c.min_front_slack_m = std::numeric_limits<double>::infinity();
  c.min_rear_slack_m = std::numeric_limits<double>::infinity();
  for (const StudyCycle& cy : run) {
    if (!cy.out.position_valid) {
      continue;
    }
    ++c.cycles_checked;
    const double front = Mm(cy.out.front_mm);
    const double front_slack = Mm(cy.out.front_error_mm) - (cy.true_front_m - front);
    const double rear_slack = Mm(cy.out.rear_error_mm) - (front - cy.true_front_m);
    c.min_front_slack_m = std::min(c.min_front_slack_m, front_slack);
    c.min_rear_slack_m = std::min(c.min_rear_slack_m, rear_slack);
    const double excess = std::max(-front_slack, -rear_slack);
    if (excess > 0.0) {
      ++c.violations;
      c.worst_excess_m = std::max(c.worst_excess_m, excess);
      if (c.first_violation_ms < 0) {
        c.first_violation_ms = cy.time_ms;
      }
    }
  }
  if (c.cycles_checked == 0) {
    c.min_front_slack_m = 0.0;
    c.min_rear_slack_m = 0.0;
  }
  return c;
}

}  // namespace railproof::ra::analysis
