// wheelrail_sim: offline wheel-rail simulation (issue 5): runs a scenario of
// spec/wheelrail/*.json on the Box2D vehicle model and writes the odometry's sensor
// streams (TG, IMU, balise per 100 ms cycle) with the truth and the slip/slide events.
// See spec/wheelrail/README.md.
//
// Exit status: 0 done; 2 bad usage or bad input (cli.hpp).
#include <chrono>
#include <cstdio>
#include <string>

#include "railproof/offline/cli.hpp"
#include "railproof/offline/output_file.hpp"
#include "railproof/ra/analysis/wheel_rail.hpp"

namespace {

struct Options {
  std::string scenario;
  std::string csv;
  std::string json;
  bool quiet = false;
};

Options ParseArgs(int argc, char** argv) {
  Options o;
  railproof::offline::Cli cli(
      "wheelrail_sim",
      "Simulates a car (body, two bogies, four wheelsets; Box2D, vertical plane) on the\n"
      "scenario's vertical alignment with a slip-dependent adhesion law, traction and brake\n"
      "from the driver schedule, and writes the on-board odometry's sensor streams (TG and\n"
      "IMU per 100 ms cycle, balise fixes, injected faults) with the truth. Prints a summary\n"
      "(distance, speeds, slip/slide events).",
      "0 done");
  cli.Add("--scenario", o.scenario, "scenario (format: spec/wheelrail/README.md)")->required();
  cli.Add("--csv", o.csv, "one row per cycle: truth, TG, cycle-mean IMU");
  cli.Add("--json", o.json, "every cycle's TG and IMU samples, balise, truth; the slip/slide events");
  cli.Add("--quiet", o.quiet, "no progress lines on stderr");
  cli.ParseOrExit(argc, argv);
  return o;
}

int Main(int argc, char** argv) {
  const Options o = ParseArgs(argc, argv);
  const auto sc = railproof::ra::analysis::LoadWheelRailScenario(o.scenario);
  railproof::offline::OutputFiles out;
  for (const std::string& path : {o.csv, o.json}) {
    if (!path.empty()) {
      out.Reserve(path);
    }
  }
  const railproof::offline::Progress report("wheelrail_sim", o.quiet);
  auto progress = [&](double t, double total) {
    char line[64];
    std::snprintf(line, sizeof line, ": %.0f / %.0f s simulated", t, total);
    report(sc.name + line);
  };
  const auto t0 = std::chrono::steady_clock::now();
  const auto run = railproof::ra::analysis::SimulateWheelRail(sc, progress);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!o.csv.empty()) {
    out.Write(o.csv, railproof::ra::analysis::WheelRailCsv(run));
  }
  if (!o.json.empty()) {
    out.WriteJson(o.json, railproof::ra::analysis::WheelRailJson(sc, run));
  }
  out.Commit();
  double vmax = 0.0;
  for (const auto& t : run.truth) {
    vmax = std::max(vmax, t.speed_mps);
  }
  const auto& last = run.truth.back();
  std::printf("%s: %.1f s simulated in %.2f s (%.0fx real time), %zu cycles\n", sc.name.c_str(), run.simulated_s, wall,
              wall > 0.0 ? run.simulated_s / wall : 0.0, run.cycles.size());
  std::printf("  distance %.2f m (TG wheel %.2f m), final speed %.2f km/h, max %.2f km/h\n", last.distance_m,
              last.tg_distance_m, last.speed_mps * 3.6, vmax * 3.6);
  std::printf("  %zu slip/slide event(s) (|creep| > %.3f for >= %.2f s)\n", run.events.size(), sc.truth.event_creep,
              sc.truth.event_min_s);
  for (const auto& e : run.events) {
    std::printf("    axle %d%s %-5s %7.2f .. %7.2f s (%5.2f s) peak creep %+.3f, front %.1f .. %.1f m\n", e.axle,
                e.tg_axle ? " (TG)" : "     ", railproof::ra::analysis::ToString(e.kind), static_cast<double>(e.start_ms) / 1000.0,
                static_cast<double>(e.end_ms) / 1000.0, static_cast<double>(e.end_ms - e.start_ms) / 1000.0,
                e.peak_creep, e.start_front_m, e.end_front_m);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return railproof::offline::RunTool("wheelrail_sim", [&] { return Main(argc, argv); });
}
