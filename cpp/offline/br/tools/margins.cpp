// margins: offline worst-case braking-margin verification (spec/design/br.md §5; issue 4
// item 4). For every stop-limit location of every running line of each --line and every
// --train: the minimum margin L - worst stopping point over the uncertainty set and the
// admissible states, by corner + grid enumeration over the runtime patterns, an Ipopt NLP
// (cross-check) and an OMPL falsifier with the runtime supervision in the loop.
//
// Exit status: 0 every margin >= 0 and every check passed; 1 a negative margin (named on
// stderr), a design-rule finding (REQ-BR-010), a falsified location or a failed NLP/grid
// cross-check; 2 bad usage or bad input (cli.hpp; including a train type whose speed
// allowance does not cover the speed-check error, REQ-SC-005).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/br/analysis/falsifier.hpp"
#include "railproof/br/analysis/margins.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/offline/cli.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/output_file.hpp"
#include "railproof/offline/svg.hpp"

namespace {

namespace an = railproof::br::analysis;
using railproof::offline::InputError;
using Json = nlohmann::ordered_json;

// Tolerance of the cross-check: the NLP's worst margin (exact physics of its worst state)
// may exceed the grid's by at most this (smoothing eps ln2 |step| plus the trapezoidal time
// error of the run-up, both well under 1 cm on the provided lines).
constexpr double kCrossCheckTolMm = 50.0;

struct Options {
  std::vector<std::string> lines;
  std::vector<std::string> trains;
  std::string json;
  std::string svg_dir;
  std::string cases_dir;
  double falsify_budget_s = 0.3;
  int falsify_per_class = 1;
  int nlp_per_class = 2;
  bool nlp_all = false;
  std::int64_t resolution_mm = 1000;
  int threads = 0;  // 0: the hardware's
  bool compare = false;
  bool quiet = false;
  bool exclude_standstill = false;
  std::string details;  // per-location rows go here instead of into --json
};

Options ParseArgs(int argc, char** argv) {
  namespace off = railproof::offline;
  Options o;
  off::Cli cli("margins",
               "Worst-case braking margins (REQ-BR-009/010/011/014): for every stop-limit location\n"
               "(platform stop and fixed-block entry, route entrance, handover, system boundary, level\n"
               "crossing, end of track; possession start and preceding-train rear at every virtual-block\n"
               "boundary and gradient / speed-limit change +- train length) of every running line and\n"
               "every train type, the minimum of L - worst stopping point over the uncertainty set and\n"
               "every state the runtime supervision admits.",
               "0 all margins >= 0 and all checks passed; 1 a negative margin (named),\n"
               "a REQ-BR-010 finding, a falsifier violation or a failed NLP/grid cross-check");
  cli.Add("--line", o.lines, "generated line JSON (build/gen/lines/<line>.json); repeatable")->required();
  cli.Add("--train", o.trains, "train JSON (build/gen/trains/<name>.json); repeatable")->required();
  cli.Add("--json", o.json,
          "result JSON (requirements, verdict, minimum per line, train and class, findings,\n"
          "statistics; with the per-location rows unless --details is given)")
      ->required();
  cli.Add("--details", o.details, "the per-location rows (worst states, adversary) in this file");
  cli.Add("--svg-dir", o.svg_dir,
          "one SVG per line x running line x train: patterns and worst case at the worst\n"
          "location of each class");
  cli.Add("--cases-dir", o.cases_dir, "write falsifier violations as regression cases (JSON)");
  cli.Add("--falsify-budget-s", o.falsify_budget_s, "OMPL falsifier time per location (0: off)")
      ->check(off::InRange(0.0, 3600.0));
  cli.Add("--falsify-per-class", o.falsify_per_class, "falsify the N worst locations per class")
      ->check(off::InRange(0, 1000));
  cli.Add("--nlp-per-class", o.nlp_per_class, "Ipopt on the N worst (grid) locations per class")
      ->check(off::InRange(0, 100000));
  cli.Add("--nlp-all", o.nlp_all, "Ipopt on every location");
  cli.Add("--resolution-mm", o.resolution_mm, "grid step of the check position")->check(off::InRange(1, 100000));
  cli.Add("--threads", o.threads, "worker threads of the grid (default: the hardware's)")->check(off::InRange(1, 256));
  cli.Add("--compare-methods", o.compare, "time Ipopt against a continuous grid of equal accuracy");
  cli.Add("--exclude-standstill-restart", o.exclude_standstill,
          "judge only moving admissible states (NOT the design note's definition: a\n"
          "standing train that restarts where V_e = 0 is admitted by the runtime; its margin is\n"
          "still reported)");
  cli.Add("--quiet", o.quiet, "no progress on stderr");
  cli.ParseOrExit(argc, argv);
  return o;
}

struct Row {
  an::Location loc;
  an::GridResult grid;
  std::optional<an::NlpResult> nlp;
  std::optional<an::FalsifierResult> fals;
  double margin_mm = 0.0;
  std::string method;
  bool cross_ok = true;
};

struct Job {
  const railproof::offline::Line* line = nullptr;
  const railproof::offline::RunningLine* rl = nullptr;
  const an::TrainType* train = nullptr;
  std::unique_ptr<an::MarginModel> model;
  an::LocationSet locs;
  std::vector<Row> rows;
  double grid_s = 0.0, nlp_s = 0.0, fals_s = 0.0;
};

Json TrajJson(const an::Trajectory& t) {
  return Json{{"check_front_mm", std::llround(t.check_front_mm)},
              {"measured_speed_mm_s", t.measured_speed_mm_s},
              {"supervised_speed_mm_s", t.supervised_speed_mm_s},
              {"runtime_emergency_pattern_mm_s", t.pattern_speed_mm_s},
              {"standstill_start", t.standstill_start},
              {"true_front_mm", std::llround(t.true_front_mm)},
              {"true_speed_mm_s", std::llround(t.true_speed_mm_s)},
              {"brake_front_mm", std::llround(t.brake_front_mm)},
              {"brake_speed_mm_s", std::llround(t.brake_speed_mm_s)},
              {"stop_mm", std::isfinite(t.stop_mm) ? Json(std::llround(t.stop_mm)) : Json("never")},
              {"run_up_ms", std::llround(t.run_up_ms)},
              {"adversary",
               {{"beta_mm_s2", t.adversary.beta_mm_s2},
                {"free_running_ms", t.adversary.free_running_ms},
                {"gradient_error_x10", t.adversary.gradient_error_x10},
                {"runup_cycle_ms", t.adversary.runup_cycle_ms},
                {"traction", t.adversary.traction},
                {"position_error_mm", t.adversary.position_error_mm},
                {"speed_error_sign", t.adversary.speed_error_sign}}}};
}

double Round3(double v) { return std::round(v * 1000.0) / 1000.0; }

std::string Svg(const Job& job, const std::map<int, std::size_t>& worst_by_class) {
  using railproof::offline::SvgPlot;
  using railproof::offline::SvgStyle;
  const auto& m = *job.model;
  const auto& calc = m.patterns();
  const std::int64_t e = m.position_error_mm();
  std::vector<SvgPlot> panels;
  for (const auto& [cls, idx] : worst_by_class) {
    const Row& r = job.rows[idx];
    const double l = static_cast<double>(r.loc.stop_limit_mm);
    const double d = static_cast<double>(m.approach_mm());
    const double over = std::max(0.0, -r.margin_mm);
    const double x_lo = -d / 1000.0;
    const double x_hi = std::max(30.0, static_cast<double>(r.loc.class_margin_mm) / 1000.0 + 10.0) + over / 1000.0;
    double v_top = 0.0;
    railproof::offline::SvgPoints ve, vs;
    for (std::int64_t x = r.loc.stop_limit_mm - m.approach_mm(); x <= r.loc.stop_limit_mm; x += 1000) {
      const double px = (static_cast<double>(x) - l) / 1000.0;
      const double a = static_cast<double>(calc.EmergencyPatternSpeed(x, r.loc.stop_limit_mm, e, e)) * 0.0036;
      const double b = static_cast<double>(calc.ServicePatternSpeed(x, r.loc.stop_limit_mm, e, e)) * 0.0036;
      ve.emplace_back(px, a);
      vs.emplace_back(px, b);
    }
    const an::Trajectory& w = r.method == "nlp" && r.nlp ? r.nlp->worst : r.grid.worst;
    railproof::offline::SvgPoints tr;
    for (const auto& [x, v] : w.points) {
      tr.emplace_back((x - l) / 1000.0, v * 0.0036);
      v_top = std::max(v_top, v * 0.0036);
    }
    v_top = std::max(v_top, static_cast<double>(m.train_max_speed_mm_s()) * 0.0036 + 10.0);
    SvgPlot& plot = panels.emplace_back(x_lo, x_hi, 0.0, v_top);
    char title[512];
    std::snprintf(title, sizeof title, "%s / %s / %s — %s: %s, margin %.3f m (%s)", job.line->name.c_str(),
                  job.rl->id.c_str(), job.train->name.c_str(), an::ToString(r.loc.cls), r.loc.id.c_str(),
                  r.margin_mm / 1000.0, r.method.c_str());
    plot.SetTitle(title);
    plot.SetXLabel("front position relative to the stop limit L (m)");
    plot.SetYLabel("speed (km/h)");
    const SvgStyle limit{"#808080", 1.0, "3 3", 1.0};
    const SvgStyle obstruction{"#800080", 1.0, "3 3", 1.0};
    plot.AddSeries(ve, SvgStyle{"#c00000", 2.0, "", 1.0}, "emergency pattern V_e (runtime, at x_s)");
    plot.AddSeries(vs, SvgStyle{"#0060c0", 2.0, "6 4", 1.0}, "service pattern V_s (runtime, at x_s)");
    plot.AddSeries(tr, SvgStyle{"#000000", 2.5, "", 1.0}, "worst-case true trajectory");
    plot.AddVLine(0.0, "", limit);
    plot.AddVLine(static_cast<double>(r.loc.class_margin_mm) / 1000.0, "", obstruction);
    if (!tr.empty()) {
      plot.AddMarker(tr.front().first, tr.front().second, "#000000", "check");
      plot.AddMarker(tr.back().first, 0.0, r.margin_mm < 0 ? "#ff0000" : "#008000", "stop");
    }
    plot.AddLegend("stop limit L", limit);
    plot.AddLegend("obstruction (L + class margin)", obstruction);
  }
  return railproof::offline::SvgStack(panels);
}

int Main(int argc, char** argv) {
  const Options o = ParseArgs(argc, argv);
  const auto t_start = std::chrono::steady_clock::now();
  const railproof::offline::Progress progress("margins", o.quiet);
  std::vector<railproof::offline::Line> lines;
  for (const auto& f : o.lines) {
    lines.push_back(railproof::offline::LoadLine(f));
  }
  std::vector<an::TrainType> trains;
  for (const auto& f : o.trains) {
    trains.push_back(an::LoadTrainType(f));
  }
  railproof::offline::OutputFiles out_files;
  for (const std::string& path : {o.json, o.details}) {
    if (!path.empty()) {
      out_files.Reserve(path);
    }
  }
  for (const std::string& dir : {o.svg_dir, o.cases_dir}) {
    out_files.Directory(dir);
  }
  const an::SpeedErrorModel se = an::ReferenceSpeedErrorModel();
  Json findings = Json::array();
  Json requirement_rows = Json::array();
  for (const auto& t : trains) {
    const std::string sc = an::SpeedAllowanceFinding(t, se);
    if (!sc.empty()) {
      throw InputError(sc);  // REQ-SC-005: refused
    }
    requirement_rows.push_back(Json{{"requirement", "REQ-SC-005"}, {"train", t.name}, {"meets_target", true},
                                    {"detail", "allowance covers the D3 bound up to the train's maximum speed"}});
    const auto dr = an::DesignRuleFindings(t);
    for (const auto& f : dr) {
      findings.push_back(Json{{"requirement", "REQ-BR-010"}, {"train", t.name}, {"finding", f}});
      std::fprintf(stderr, "margins: FINDING %s\n", f.c_str());
    }
    requirement_rows.push_back(Json{{"requirement", "REQ-BR-010"}, {"train", t.name}, {"meets_target", dr.empty()},
                                    {"detail", dr.empty() ? "beta_n7 <= beta_e <= lowest real emergency deceleration"
                                                          : dr.front()}});
  }

  // jobs
  std::vector<Job> jobs;
  for (const auto& line : lines) {
    for (const auto& rl : line.running_lines) {
      for (const auto& t : trains) {
        Job j;
        j.line = &line;
        j.rl = &rl;
        j.train = &t;
        j.model = std::make_unique<an::MarginModel>(rl, t, se);
        j.locs = an::EnumerateLocations(rl, t.length_mm, j.model->approach_mm());
        for (const auto& l : j.locs.analysed) {
          j.rows.push_back(Row{l, {}, std::nullopt, std::nullopt, 0.0, "", true});
        }
        jobs.push_back(std::move(j));
      }
    }
  }
  // grid (parallel over locations)
  std::vector<std::pair<std::size_t, std::size_t>> tasks;
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    for (std::size_t r = 0; r < jobs[j].rows.size(); ++r) {
      tasks.emplace_back(j, r);
    }
  }
  progress("grid: " + std::to_string(tasks.size()) + " location(s) x train(s) at " + std::to_string(o.resolution_mm) +
           " mm resolution");
  const int nthreads = o.threads > 0 ? o.threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::mutex err_mu;
  std::string err;
  const auto tg0 = std::chrono::steady_clock::now();
  {
    std::vector<std::thread> pool;
    for (int i = 0; i < nthreads; ++i) {
      pool.emplace_back([&] {
        for (;;) {
          const std::size_t k = next.fetch_add(1);
          if (k >= tasks.size()) {
            return;
          }
          try {
            Job& job = jobs[tasks[k].first];
            Row& row = job.rows[tasks[k].second];
            row.grid = an::GridWorstCase(*job.model, row.loc, o.resolution_mm);
            row.margin_mm = o.exclude_standstill ? row.grid.moving_margin_mm : row.grid.margin_mm;
            row.method = "grid";
          } catch (const std::exception& e) {
            std::lock_guard<std::mutex> lock(err_mu);
            err = e.what();
          }
          const std::size_t d = done.fetch_add(1) + 1;
          if (!o.quiet && (d % std::max<std::size_t>(1, tasks.size() / 10) == 0 || d == tasks.size())) {
            std::fprintf(stderr, "margins: grid %zu/%zu\n", d, tasks.size());
          }
        }
      });
    }
    for (auto& t : pool) {
      t.join();
    }
  }
  if (!err.empty()) {
    throw std::runtime_error(err);
  }
  const double grid_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - tg0).count();

  // NLP on the worst locations per class (or all); falsifier on the worst per class.
  std::size_t nlp_runs = 0, fals_runs = 0, fals_found = 0, cross_fail = 0;
  double nlp_wall = 0.0, fals_wall = 0.0;
  Json cases = Json::array();
  for (auto& job : jobs) {
    std::map<int, std::vector<std::size_t>> by_class;
    for (std::size_t r = 0; r < job.rows.size(); ++r) {
      by_class[static_cast<int>(job.rows[r].loc.cls)].push_back(r);
    }
    for (auto& [cls, idx] : by_class) {
      std::sort(idx.begin(), idx.end(),
                [&](std::size_t a, std::size_t b) { return job.rows[a].grid.margin_mm < job.rows[b].grid.margin_mm; });
      const std::size_t nn = o.nlp_all ? idx.size() : std::min<std::size_t>(idx.size(), static_cast<std::size_t>(o.nlp_per_class));
      for (std::size_t k = 0; k < nn; ++k) {
        Row& row = job.rows[idx[k]];
        std::vector<an::NlpSeed> seeds;
        for (const auto& mn : row.grid.minima) {
          seeds.push_back({std::get<0>(mn), static_cast<double>(std::get<1>(mn))});
        }
        seeds.insert(seeds.begin(), an::NlpSeed{row.grid.worst_moving.check_front_mm,
                                                static_cast<double>(row.grid.worst_moving.measured_speed_mm_s)});
        if (seeds.empty()) {
          continue;
        }
        row.nlp = an::NlpWorstCase(*job.model, row.loc, seeds);
        ++nlp_runs;
        nlp_wall += row.nlp->wall_s;
        if (row.nlp->solved) {
          if (row.nlp->margin_mm > row.grid.moving_margin_mm + kCrossCheckTolMm) {
            row.cross_ok = false;
            ++cross_fail;
            std::fprintf(stderr, "margins: CROSS-CHECK FAILED %s/%s/%s %s: NLP margin %.3f m > grid %.3f m + %.3f m\n",
                         job.line->name.c_str(), job.rl->id.c_str(), job.train->name.c_str(), row.loc.id.c_str(),
                         row.nlp->margin_mm / 1000.0, row.grid.moving_margin_mm / 1000.0, kCrossCheckTolMm / 1000.0);
          }
          // the NLP searches a relaxation: its margin counts as the location's margin only
          // when the runtime supervision admits its worst state
          if (row.nlp->runtime_admissible && row.nlp->margin_mm < row.margin_mm) {
            row.margin_mm = row.nlp->margin_mm;
            row.method = "nlp";
          }
        }
      }
      const std::size_t nf = o.falsify_budget_s > 0.0 ? std::min<std::size_t>(idx.size(), static_cast<std::size_t>(o.falsify_per_class)) : 0;
      for (std::size_t k = 0; k < nf; ++k) {
        Row& row = job.rows[idx[k]];
        an::FalsifierOptions fo;
        fo.budget_s = o.falsify_budget_s;
        fo.seed = 1;
        fo.admit_standstill_restart = !o.exclude_standstill;
        row.fals = an::Falsify(*job.model, row.loc, job.line->name, fo);
        ++fals_runs;
        fals_wall += row.fals->wall_s;
        if (row.fals->violation) {
          ++fals_found;
          if (row.fals->max_overrun_mm > 0.0 && -row.fals->max_overrun_mm < row.margin_mm) {
            row.margin_mm = -row.fals->max_overrun_mm;
            row.method = "falsifier";
          }
          cases.push_back(row.fals->regression_case);
          if (!o.cases_dir.empty()) {
            std::string name = job.line->name + "_" + job.rl->id + "_" + job.train->name + "_" + an::ToString(row.loc.cls) + "_" +
                               std::to_string(row.loc.stop_limit_mm) + ".json";
            out_files.WriteJson(std::filesystem::path(o.cases_dir) / name, row.fals->regression_case);
          }
        }
      }
    }
    progress("nlp/falsifier: " + job.line->name + "/" + job.rl->id + "/" + job.train->name + " done");
  }

  // compare methods: Ipopt vs a grid over the same continuous model of equal accuracy
  Json compare = Json::array();
  if (o.compare) {
    for (auto& job : jobs) {
      const Row* worst = nullptr;
      for (const auto& r : job.rows) {
        if (r.nlp && r.nlp->solved && (!worst || r.grid.moving_margin_mm < worst->grid.moving_margin_mm)) {
          worst = &r;
        }
      }
      if (!worst) {
        continue;
      }
      std::vector<an::NlpSeed> seeds{{worst->grid.worst_moving.check_front_mm,
                                      static_cast<double>(worst->grid.worst_moving.measured_speed_mm_s)}};
      const an::NlpResult nr = an::NlpWorstCase(*job.model, worst->loc, seeds);
      if (!nr.solved) {
        continue;
      }
      Json steps = Json::array();
      double equal_s = -1.0, equal_step = -1.0;
      for (double step = 1000.0; step >= 1.0; step /= 10.0) {
        const auto g = an::ContinuousGridWorstCase(*job.model, worst->loc, step, 1);
        steps.push_back(Json{{"step_mm", step}, {"objective_m", g.objective_m}, {"evaluations", g.evaluations}, {"wall_s", g.wall_s}});
        progress("compare " + job.rl->id + "/" + job.train->name + ": grid step " + std::to_string(step) + " mm: " +
                 std::to_string(g.wall_s) + " s");
        if (g.objective_m >= nr.objective_m - 1e-3) {
          equal_s = g.wall_s;
          equal_step = step;
          break;
        }
      }
      const auto full = an::ContinuousGridWorstCase(*job.model, worst->loc, 1000.0, 2);
      compare.push_back(Json{{"line", job.line->name}, {"running_line", job.rl->id}, {"train", job.train->name},
                             {"location", worst->loc.id}, {"nlp_objective_m", nr.objective_m}, {"nlp_wall_s", nr.wall_s},
                             {"grid_refinement", steps}, {"equal_accuracy_step_mm", equal_step},
                             {"equal_accuracy_grid_s", equal_s},
                             {"speedup", equal_s > 0 ? Json(equal_s / nr.wall_s) : Json(nullptr)},
                             {"full_parameter_grid_2_per_axis_1m", {{"evaluations", full.evaluations}, {"wall_s", full.wall_s}, {"objective_m", full.objective_m}}}});
    }
  }

  // results
  bool negative = false;
  Json rows = Json::array();
  Json summary = Json::array();
  std::size_t skipped_total = 0;
  for (auto& job : jobs) {
    skipped_total += job.locs.skipped.size();
    std::map<int, std::size_t> worst_by_class;
    for (std::size_t r = 0; r < job.rows.size(); ++r) {
      const auto c = static_cast<int>(job.rows[r].loc.cls);
      if (!worst_by_class.count(c) || job.rows[r].margin_mm < job.rows[worst_by_class[c]].margin_mm) {
        worst_by_class[c] = r;
      }
    }
    for (const auto& row : job.rows) {
      const bool ok = row.margin_mm >= 0.0 && row.cross_ok && !(row.fals && row.fals->violation);
      if (row.margin_mm < 0.0) {
        negative = true;
      }
      Json jr{{"line", job.line->name},
              {"running_line", job.rl->id},
              {"train", job.train->name},
              {"class", an::ToString(row.loc.cls)},
              {"id", row.loc.id},
              {"requirements", row.loc.cls == an::LocationClass::kPossession ? Json{"REQ-BR-009", "REQ-BR-011", "REQ-BR-014"}
                                                                             : Json{"REQ-BR-009", "REQ-BR-014"}},
              {"obstruction_mm", row.loc.obstruction_mm},
              {"class_margin_mm", row.loc.class_margin_mm},
              {"stop_limit_mm", row.loc.stop_limit_mm},
              {"margin_mm", Round3(row.margin_mm)},
              {"margin_to_obstruction_mm", Round3(row.margin_mm + static_cast<double>(row.loc.class_margin_mm))},
              {"method", row.method},
              {"grid", {{"margin_mm", Round3(row.grid.margin_mm)}, {"moving_margin_mm", Round3(row.grid.moving_margin_mm)},
                        {"standstill_restart_margin_mm", Round3(row.grid.standstill_margin_mm)},
                        {"checks", row.grid.checks}, {"worst", TrajJson(row.grid.worst)},
                        {"worst_moving", TrajJson(row.grid.worst_moving)}}},
              {"meets_target", ok}};
      if (row.nlp) {
        jr["nlp"] = Json{{"status", row.nlp->status},
                         {"iterations", row.nlp->iterations},
                         {"objective_m", row.nlp->objective_m},
                         {"margin_mm", Round3(row.nlp->margin_mm)},
                         {"runtime_admissible", row.nlp->runtime_admissible},
                         {"cross_check_ok", row.cross_ok},
                         {"wall_s", row.nlp->wall_s},
                         {"worst", TrajJson(row.nlp->worst)}};
      }
      if (row.fals) {
        jr["falsifier"] = Json{{"violation", row.fals->violation},
                               {"max_overrun_mm", Round3(row.fals->max_overrun_mm)},
                               {"propagations", row.fals->propagations},
                               {"wall_s", row.fals->wall_s}};
      }
      rows.push_back(jr);
    }
    for (const auto& [c, idx] : worst_by_class) {
      const Row& r = job.rows[idx];
      summary.push_back(Json{{"line", job.line->name}, {"running_line", job.rl->id}, {"train", job.train->name},
                             {"class", an::ToString(r.loc.cls)}, {"worst_id", r.loc.id}, {"stop_limit_mm", r.loc.stop_limit_mm},
                             {"min_margin_mm", Round3(r.margin_mm)},
                             {"margin_to_obstruction_mm", Round3(r.margin_mm + static_cast<double>(r.loc.class_margin_mm))},
                             {"method", r.method}, {"meets_target", r.margin_mm >= 0.0}});
      std::printf("%-14s %-5s %-13s %-16s min margin %9.3f m (to obstruction %9.3f m) at %s [%s]\n", job.line->name.c_str(),
                  job.rl->id.c_str(), job.train->name.c_str(), an::ToString(r.loc.cls), r.margin_mm / 1000.0,
                  (r.margin_mm + static_cast<double>(r.loc.class_margin_mm)) / 1000.0, r.loc.id.c_str(), r.method.c_str());
    }
    if (!o.svg_dir.empty()) {
      out_files.Write(std::filesystem::path(o.svg_dir) / (job.line->name + "_" + job.rl->id + "_" + job.train->name + ".svg"),
                      Svg(job, worst_by_class));
    }
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
  const bool pass = !negative && findings.empty() && fals_found == 0 && cross_fail == 0;
  Json skipped = Json::array();
  for (const auto& job : jobs) {
    for (const auto& l : job.locs.skipped) {
      skipped.push_back(Json{{"line", job.line->name}, {"running_line", job.rl->id}, {"train", job.train->name},
                             {"class", an::ToString(l.cls)}, {"id", l.id}, {"stop_limit_mm", l.stop_limit_mm},
                             {"reason", "stop limit closer to the line start than the approach length " +
                                            std::to_string(job.model->approach_mm()) + " mm"}});
    }
  }
  Json trains_json = Json::array();
  for (const auto& job : jobs) {
    trains_json.push_back(Json{{"line", job.line->name}, {"running_line", job.rl->id}, {"train", job.train->name},
                               {"position_error_mm", job.model->position_error_mm()},
                               {"longest_balise_spacing_mm", job.model->longest_balise_spacing_mm()},
                               {"approach_mm", job.model->approach_mm()},
                               {"locations", job.rows.size()}, {"skipped", job.locs.skipped.size()}});
  }
  Json out{{"schema", "railproof/margins/1"},
           {"requirements", {"REQ-BR-001", "REQ-BR-005", "REQ-BR-007", "REQ-BR-009", "REQ-BR-010", "REQ-BR-011", "REQ-BR-014", "REQ-SC-005"}},
           {"verdict", pass ? "pass" : "fail"},
           {"model",
            {{"speed_error", {{"n_1f", se.design.n_1f}, {"f_1_hz", se.design.f_1_hz}, {"envelope_c0_mm_s", se.c0_mm_s}, {"envelope_c1", se.c1}}},
             {"grid_resolution_mm", o.resolution_mm},
             {"standstill_restart_admitted", !o.exclude_standstill},
             {"cross_check_tolerance_mm", kCrossCheckTolMm}}},
           {"runs", trains_json},
           {"findings", findings},
           {"requirement_rows", requirement_rows},
           {"summary", summary},
           {"statistics",
            {{"locations", tasks.size()}, {"skipped", skipped_total}, {"grid_wall_s", grid_wall},
             {"nlp_runs", nlp_runs}, {"nlp_wall_s", nlp_wall}, {"nlp_cross_check_failures", cross_fail},
             {"falsifier_runs", fals_runs}, {"falsifier_violations", fals_found}, {"falsifier_wall_s", fals_wall},
             {"threads", nthreads}, {"wall_s", wall}}},
           {"compare_methods", compare},
           {"regression_cases", cases},
           {"skipped_count", skipped.size()}};
  if (o.details.empty()) {
    out["skipped"] = std::move(skipped);
    out["rows"] = std::move(rows);
  } else {
    out["details"] = std::filesystem::path(o.details).filename().string();
    const Json details{{"schema", "railproof/margins-details/1"}, {"skipped", skipped}, {"rows", rows}};
    out_files.WriteJson(o.details, details);
  }
  out_files.WriteJson(o.json, out);
  out_files.Commit();
  std::printf("%zu location x train rows (%zu skipped near the line start), grid %.1f s, %zu NLP %.1f s, %zu falsifier %.1f s (%zu violation(s)); total %.1f s: %s\n",
              tasks.size(), skipped_total, grid_wall, nlp_runs, nlp_wall, fals_runs, fals_wall, fals_found, wall,
              pass ? "PASS" : "FAIL");
  for (const auto& job : jobs) {
    for (const auto& row : job.rows) {
      if (row.margin_mm < 0.0) {
        std::fprintf(stderr,
                     "margins: NEGATIVE MARGIN: line %s, running line %s, train %s, class %s, id '%s', stop limit at %.3f m, "
                     "margin %.3f m (%s)\n",
                     job.line->name.c_str(), job.rl->id.c_str(), job.train->name.c_str(), an::ToString(row.loc.cls),
                     row.loc.id.c_str(), static_cast<double>(row.loc.stop_limit_mm) / 1000.0, row.margin_mm / 1000.0,
                     row.method.c_str());
      }
    }
  }
  return pass ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return railproof::offline::RunTool("margins", [&] { return Main(argc, argv); });
}
