// line_sim: offline system simulation of a line (simulation.hpp, spec/design/sim.md). Runs a
// scenario (spec/scenarios/*.json) on a generated line (build/gen/lines/<line>.json) with the
// real on-board units (train data of build/gen/trains/<type>.json) and the real wayside unit,
// their telegrams over a lossy channel and injected faults; checks the safety invariants at
// every step. See spec/scenarios/README.md.
//
// Exit status: 0 no invariant violated; 1 invariant violations; 2 bad usage or bad input
// (cli.hpp).
#include <chrono>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/offline/cli.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/output_file.hpp"
#include "railproof/sim/scenario.hpp"
#include "railproof/sim/simulation.hpp"

namespace {

using railproof::offline::InputError;
using Json = nlohmann::ordered_json;

void SetLeaderCap(railproof::sim::Scenario& sc, double kmh) {
  if (!sc.gap) {
    throw InputError(sc.file + ": --leader-cap-kmh / --sweep-leader-cap need a 'gap' entry naming the leader");
  }
  for (auto& t : sc.trains) {
    if (t.id == sc.gap->leader) {
      t.speed_cap_mps = kmh / 3.6;
    }
  }
}

struct Options {
  std::string scenario;
  std::string lines_dir;
  std::string trains_dir;
  std::string log;
  std::string svg;
  std::string summary;
  bool log_full = false;
  bool quiet = false;
  double leader_cap_kmh = 0.0;  // 0: the scenario's
  std::vector<double> sweep;
};

Options ParseArgs(int argc, char** argv) {
  namespace off = railproof::offline;
  Options o;
  off::Cli cli("line_sim",
               "Simulates a line scenario: every train's true motion, its sensors, its on-board unit\n"
               "(odometry, braking supervision, crossing protection, radio) and a driver; the wayside\n"
               "unit (radio endpoints, moving-block ground, crossing controllers) and the crossings'\n"
               "equipment; the units' telegrams over a lossy, delaying channel, and injected faults.\n"
               "Safety invariants are checked after every step.\n"
               "Progress: one line per 10 % of simulated time on stderr.",
               "0 no invariant violated, 1 invariant violations");
  const CLI::Validator speed = off::InRange(0.0, 400.0, true);
  cli.Add("--scenario", o.scenario, "scenario (format: spec/scenarios/README.md)")->required();
  cli.Add("--lines-dir", o.lines_dir, "directory of generated line JSON files (<line>.json)")->required();
  cli.Add("--trains-dir", o.trains_dir,
          "directory of generated train-type JSON files (<type>.json): each train's on-board data is\n"
          "the type of its length")
      ->required();
  cli.Add("--log", o.log,
          "JSON event log (cycles, reports, telegrams, faults, limit changes, violations)\n"
          "followed by the summary");
  cli.Add("--log-full", o.log_full, "also log every accepted report and stop-limit telegram");
  cli.Add("--svg", o.svg, "time-distance diagram (SVG)");
  cli.Add("--summary", o.summary, "machine-readable summary (JSON)");
  cli.Add("--leader-cap-kmh", o.leader_cap_kmh, "override the speed cap of the scenario's gap leader (km/h)")
      ->check(speed);
  cli.Add("--sweep-leader-cap", o.sweep,
          "run the scenario once per leader cap of the comma-separated list (km/h) and write one\n"
          "summary with the settled gaps")
      ->delimiter(',')
      ->check(speed)
      ->excludes("--log")
      ->excludes("--svg");
  cli.Add("--quiet", o.quiet, "no progress lines on stderr");
  cli.ParseOrExit(argc, argv);
  return o;
}

void PrintResult(const Json& s, double wall_s) {
  std::printf("%s: %s, %llu violation(s), %.0f s simulated in %.1f s\n", s["scenario"].get<std::string>().c_str(),
              s["result"].get<std::string>().c_str(), static_cast<unsigned long long>(s["violations"].get<std::uint64_t>()),
              s["simulated_s"].get<double>(), wall_s);
  const auto& p = s["progress"];
  std::printf("  trains entered %zu, left the line %zu, %.1f train-km\n", p["trains_entered"].get<std::size_t>(),
              p["trains_left_line"].get<std::size_t>(), p["train_km"].get<double>());
  if (!s["gap"].is_null()) {
    const auto& g = s["gap"];
    std::printf(
        "  settled gap (leader %d rear to follower %d front): %.1f m (min %.1f, max %.1f, sd %.1f) at %.1f km/h\n",
        g["leader"].get<int>(), g["follower"].get<int>(), g["settled_gap_m"].get<double>(), g["min_m"].get<double>(),
        g["max_m"].get<double>(), g["std_m"].get<double>(), g["leader_speed_kmh"].get<double>());
  }
  for (const auto& v : s["violation_list"]) {
    std::printf("  VIOLATION t=%.1f s %s: %s\n", v["t_s"].get<double>(), v["requirement"].get<std::string>().c_str(),
                v["detail"].get<std::string>().c_str());
  }
}

int Main(int argc, char** argv) {
  const Options o = ParseArgs(argc, argv);
  const auto base = railproof::sim::LoadScenario(o.scenario);
  const auto line = railproof::offline::LoadLine(railproof::offline::LinePath(o.lines_dir, base.line));
  const auto types = railproof::offline::LoadTrainTypes(o.trains_dir);
  const railproof::offline::Progress progress("line_sim", o.quiet);
  railproof::offline::OutputFiles out;
  for (const std::string& path : {o.summary, o.svg}) {
    if (!path.empty()) {
      out.Reserve(path);
    }
  }

  if (!o.sweep.empty()) {
    Json runs = Json::array();
    bool grows = true;
    double prev = -1.0;
    bool all_pass = true;
    for (const double cap : o.sweep) {
      auto sc = base;
      SetLeaderCap(sc, cap);
      railproof::sim::Simulation sim(sc, line, types);
      const auto t0 = std::chrono::steady_clock::now();
      railproof::sim::RunOptions ro;
      ro.progress = std::cref(progress);
      sim.Run(ro);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const Json s = sim.Summary();
      PrintResult(s, wall);
      const double gap = s["gap"].is_null() ? -1.0 : s["gap"]["settled_gap_m"].get<double>();
      grows = grows && gap > prev;
      prev = gap;
      all_pass = all_pass && s["result"] == "PASS";
      runs.push_back(Json{{"leader_cap_kmh", cap}, {"result", s["result"]}, {"violations", s["violations"]},
                          {"gap", s["gap"]}});
    }
    Json sweep{{"schema", "railproof/sim-sweep/1"},
               {"scenario", base.name},
               {"line", base.line},
               {"requirements", {"REQ-MB-006", "REQ-MB-008", "REQ-MB-018"}},
               {"runs", runs},
               {"gap_grows_with_speed", grows},
               {"result", all_pass ? "PASS" : "FAIL"}};
    std::printf("gap grows with the leader's speed: %s\n", grows ? "yes" : "no");
    if (!o.summary.empty()) {
      out.WriteJson(o.summary, sweep);
    }
    out.Commit();
    return all_pass ? 0 : 1;
  }

  auto sc = base;
  if (o.leader_cap_kmh > 0.0) {
    SetLeaderCap(sc, o.leader_cap_kmh);
  }
  railproof::sim::Simulation sim(sc, line, types);
  railproof::sim::RunOptions ro;
  ro.progress = std::cref(progress);
  ro.log_full = o.log_full;
  if (!o.log.empty()) {
    ro.log = &out.Stream(o.log);
  }
  const auto t0 = std::chrono::steady_clock::now();
  sim.Run(ro);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Json s = sim.Summary();
  if (!o.summary.empty()) {
    out.WriteJson(o.summary, s);
  }
  if (!o.svg.empty()) {
    out.Write(o.svg, sim.Svg());
  }
  out.Commit();
  PrintResult(s, wall);
  return s["result"] == "PASS" ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return railproof::offline::RunTool("line_sim", [&] { return Main(argc, argv); });
}
