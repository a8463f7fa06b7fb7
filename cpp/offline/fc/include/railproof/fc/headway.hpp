// The D2 headway study (REQ-FC-009, spec/design/fc.md §8): the first two services of a
// timetable as leader and follower from their origin over their first stop (the studied
// station) to the next, in D2's three cases, the leader departing the station late by each
// delay of a sweep; per case the arrival-departure interval (follower's arrival at the station
// minus the leader's departure) of the moving-block baseline, the fixed-block baseline and the
// controlled follower, their minima and the reduction against the baseline. Offline module.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/fc/follower.hpp"
#include "railproof/lc/analysis/warning_study.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/train_type.hpp"

namespace railproof::fc {

struct StudyInput {
  const offline::Line* line = nullptr;
  const lc::analysis::Timetable* timetable = nullptr;
  const std::map<std::string, offline::TrainType>* trains = nullptr;
  std::vector<double> delays_s;  // the leader's late departures swept
};

struct PolicyRun {
  Policy policy = Policy::kMovingBlockBaseline;
  Run run;
  double interval_s = 0.0;  // follower arrival - leader departure (+inf: no arrival)
};

struct DelayRuns {
  double delay_s = 0.0;
  std::vector<PolicyRun> runs;  // in the order of Policy
};

struct CaseResult {
  Case which = Case::kLevelNoLimits;
  ApproachPoint approach;
  OutsideStop outside;
  double planned_arrival_s = 0.0, planned_departure_s = 0.0;  // leader at the station
  std::vector<DelayRuns> delays;
};

struct StudyResult {
  std::string station, origin, next;
  double interval_planned_s = 0.0;  // follower's planned arrival - leader's planned departure
  std::vector<CaseResult> cases;
};

// Checks the inputs (InputError "<file>: <entry>: <reason>") and runs every case.
// @implements REQ-FC-009 REQ-FC-011
StudyResult RunStudy(const StudyInput& in);

// The result JSON (schema railproof/fc-headway/1) and whether every check holds.
nlohmann::ordered_json StudyJson(const StudyResult& r, bool* pass);

// The time-distance diagram of one case at one delay (SVG).
std::string TimeDistanceSvg(const StudyResult& r, const CaseResult& c, const DelayRuns& d);

}  // namespace railproof::fc
