// warning_study: warning times of the level crossings of a line under a timetable for fixed
// treadles, on-board requests (without / with dwell awareness) and GNSS-time pre-arming
// (REQ-LC-017; spec/design/lc.md, spec/timetables/README.md).
//
// Exit status: 0 pass; 1 a warning of an on-board or GNSS-time method shorter than the
// design warning time, or a train braked by a crossing's protection pattern (contract
// method; each named on stderr); 2 bad usage or bad input (cli.hpp).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "railproof/offline/train_type.hpp"
#include "railproof/lc/analysis/warning_study.hpp"
#include "railproof/offline/cli.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/output_file.hpp"

namespace {

namespace an = railproof::lc::analysis;
using railproof::offline::InputError;

struct Options {
  std::string line, timetable, trains_dir, json, svg_dir;
  std::vector<double> lead_sweep_s;
  bool quiet = false;
};

Options ParseArgs(int argc, char** argv) {
  namespace off = railproof::offline;
  Options o;
  off::Cli cli("warning_study",
               "Warning-time study of level crossings (REQ-LC-017, also REQ-LC-002/005/008/015). Every\n"
               "service of the timetable is simulated on the line (the offline train-motion model\n"
               "without gradients, seeded driver variation); for every crossing it passes, the\n"
               "warning time (arrival at the near edge minus warning start) is computed for fixed\n"
               "treadles, the on-board request (runtime lc::onboard::CrossingProtection: without and\n"
               "with dwell awareness, and dwell-aware from the approach on) and GNSS-time pre-arming;\n"
               "trains the protection pattern would brake are counted (runtime braking patterns and\n"
               "supervision).",
               "0 pass; 1 a warning of an on-board or GNSS-time method below the design\n"
               "warning time, or a train braked by the protection pattern (named on stderr)");
  cli.Add("--line", o.line, "generated line JSON (build/gen/lines/<line>.json)")->required();
  cli.Add("--timetable", o.timetable, "generated timetable JSON (build/gen/timetables/<name>.json)")
      ->required();
  cli.Add("--trains-dir", o.trains_dir, "generated train JSON (build/gen/trains)")->required();
  cli.Add("--json", o.json,
          "result JSON (requirements, per-method statistics, requirement rows, per-crossing rows\n"
          "with meets_target, every passage)")
      ->required();
  cli.Add("--svg-dir", o.svg_dir, "one histogram per method: warning_time_<method>.svg");
  cli.Add("--lead-sweep", o.lead_sweep_s,
          "also run the on-board methods with these request leads (s, comma-separated) and\n"
          "report trains braked and warning times per lead (sensitivity of REQ-LC-015 to\n"
          "request_lead_ms; informational)")
      ->delimiter(',')
      ->check(off::InRange(0.0, 600.0));
  cli.Add("--quiet", o.quiet, "no progress on stderr");
  cli.ParseOrExit(argc, argv);
  return o;
}

int Main(int argc, char** argv) {
  const Options o = ParseArgs(argc, argv);
  const auto t0 = std::chrono::steady_clock::now();
  const railproof::offline::Line line = railproof::offline::LoadLine(o.line);
  const an::Timetable tt = an::LoadTimetable(o.timetable);
  std::map<std::string, an::TrainType> trains;
  for (const auto& sv : tt.services) {
    if (trains.count(sv.train) != 0U) {
      continue;
    }
    const std::filesystem::path p = std::filesystem::path(o.trains_dir) / (sv.train + ".json");
    if (!std::filesystem::exists(p)) {
      throw InputError(tt.file + ": service " + sv.id + ": train type '" + sv.train + "' not found (" + p.string() + ")");
    }
    trains.emplace(sv.train, an::LoadTrainType(p));
  }
  railproof::offline::OutputFiles out;
  out.Reserve(o.json);
  out.Directory(o.svg_dir);
  const railproof::offline::Progress progress("warning_study", o.quiet);
  an::StudyInputs in{&line, &tt, &trains};
  const an::StudyResult r = an::RunStudy(in, [&](std::size_t done, std::size_t total) {
    if (done % 10 == 0 || done == total) {
      progress(std::to_string(done) + "/" + std::to_string(total) + " services");
    }
  });
  auto json = an::StudyJson(in, r, 0.0);
  if (!o.lead_sweep_s.empty()) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (const double lead_s : o.lead_sweep_s) {
      const auto lead = static_cast<std::int64_t>(std::llround(lead_s * 1000.0));
      an::StudyInputs li = in;
      li.request_lead_ms = lead;
      const an::StudyResult lr = an::RunStudy(li);
      char done[64];
      std::snprintf(done, sizeof done, "request lead %.1f s done", static_cast<double>(lead) / 1000.0);
      progress(done);
      rows.push_back(an::LeadSensitivityRow(lr, lead));
    }
    json["sensitivity_request_lead"] = rows;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  json["statistics"]["wall_s"] = std::round(wall * 1000.0) / 1000.0;
  out.WriteJson(o.json, json);
  if (!o.svg_dir.empty()) {
    for (an::Method m : {an::Method::kTreadle, an::Method::kOnboard, an::Method::kOnboardDwell, an::Method::kOnboardApproach,
                         an::Method::kGnss, an::Method::kGnssReceiveTime}) {
      out.Write(std::filesystem::path(o.svg_dir) / (std::string("warning_time_") + an::ToString(m) + ".svg"),
                an::HistogramSvg(r, m, line.name));
    }
  }
  out.Commit();
  std::printf("%-30s %6s %7s %7s %7s %7s %8s %6s %7s\n", "method", "n", "min_s", "p05_s", "median", "max_s", "45-74s", "below",
              "braked");
  for (an::Method m : {an::Method::kTreadle, an::Method::kOnboard, an::Method::kOnboardDwell, an::Method::kOnboardApproach,
                       an::Method::kGnss, an::Method::kGnssReceiveTime}) {
    const an::WarningStats s = an::ComputeStats(r.passages, m);
    std::size_t braked = 0;
    for (const auto& p : r.passages) {
      braked += p.braked[static_cast<std::size_t>(m)] ? 1U : 0U;
    }
    std::printf("%-30s %6zu %7.1f %7.1f %7.1f %7.1f %7.0f%% %6zu %7s\n", an::ToString(m), s.count, s.min_s, s.p05_s, s.p50_s,
                s.max_s, s.share_45_74 * 100.0, s.below_design, an::IsOnboard(m) ? std::to_string(braked).c_str() : "-");
  }
  bool pass = an::StudyPasses(r);
  for (const auto& p : r.passages) {
    for (an::Method m : {an::Method::kOnboard, an::Method::kOnboardDwell, an::Method::kOnboardApproach, an::Method::kGnss}) {
      const double w = p.warning_ms[static_cast<std::size_t>(m)];
      if (w < static_cast<double>(p.design_ms)) {
        std::fprintf(stderr, "warning_study: SHORT WARNING: %s, service %s (%s), crossing %s: %.1f s < design %.1f s\n", an::ToString(m),
                     p.service.c_str(), p.running_line.c_str(), p.crossing.c_str(), w / 1000.0,
                     static_cast<double>(p.design_ms) / 1000.0);
      }
    }
    if (p.braked[static_cast<std::size_t>(an::Method::kOnboardDwell)]) {
      std::fprintf(stderr, "warning_study: BRAKED: service %s (%s) by the protection pattern of crossing %s\n", p.service.c_str(),
                   p.running_line.c_str(), p.crossing.c_str());
    }
  }
  std::printf("%zu passages of %zu services, %.1f s: %s\n", r.passages.size(), tt.services.size(), wall, pass ? "PASS" : "FAIL");
  return pass ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return railproof::offline::RunTool("warning_study", [&] { return Main(argc, argv); });
}
