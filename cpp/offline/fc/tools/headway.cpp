// headway: the D2 headway study (REQ-FC-009; spec/design/fc.md §8): the first two services of
// the timetable as leader and follower, D2's three cases, the leader departing its first stop
// late by each delay of the sweep; per case the minimum arrival-departure interval of the
// moving-block baseline, the fixed-block baseline and the controlled follower.
//
// Exit status: 0 pass; 1 a check failed (a trajectory beyond its ceilings, a follower that
// never arrives, the approach point's Ipopt/grid cross-check; named on stderr); 2 bad usage or
// bad input (cli.hpp).
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "railproof/fc/headway.hpp"
#include "railproof/generated/fc_params.hpp"
#include "railproof/offline/cli.hpp"
#include "railproof/offline/output_file.hpp"

namespace {

namespace fc = railproof::fc;
namespace off = railproof::offline;
namespace fcp = railproof::params::fc;

struct Options {
  std::string line, timetable, trains_dir, json, svg_dir;
  bool quiet = false;
};

int Main(int argc, char** argv) {
  Options o;
  off::Cli cli("headway",
               "D2 headway study (REQ-FC-009). The first two services of the timetable run as leader\n"
               "and follower from their origin over their first stop to the next, in D2's three cases\n"
               "(level without limits, speed limits, gradients), the leader departing the first stop\n"
               "late by 0 to leader_delay_max_ms; per case the minimum arrival-departure interval of\n"
               "the moving-block baseline, the fixed-block baseline and the controlled follower\n"
               "(approach point, outside stop, slowing rule), and the reduction.",
               "0 pass; 1 a check failed (named on stderr)");
  cli.Add("--line", o.line, "generated line JSON (build/gen/lines/<line>.json)")->required();
  cli.Add("--timetable", o.timetable, "generated timetable JSON (build/gen/timetables/<name>.json)")->required();
  cli.Add("--trains-dir", o.trains_dir, "generated train JSON (build/gen/trains)")->required();
  cli.Add("--json", o.json, "result JSON (per case the minimum intervals and reductions; every run)")->required();
  cli.Add("--svg-dir", o.svg_dir, "time-distance diagrams: headway_<case>.svg");
  cli.Add("--quiet", o.quiet, "no progress lines");
  cli.ParseOrExit(argc, argv);

  off::OutputFiles out;
  out.Reserve(o.json);
  if (!o.svg_dir.empty()) {
    out.Directory(o.svg_dir);
  }
  const off::Progress progress("headway", o.quiet);
  const off::Line line = off::LoadLine(o.line);
  const railproof::lc::analysis::Timetable tt = railproof::lc::analysis::LoadTimetable(o.timetable);
  std::map<std::string, off::TrainType> trains;
  for (const auto& s : tt.services) {
    if (trains.count(s.train) == 0) {
      trains.emplace(s.train, off::LoadTrainType(std::filesystem::path(o.trains_dir) / (s.train + ".json")));
    }
  }
  fc::StudyInput in{&line, &tt, &trains, {}};
  for (std::int64_t d = 0; d <= fcp::leader_delay_max_ms; d += fcp::leader_delay_step_ms) {
    in.delays_s.push_back(static_cast<double>(d) / 1000.0);
  }
  progress("running 3 cases x " + std::to_string(in.delays_s.size()) + " delays x 3 policies");
  const fc::StudyResult r = fc::RunStudy(in);
  bool pass = true;
  const auto j = fc::StudyJson(r, &pass);
  out.WriteJson(o.json, j);
  if (!o.svg_dir.empty()) {
    for (const fc::CaseResult& c : r.cases) {
      out.Write(std::filesystem::path(o.svg_dir) / (std::string("headway_") + fc::CaseName(c.which) + ".svg"),
                fc::TimeDistanceSvg(r, c, c.delays.back()));
    }
  }
  out.Commit();
  for (const auto& c : j["cases"]) {
    progress(c["case"].get<std::string>() + ": minimum interval baseline " + c["min_interval_baseline_s"].dump() +
             " s, fixed block " + c["min_interval_fixed_block_s"].dump() + " s, controlled " +
             c["min_interval_controlled_s"].dump() + " s");
    if (!c["meets_target"].get<bool>()) {
      std::fprintf(stderr, "headway: case %s: check failed (cross-check %s ms, worst excess %s m/s)\n",
                   c["case"].get<std::string>().c_str(), c["ipopt_minus_grid_ms"].dump().c_str(),
                   c["worst_excess_mps"].dump().c_str());
    }
  }
  return pass ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return off::RunTool("headway", [&] { return Main(argc, argv); });
}
