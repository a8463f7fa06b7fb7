// line_sim: offline line scenario simulation (moving block, issue 3 item 6). Runs a
// scenario (spec/scenarios/*.json) on a generated line (build/gen/lines/<line>.json) with
// the runtime ground and on-board code, the radio telegram layer over a lossy channel and
// injected faults; checks the safety invariants at every step. See spec/scenarios/README.md.
//
// Exit status: 0 no invariant violated; 1 invariant violations; 2 bad input or error.
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
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

void PrintHelp() {
  std::printf(
      "usage: line_sim --scenario FILE --lines-dir DIR [--log FILE] [--log-full] [--svg FILE]\n"
      "                [--summary FILE] [--leader-cap-kmh V] [--sweep-leader-cap V1,V2,...]\n"
      "                [--quiet] [--help]\n"
      "\n"
      "Simulates a moving-block line scenario: trains with simple longitudinal dynamics, the\n"
      "ground (tracking, interlocking, stop limits) and on-board authority handling, position\n"
      "reports and stop-limit telegrams through the radio telegram layer over a lossy, delaying\n"
      "channel, and injected faults. Safety invariants are checked after every step.\n"
      "\n"
      "  --scenario FILE        scenario (format: spec/scenarios/README.md)\n"
      "  --lines-dir DIR        directory of generated line JSON files (<line>.json)\n"
      "  --log FILE             JSON event log (cycles, reports, telegrams, faults, limit\n"
      "                         changes, violations) followed by the summary\n"
      "  --log-full             also log every accepted report and stop-limit telegram\n"
      "  --svg FILE             time-distance diagram (SVG)\n"
      "  --summary FILE         machine-readable summary (JSON)\n"
      "  --leader-cap-kmh V     override the speed cap of the scenario's gap leader\n"
      "  --sweep-leader-cap L   run the scenario once per leader cap in the comma-separated\n"
      "                         list L (km/h) and write one summary with the settled gaps\n"
      "  --quiet                no progress lines on stderr\n"
      "\n"
      "Progress: one line per 10 %% of simulated time on stderr. Exit status: 0 no invariant\n"
      "violated, 1 invariant violations, 2 bad input or error.\n");
}

// --leader-cap-kmh and every entry of --sweep-leader-cap.
const railproof::offline::NumberRule kSpeedKmh{
    .lo = 0.0, .hi = 400.0, .lo_open = true, .message = "{opt}: not a speed in (0, 400] km/h: '{value}'"};

void WriteFile(const std::filesystem::path& path, const std::string& text) {
  railproof::offline::WriteFileAtomic(path, text);
}

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
  std::string log;
  std::string svg;
  std::string summary;
  bool log_full = false;
  bool quiet = false;
  std::optional<double> leader_cap;
  std::vector<double> sweep;
};

Options ParseArgs(int argc, char** argv) {
  Options o;
  railproof::offline::CliParser cli({.tool = "line_sim", .unknown = railproof::offline::CliStyle::Unknown::kQuoted}, PrintHelp);
  cli.Value("--scenario", o.scenario)
      .Value("--lines-dir", o.lines_dir)
      .Value("--log", o.log)
      .Flag("--log-full", o.log_full)
      .Value("--svg", o.svg)
      .Value("--summary", o.summary)
      .Flag("--quiet", o.quiet)
      .Number("--leader-cap-kmh", [&](double v) { o.leader_cap = v; }, kSpeedKmh)
      .Custom("--sweep-leader-cap",
              [&](const std::string& list) -> std::optional<std::string> {
                std::stringstream ss(list);
                std::string item;
                while (std::getline(ss, item, ',')) {
                  double v = 0.0;
                  if (auto error = railproof::offline::ParseCliNumber("--sweep-leader-cap", item, kSpeedKmh, v)) {
                    return error;
                  }
                  o.sweep.push_back(v);
                }
                if (o.sweep.empty()) {
                  return "--sweep-leader-cap: empty list";
                }
                return std::nullopt;
              })
      .Require("--scenario")
      .Require("--lines-dir");
  cli.ParseOrExit(argc, argv);
  if (!o.sweep.empty() && (!o.log.empty() || !o.svg.empty())) {
    cli.Fail("--sweep-leader-cap writes only --summary (no --log / --svg)");
  }
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
    std::printf("  settled gap (leader %d rear to follower %d front): %.1f m (min %.1f, max %.1f) at %.1f km/h\n",
                g["leader"].get<int>(), g["follower"].get<int>(), g["settled_gap_m"].get<double>(),
                g["min_m"].get<double>(), g["max_m"].get<double>(), g["leader_speed_kmh"].get<double>());
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
  auto progress = [&](const std::string& line_text) {
    if (!o.quiet) {
      std::fprintf(stderr, "line_sim: %s\n", line_text.c_str());
    }
  };

  if (!o.sweep.empty()) {
    Json runs = Json::array();
    bool grows = true;
    double prev = -1.0;
    bool all_pass = true;
    for (const double cap : o.sweep) {
      auto sc = base;
      SetLeaderCap(sc, cap);
      railproof::sim::Simulation sim(sc, line);
      const auto t0 = std::chrono::steady_clock::now();
      railproof::sim::RunOptions ro;
      ro.progress = progress;
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
    Json out{{"schema", "railproof/sim-sweep/1"},
             {"scenario", base.name},
             {"line", base.line},
             {"requirements", {"REQ-MB-006", "REQ-MB-008", "REQ-MB-018"}},
             {"runs", runs},
             {"gap_grows_with_speed", grows},
             {"result", all_pass ? "PASS" : "FAIL"}};
    std::printf("gap grows with the leader's speed: %s\n", grows ? "yes" : "no");
    if (!o.summary.empty()) {
      WriteFile(o.summary, out.dump(1) + "\n");
    }
    return all_pass ? 0 : 1;
  }

  auto sc = base;
  if (o.leader_cap) {
    SetLeaderCap(sc, *o.leader_cap);
  }
  railproof::sim::Simulation sim(sc, line);
  std::ofstream log;
  std::string log_tmp;
  railproof::sim::RunOptions ro;
  ro.progress = progress;
  ro.log_full = o.log_full;
  if (!o.log.empty()) {
    log_tmp = o.log + ".tmp";
    log.open(log_tmp, std::ios::binary);
    if (!log) {
      throw InputError(o.log + ": cannot write");
    }
    ro.log = &log;
  }
  const auto t0 = std::chrono::steady_clock::now();
  sim.Run(ro);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!o.log.empty()) {
    log.close();
    if (!log) {
      throw InputError(o.log + ": write failed");
    }
    std::filesystem::rename(log_tmp, o.log);
  }
  const Json s = sim.Summary();
  if (!o.summary.empty()) {
    WriteFile(o.summary, s.dump(1) + "\n");
  }
  if (!o.svg.empty()) {
    WriteFile(o.svg, sim.Svg());
  }
  PrintResult(s, wall);
  return s["result"] == "PASS" ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "line_sim: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "line_sim: error: %s\n", e.what());
    return 2;
  }
}
