// libFuzzer target: the timetable loader of warning_study (lc::analysis::ParseTimetable and
// the fit to the line and train types, lc::analysis::CheckTimetable; cpp/offline/lc/src/
// warning_study_timetable.cpp) on any bytes, structure-aware (json_fuzz.hpp). Seeds: the
// committed corpus and the generated timetables (build/gen/timetables); the line and train
// types are the generated ones. Oracle: every rejection is the project's input error in the
// one form "<file>: <entry>: <reason>", no crash and no undefined behaviour (ASan+UBSan), and
// an accepted timetable holds the values the study computes with within their ranges
// ([min, max] pairs ordered) and names its train types by plain names.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "json_fuzz.hpp"
#include "railproof/lc/analysis/warning_study.hpp"

namespace {

namespace an = railproof::lc::analysis;
namespace off = railproof::offline;
using railproof::fuzz::Require;

const std::string kFile = "timetable.json";

const off::Line& StudyLine() {
  static const off::Line line = off::LoadLine(RAILPROOF_FUZZ_LINE);
  return line;
}

const std::map<std::string, off::TrainType>& Trains() {
  static const std::map<std::string, off::TrainType> trains = [] {
    std::map<std::string, off::TrainType> out;
    for (const auto& e : std::filesystem::directory_iterator(RAILPROOF_FUZZ_TRAINS_DIR)) {
      if (e.is_regular_file() && e.path().extension() == ".json") {
        off::TrainType t = off::LoadTrainType(e.path());
        out.emplace(t.name, std::move(t));
      }
    }
    return out;
  }();
  return trains;
}

bool Ordered(const an::RangeMs& r, std::int64_t lo, std::int64_t hi) { return lo <= r.min && r.min <= r.max && r.max <= hi; }

void CheckAccepted(const an::Timetable& tt) {
  Require(!tt.services.empty(), "a service");
  Require(tt.planned_time_step_ms >= 1 && tt.running_time_allowance_percent >= 0 && tt.running_time_allowance_percent <= 100,
          "planning values within their ranges");
  Require(50 <= tt.driver.cruise_min_percent && tt.driver.cruise_min_percent <= tt.driver.cruise_max_percent &&
              tt.driver.cruise_max_percent <= 100 && Ordered(tt.driver.start_delay_ms, 0, 600'000),
          "driver model within its ranges");
  Require(Ordered(tt.comms.uplink_ms, 0, 60'000) && Ordered(tt.comms.downlink_ms, 0, 60'000) &&
              Ordered(tt.comms.barrier_travel_ms, 0, 60'000) && Ordered(tt.comms.report_latency_ms, 0, 60'000) &&
              tt.comms.ground_cycle_ms >= 1 && tt.comms.onboard_cycle_ms >= 1,
          "communication model within its ranges");
  for (const an::Service& s : tt.services) {
    Require(0 <= s.depart_ms && s.depart_ms < 2LL * 24 * 3'600'000, "departure within two days");
    Require(!s.train.empty() && s.train.find_first_of("/\\") == std::string::npos, "train type a plain name");
    for (const an::ServiceStop& stop : s.stops) {
      Require(0 <= stop.dwell_ms && stop.dwell_ms <= 3'600'000, "dwell within an hour");
    }
  }
  an::CheckTimetable(tt, StudyLine(), Trains());
}

}  // namespace

RAILPROOF_FUZZ_JSON_MUTATOR()

// @verifies REQ-LC-017
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  (void)StudyLine();  // loaded before the first input: their errors are not the timetable's
  (void)Trains();
  return railproof::fuzz::TestOneInput(kFile, data, size,
                                       [](const std::string& text) { CheckAccepted(an::ParseTimetable(text, kFile)); });
}
