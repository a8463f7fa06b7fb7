// speedcheck_design: design calculator of the two-counter digital speed check (D3, digest
// §5; spec/design/br.md §6; REQ-SC-002, REQ-SC-004, REQ-SC-005, REQ-SC-006).
// Computes the reference design from the generated parameters (spec/parameters/
// speed_check.yaml) by the D3 design rule, its errors at every check speed, the TG
// constraint, the comparison with D3's 0.312 s sampling period, the f_1-n_1F design curve
// and, per train type (build/gen/trains/*.json), whether the supervision's speed allowance
// covers the design's error bound (REQ-SC-005). Prints a table; writes JSON and an SVG.
//
// Exit status: 0 verdict pass; 1 verdict fail; 2 bad input or error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/br/analysis/speedcheck_design.hpp"
#include "railproof/offline/cli.hpp"
#include "railproof/offline/json_reader.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/offline/output_file.hpp"

namespace {

namespace an = railproof::br::analysis;
using railproof::offline::InputError;
using railproof::offline::JsonNode;
using Json = nlohmann::ordered_json;

constexpr std::string_view kTrainSchema = "railproof/train-json/1";

void PrintHelp() {
  std::printf(
      "usage: speedcheck_design [--train-json FILE]... [--json FILE] [--svg FILE]\n"
      "                         [--target-basis design-max|check-speed] [--n1f N --f1 HZ]\n"
      "                         [--help]\n"
      "\n"
      "Design of the two-counter digital speed check (D3; REQ-SC-002/004/005/006). The\n"
      "reference inputs come from spec/parameters/sc.yaml (compiled in); timing\n"
      "terms T_c'' = T_s'' = T_s (ASM-023). The design rule of D3 gives n_1F = 2/(dV/V_E)\n"
      "and f_1 = f_M (rounded up to a whole Hz); the tool reports static, dynamic and total\n"
      "error, n_2E and the TG constraint f_1 <= f_2E n_1F / n_2E per check speed, the\n"
      "comparison with D3's 0.312 s sampling period and the f_1-n_1F design curve.\n"
      "\n"
      "  --train-json FILE   train type (schema %s, keys of spec/trains/*.yaml); checks that\n"
      "                      its allowance speed_error_ppm / speed_error_abs_mm_s covers the\n"
      "                      design's error bound up to max_speed_kmh + emergency_overspeed_kmh\n"
      "                      (REQ-SC-005); repeatable\n"
      "  --json FILE         write the results as JSON (\"requirements\", \"verdict\", rows\n"
      "                      with \"meets_target\")\n"
      "  --svg FILE          write the f_1-n_1F design curve (log f_1) with f_M, the\n"
      "                      asymptote and the design points\n"
      "  --target-basis B    design-max (default): the target is a fraction of V_E max at\n"
      "                      every check speed (D3: 0.25 %% = 0.625 km/h); check-speed: a\n"
      "                      fraction of each check speed\n"
      "  --n1f N --f1 HZ     evaluate this design instead of the D3 optimum\n"
      "\n"
      "Exit status: 0 pass, 1 fail (a row misses its target), 2 bad input.\n",
      std::string(kTrainSchema).c_str());
}

[[noreturn]] void Fail(const std::string& reason) {
  std::fprintf(stderr, "speedcheck_design: %s\n", reason.c_str());
  std::exit(2);
}

// --n1f and --f1.
const railproof::offline::NumberRule kPositive{.lo = 0.0,
                                           .lo_open = true,
                                           .reject_range_error = true,
                                           .message = "{opt}: not a positive number: '{value}'"};

struct TrainRow {
  std::string name;
  std::string file;
  double max_speed_kmh = 0.0;
  double overspeed_kmh = 0.0;
  std::int64_t v_max_mm_s = 0;
  std::int64_t ppm = 0;
  std::int64_t abs_mm_s = 0;
  an::AllowanceCheck check;
};

TrainRow LoadTrain(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path + ": cannot read train file");
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  const nlohmann::json doc = JsonNode::Parse(ss.str(), path);
  const JsonNode root(doc, "", path);
  const JsonNode schema = root.Key("schema");
  if (schema.String() != kTrainSchema) {
    schema.Fail("unsupported schema '" + schema.String() + "', expected '" +
                std::string(kTrainSchema) + "'");
  }
  TrainRow t;
  t.file = path;
  t.name = root.Key("name").String();
  const JsonNode vmax = root.Key("max_speed_kmh");
  t.max_speed_kmh = vmax.Number();
  if (t.max_speed_kmh <= 0.0) {
    vmax.Fail("must be positive");
  }
  if (const auto braking = root.OptKey("braking")) {
    if (const auto over = braking->OptKey("emergency_overspeed_kmh")) {
      t.overspeed_kmh = over->Number();
      if (t.overspeed_kmh < 0.0) {
        over->Fail("must be >= 0");
      }
    }
  }
  const JsonNode sup = root.Key("supervision");
  const JsonNode ppm = sup.Key("speed_error_ppm");
  t.ppm = ppm.Int();
  if (t.ppm < 0 || t.ppm > 1'000'000) {
    ppm.Fail("must be in 0..1000000");
  }
  const JsonNode abs = sup.Key("speed_error_abs_mm_s");
  t.abs_mm_s = abs.Int();
  if (t.abs_mm_s < 0) {
    abs.Fail("must be >= 0");
  }
  t.v_max_mm_s = an::KmhToMmSCeil(t.max_speed_kmh + t.overspeed_kmh);
  return t;
}

// ---- SVG (own small writer: the design curve needs a logarithmic f_1 axis) ---------------

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  return buf;
}

std::string Esc(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

struct DesignPoint {
  double n;
  double f;
  std::string label;
  std::string colour;
};

std::string RenderSvg(const an::SpeedCheckDesign& d, const an::SpeedCheckDesign& fixed,
                      double n_to) {
  const an::SpeedCheckInputs& in = d.inputs;
  constexpr double kW = 960;
  constexpr double kH = 640;
  constexpr double kL = 90;
  constexpr double kR = 30;
  constexpr double kT = 60;
  constexpr double kB = 70;
  const double x_min = 0.0;
  const double x_max = n_to;
  const double ly_min = 3.0;  // 1 kHz
  const double ly_max = 5.0;  // 100 kHz
  const auto X = [&](double n) { return kL + (n - x_min) / (x_max - x_min) * (kW - kL - kR); };
  const auto Y = [&](double f) {
    return kT + (ly_max - std::log10(f)) / (ly_max - ly_min) * (kH - kT - kB);
  };
  std::ostringstream s;
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kW << "\" height=\"" << kH
    << "\" viewBox=\"0 0 " << kW << ' ' << kH << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  s << "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>\n";
  s << "<defs><clipPath id=\"plot\"><rect x=\"" << kL << "\" y=\"" << kT << "\" width=\""
    << kW - kL - kR << "\" height=\"" << kH - kT - kB << "\"/></clipPath></defs>\n";
  char title[256];
  std::snprintf(title, sizeof title,
                "Two-counter speed check: f_1 - n_1F design curve (dV/V_E = %.2f %%, "
                "V_E = %g km/h, alpha = %g km/h/s, K = %g)",
                100.0 * in.target_ratio, in.max_speed_kmh, in.alpha_kmh_s, an::TimingFactor(in));
  s << "<text x=\"" << kW / 2 << "\" y=\"28\" text-anchor=\"middle\" font-size=\"15\">"
    << Esc(title) << "</text>\n";
  // grid and ticks
  for (double n = 0; n <= x_max + 1e-9; n += 500) {
    s << "<line x1=\"" << Num(X(n)) << "\" y1=\"" << kT << "\" x2=\"" << Num(X(n)) << "\" y2=\""
      << kH - kB << "\" stroke=\"#e0e0e0\"/>\n";
    s << "<text x=\"" << Num(X(n)) << "\" y=\"" << kH - kB + 18 << "\" text-anchor=\"middle\">"
      << static_cast<long long>(n) << "</text>\n";
  }
  for (int dec = 3; dec <= 5; ++dec) {
    for (const int m : {1, 2, 5}) {
      const double f = m * std::pow(10.0, dec);
      if (std::log10(f) > ly_max + 1e-9) {
        continue;
      }
      s << "<line x1=\"" << kL << "\" y1=\"" << Num(Y(f)) << "\" x2=\"" << kW - kR << "\" y2=\""
        << Num(Y(f)) << "\" stroke=\"" << (m == 1 ? "#c8c8c8" : "#eeeeee") << "\"/>\n";
      s << "<text x=\"" << kL - 6 << "\" y=\"" << Num(Y(f) + 4) << "\" text-anchor=\"end\">"
        << static_cast<long long>(f) << "</text>\n";
    }
  }
  s << "<rect x=\"" << kL << "\" y=\"" << kT << "\" width=\"" << kW - kL - kR << "\" height=\""
    << kH - kT - kB << "\" fill=\"none\" stroke=\"#000000\"/>\n";
  s << "<text x=\"" << (kL + kW - kR) / 2 << "\" y=\"" << kH - 22
    << "\" text-anchor=\"middle\">n_1F (counter-1 count at the check speed)</text>\n";
  s << "<text transform=\"translate(22," << (kT + kH - kB) / 2
    << ") rotate(-90)\" text-anchor=\"middle\">f_1 reference oscillator [Hz] (log)</text>\n";
  s << "<g clip-path=\"url(#plot)\">\n";
  // feasible region (above the curve: total error <= target)
  // own sampling of the curve, reaching closer to the asymptote than DesignCurve (clipped)
  std::vector<std::pair<double, double>> curve;
  {
    const double n_a0 = an::AsymptoteN1F(in);
    for (int i = 0; i <= 400; ++i) {
      const double n = n_a0 + (n_to - n_a0) * std::pow(10.0, -5.0 + 5.0 * i / 400.0);
      curve.emplace_back(n, an::DesignCurveF1Hz(in, n));
    }
  }
  std::string pts;
  std::string area = Num(X(curve.front().first)) + "," + Num(Y(std::pow(10.0, ly_max)));
  for (const auto& [n, f] : curve) {
    const double fy = std::min(f, std::pow(10.0, ly_max + 0.2));
    pts += Num(X(n)) + "," + Num(Y(fy)) + " ";
    area += " " + Num(X(n)) + "," + Num(Y(fy));
  }
  area += " " + Num(X(curve.back().first)) + "," + Num(Y(std::pow(10.0, ly_max)));
  s << "<polygon points=\"" << area << "\" fill=\"#4a90d9\" fill-opacity=\"0.10\"/>\n";
  // constant sampling-time lines f_1 = n_1F / T_s
  const std::pair<double, std::string> lines[] = {
      {d.sampling_s, "#2e8b57"}, {in.reference_sampling_s, "#b8860b"}};
  for (const auto& [ts, colour] : lines) {
    if (ts <= 0.0) {
      continue;
    }
    std::string line;  // f_1 = n_1F / T_s is a curve on the log axis
    for (int i = 0; i <= 100; ++i) {
      const double n = std::max(1.0, x_max * i / 100.0);
      line += Num(X(n)) + "," + Num(Y(n / ts)) + " ";
    }
    s << "<polyline points=\"" << line << "\" fill=\"none\" stroke=\"" << colour
      << "\" stroke-dasharray=\"3 3\"/>\n";
  }
  s << "<polyline points=\"" << pts << "\" fill=\"none\" stroke=\"#1f5fa8\" stroke-width=\"2\"/>\n";
  // asymptote and f_M
  const double n_a = an::AsymptoteN1F(in);
  const double f_m = an::MinimumF1Hz(in);
  s << "<line x1=\"" << Num(X(n_a)) << "\" y1=\"" << kT << "\" x2=\"" << Num(X(n_a)) << "\" y2=\""
    << kH - kB << "\" stroke=\"#c0392b\" stroke-dasharray=\"8 4\" stroke-width=\"1.5\"/>\n";
  s << "<line x1=\"" << kL << "\" y1=\"" << Num(Y(f_m)) << "\" x2=\"" << kW - kR << "\" y2=\""
    << Num(Y(f_m)) << "\" stroke=\"#7f8c8d\" stroke-dasharray=\"2 4\"/>\n";
  s << "</g>\n";
  char buf[200];
  std::snprintf(buf, sizeof buf, "asymptote n_1F = 1/(dV/V_E) = %.0f", n_a);
  s << "<text x=\"" << Num(X(n_a) + 6) << "\" y=\"" << kT + 16 << "\" fill=\"#c0392b\">" << Esc(buf)
    << "</text>\n";
  std::snprintf(buf, sizeof buf, "f_M = %.0f Hz", f_m);
  s << "<text x=\"" << kW - kR - 6 << "\" y=\"" << Num(Y(f_m) - 5)
    << "\" text-anchor=\"end\" fill=\"#555555\">" << Esc(buf) << "</text>\n";
  // design points
  std::vector<DesignPoint> points;
  std::snprintf(buf, sizeof buf, "minimum / design: n_1F = %lld, f_1 = %.0f Hz, T_s = %.4f s",
                static_cast<long long>(d.n_1f), d.f_1_hz, d.sampling_s);
  points.push_back({static_cast<double>(d.n_1f), d.f_1_hz, buf, "#c0392b"});
  if (in.reference_sampling_s > 0.0) {
    const double f_opt = static_cast<double>(d.n_1f) / in.reference_sampling_s;
    std::snprintf(buf, sizeof buf, "n_1F = %lld at T_s = %.3f s: f_1 = %.0f Hz (%.3f %%)",
                  static_cast<long long>(d.n_1f), in.reference_sampling_s, f_opt,
                  100.0 * an::TotalErrorKmh(in, in.max_speed_kmh, static_cast<double>(d.n_1f),
                                            f_opt) / in.max_speed_kmh);
    points.push_back({static_cast<double>(d.n_1f), f_opt, buf, "#b8860b"});
    std::snprintf(buf, sizeof buf, "T_s = %.3f s meeting the target: n_1F = %lld, f_1 = %.0f Hz",
                  in.reference_sampling_s, static_cast<long long>(fixed.n_1f), fixed.f_1_hz);
    points.push_back({static_cast<double>(fixed.n_1f), fixed.f_1_hz, buf, "#8e44ad"});
  }
  for (const DesignPoint& p : points) {
    s << "<circle cx=\"" << Num(X(p.n)) << "\" cy=\"" << Num(Y(p.f)) << "\" r=\"5\" fill=\""
      << p.colour << "\" stroke=\"#000000\"/>\n";
  }
  // legend
  double ly = kT + 40;
  const double lx = kL + (kW - kL - kR) * 0.42;
  const auto legend_line = [&](const std::string& colour, const std::string& dash,
                               const std::string& label) {
    s << "<line x1=\"" << Num(lx) << "\" y1=\"" << Num(ly - 4) << "\" x2=\"" << Num(lx + 28)
      << "\" y2=\"" << Num(ly - 4) << "\" stroke=\"" << colour << "\" stroke-width=\"2\""
      << (dash.empty() ? "" : " stroke-dasharray=\"" + dash + "\"") << "/>\n";
    s << "<text x=\"" << Num(lx + 36) << "\" y=\"" << Num(ly) << "\">" << Esc(label) << "</text>\n";
    ly += 18;
  };
  std::snprintf(buf, sizeof buf, "design curve: total error = %.3f km/h (shaded: meets it)",
                in.target_ratio * in.max_speed_kmh);
  legend_line("#1f5fa8", "", buf);
  std::snprintf(buf, sizeof buf, "T_s = %.4f s (optimum)", d.sampling_s);
  legend_line("#2e8b57", "3 3", buf);
  if (in.reference_sampling_s > 0.0) {
    std::snprintf(buf, sizeof buf, "T_s = %.3f s (D3 sampling period)", in.reference_sampling_s);
    legend_line("#b8860b", "3 3", buf);
  }
  for (const DesignPoint& p : points) {
    s << "<circle cx=\"" << Num(lx + 14) << "\" cy=\"" << Num(ly - 4) << "\" r=\"5\" fill=\""
      << p.colour << "\" stroke=\"#000000\"/>\n";
    s << "<text x=\"" << Num(lx + 36) << "\" y=\"" << Num(ly) << "\">" << Esc(p.label)
      << "</text>\n";
    ly += 18;
  }
  s << "</svg>\n";
  return s.str();
}

// ---- JSON ------------------------------------------------------------------------------

Json RowJson(const an::CheckSpeedRow& r) {
  Json j;
  j["check_speed_kmh"] = r.check_speed_kmh;
  j["f_2e_hz"] = r.f_2e_hz;
  j["n_2e"] = r.n_2e;
  j["gate_s"] = r.gate_s;
  j["threshold_kmh"] = r.threshold_kmh;
  j["static_error_kmh"] = r.static_kmh;
  j["dynamic_error_kmh"] = r.dynamic_kmh;
  j["dynamic_error_linear_kmh"] = r.dynamic_linear_kmh;
  j["total_error_kmh"] = r.total_kmh;
  j["static_error_pct_of_check_speed"] = 100.0 * r.static_kmh / r.check_speed_kmh;
  j["dynamic_error_pct_of_check_speed"] = 100.0 * r.dynamic_kmh / r.check_speed_kmh;
  j["total_error_pct_of_check_speed"] = r.total_pct_of_check;
  j["total_error_pct_of_design_max"] = r.total_pct_of_max;
  j["target_kmh"] = r.target_kmh;
  j["meets_target"] = r.meets_target;
  j["tg_limit_hz"] = r.tg_limit_hz;
  j["tg_constraint_met"] = r.tg_ok;
  return j;
}

Json ComparisonJson(const an::SpeedCheckDesign& d, const std::string& what) {
  const an::CheckSpeedRow& top = d.rows.front();
  Json j;
  j["what"] = what;
  j["n_1f"] = d.n_1f;
  j["f_1_hz"] = d.f_1_hz;
  j["sampling_s"] = d.sampling_s;
  j["total_error_kmh_at_max"] = top.total_kmh;
  j["total_error_pct_at_max"] = top.total_pct_of_max;
  // deliberately not "meets_target": comparison rows are not requirement rows
  j["within_target_at_every_check_speed"] = d.MeetsTarget();
  return j;
}

void WriteFile(const std::string& path, const std::string& text) {
  try {
    railproof::offline::WriteFileAtomic(path, text);
  } catch (const InputError& e) {
    Fail(e.what());
  }
}

}  // namespace

// @implements REQ-SC-002 REQ-SC-004 REQ-SC-005 REQ-SC-006
int main(int argc, char** argv) {
  std::vector<std::string> train_files;
  std::string json_path;
  std::string svg_path;
  an::SpeedCheckInputs in = an::ReferenceSpeedCheckInputs();
  double n1f_opt = 0.0;
  double f1_opt = 0.0;
  railproof::offline::CliParser cli(
      {.tool = "speedcheck_design", .values = railproof::offline::CliStyle::Values::kPaired, .see_help = false},
      PrintHelp);
  cli.List("--train-json", train_files)
      .Value("--json", json_path)
      .Value("--svg", svg_path)
      .Custom("--target-basis",
              [&](const std::string& b) -> std::optional<std::string> {
                if (b == "design-max") {
                  in.target_basis = an::TargetBasis::kDesignMaxSpeed;
                } else if (b == "check-speed") {
                  in.target_basis = an::TargetBasis::kCheckSpeed;
                } else {
                  return "--target-basis: expected design-max or check-speed, got '" + b + "'";
                }
                return std::nullopt;
              })
      .Custom("--n1f",
              [&](const std::string& v) -> std::optional<std::string> {
                if (auto error = railproof::offline::ParseCliNumber("--n1f", v, kPositive, n1f_opt)) {
                  return error;
                }
                if (n1f_opt != std::floor(n1f_opt) || n1f_opt > 1e9) {
                  return "--n1f: expected a whole number 1..1e9, got '" + v + "'";
                }
                return std::nullopt;
              })
      .Number("--f1", f1_opt, kPositive);
  cli.ParseOrExit(argc, argv);
  if ((n1f_opt > 0.0) != (f1_opt > 0.0)) {
    cli.Fail("--n1f and --f1 go together");
  }

  try {
    const bool custom = n1f_opt > 0.0;
    const an::SpeedCheckDesign d =
        custom ? an::MakeSpeedCheckDesign(in, static_cast<std::int64_t>(n1f_opt), f1_opt)
               : an::OptimumSpeedCheckDesign(in);
    // D3's sampling period: the optimum n_1F there, and the smallest n_1F meeting the target.
    const double ts_ref = in.reference_sampling_s;
    const an::SpeedCheckDesign at_ref =
        an::MakeSpeedCheckDesign(in, d.n_1f, static_cast<double>(d.n_1f) / ts_ref);
    const an::SpeedCheckDesign fixed = an::FixedSamplingSpeedCheckDesign(in, ts_ref);

    std::vector<TrainRow> trains;
    for (const std::string& f : train_files) {
      TrainRow t = LoadTrain(f);
      t.check = an::AllowanceCovers(d, t.ppm, t.abs_mm_s, t.v_max_mm_s);
      trains.push_back(std::move(t));
    }
    const bool trains_ok = std::all_of(trains.begin(), trains.end(),
                                       [](const TrainRow& t) { return t.check.Covered(); });
    const bool pass = d.MeetsTarget() && d.TgOk() && trains_ok;

    // ---- human-readable
    const double target_max = in.target_ratio * in.max_speed_kmh;
    std::printf("Two-counter digital speed check design (D3; ASM-023: T_c'' = T_s'' = T_s, K = %g)\n",
                an::TimingFactor(in));
    std::printf("  V_E max %g km/h, alpha %g km/h/s, target %.3f %% (%s; %.4f km/h at V_E max)\n",
                in.max_speed_kmh, in.alpha_kmh_s, 100.0 * in.target_ratio,
                an::ToString(in.target_basis), target_max);
    std::printf("  %s: n_1F = %lld, f_1 = %.1f Hz, T_s = n_1F/f_1 = %.4f s\n",
                custom ? "given design" : "D3 rule n_1F = 2/(dV/V_E), f_1 = f_M",
                static_cast<long long>(d.n_1f), d.f_1_hz, d.sampling_s);
    std::printf("  curve minimum f_M = %.1f Hz at n_1F = %.1f; asymptote n_1F = %.1f\n",
                an::MinimumF1Hz(in), an::OptimumN1F(in), an::AsymptoteN1F(in));
    std::printf("\n  check  f_2E[Hz]  n_2E  V_th[km/h]  static  dynamic  total[km/h]  %%check  "
                "%%max  target  ok   TG f1<=f2E*n1F/n2E\n");
    for (const an::CheckSpeedRow& r : d.rows) {
      std::printf("  %5.0f  %8.2f  %4lld  %10.3f  %6.4f  %7.4f  %11.4f  %6.3f  %5.3f  %6.4f  %-3s  "
                  "%s (%.0f <= %.0f)\n",
                  r.check_speed_kmh, r.f_2e_hz, static_cast<long long>(r.n_2e), r.threshold_kmh,
                  r.static_kmh, r.dynamic_kmh, r.total_kmh, r.total_pct_of_check,
                  r.total_pct_of_max, r.target_kmh, r.meets_target ? "yes" : "NO",
                  r.tg_ok ? "met" : "VIOLATED", d.f_1_hz, r.tg_limit_hz);
    }
    std::printf("\n  D3 sampling period T_s = %.3f s:\n", ts_ref);
    std::printf("    n_1F = %lld there: f_1 = %.1f Hz, total %.4f km/h = %.3f %% of V_E max (%s)\n",
                static_cast<long long>(at_ref.n_1f), at_ref.f_1_hz, at_ref.rows.front().total_kmh,
                at_ref.rows.front().total_pct_of_max,
                at_ref.MeetsTarget() ? "meets the target" : "misses the target");
    std::printf("    smallest n_1F meeting the target there: n_1F = %lld, f_1 = %.0f Hz, total "
                "%.4f km/h\n",
                static_cast<long long>(fixed.n_1f), fixed.f_1_hz, fixed.rows.front().total_kmh);
    if (!trains.empty()) {
      std::printf("\n  REQ-SC-005 allowance (ceil(v_m ppm/1e6) + abs) vs error bound, v <= v_max:\n");
      std::printf("  %-14s %9s %6s %5s  %s\n", "train", "v_max", "ppm", "abs",
                  "worst shortfall [mm/s] at v");
      for (const TrainRow& t : trains) {
        std::printf("  %-14s %9lld %6lld %5lld  %lld at %lld mm/s  %s\n", t.name.c_str(),
                    static_cast<long long>(t.v_max_mm_s), static_cast<long long>(t.ppm),
                    static_cast<long long>(t.abs_mm_s),
                    static_cast<long long>(t.check.worst_shortfall_mm_s),
                    static_cast<long long>(t.check.at_speed_mm_s),
                    t.check.Covered() ? "covered" : "NOT COVERED");
      }
    }
    std::printf("\nverdict: %s\n", pass ? "pass" : "fail");

    // ---- JSON
    if (!json_path.empty()) {
      Json j;
      j["tool"] = "speedcheck_design";
      Json reqs = Json::array({"REQ-SC-002", "REQ-SC-004"});
      if (!trains.empty()) {
        reqs.push_back("REQ-SC-005");
      }
      reqs.push_back("REQ-SC-006");
      j["requirements"] = reqs;
      j["verdict"] = pass ? "pass" : "fail";
      j["source"] = Json::array({"D3", "ASM-023"});
      Json ij;
      ij["max_speed_kmh"] = in.max_speed_kmh;
      ij["alpha_kmh_s"] = in.alpha_kmh_s;
      ij["target_ratio"] = in.target_ratio;
      ij["target_basis"] = an::ToString(in.target_basis);
      ij["target_kmh_at_max"] = target_max;
      ij["tc_over_ts"] = in.tc_over_ts;
      ij["ts2_over_ts"] = in.ts2_over_ts;
      ij["timing_factor_k"] = an::TimingFactor(in);
      ij["check_speeds_kmh"] = in.check_speeds_kmh;
      ij["tg_teeth"] = in.tg_teeth;
      ij["wheel_diameter_mm"] = in.wheel_diameter_mm;
      ij["reference_sampling_s"] = ts_ref;
      j["inputs"] = ij;
      Json dj;
      dj["rule"] = custom ? "given (--n1f, --f1)"
                          : "D3 optimum: n_1F = 2/(dV/V_E), f_1 = f_M rounded up to a whole Hz";
      dj["n_1f"] = d.n_1f;
      dj["f_1_hz"] = d.f_1_hz;
      dj["sampling_s"] = d.sampling_s;
      dj["meets_target_at_every_check_speed"] = d.MeetsTarget();
      dj["tg_constraint_met_at_every_check_speed"] = d.TgOk();
      j["design"] = dj;
      Json rows = Json::array();
      for (const an::CheckSpeedRow& r : d.rows) {
        rows.push_back(RowJson(r));
      }
      j["check_speeds"] = rows;
      Json cmp = Json::array();
      cmp.push_back(ComparisonJson(at_ref, "design n_1F at the D3 sampling period"));
      cmp.push_back(ComparisonJson(fixed, "smallest n_1F meeting the target at the D3 sampling period"));
      j["sampling_comparison"] = cmp;
      Json cj;
      cj["asymptote_n1f"] = an::AsymptoteN1F(in);
      cj["minimum"] = {{"n_1f", an::OptimumN1F(in)}, {"f_1_hz", an::MinimumF1Hz(in)}};
      Json pts = Json::array();
      for (const auto& [n, f] : an::DesignCurve(in, 10.0 * an::AsymptoteN1F(in), 60)) {
        pts.push_back(Json::array({n, f}));
      }
      cj["points_n1f_f1_hz"] = pts;
      j["design_curve"] = cj;
      Json bj = Json::array();
      for (const double v : {0.0, 30.0, 70.0, 110.0, 160.0, 210.0, 250.0}) {
        const std::int64_t mm = an::KmhToMmSCeil(v);
        bj.push_back({{"speed_mm_s", mm}, {"bound_mm_s", an::SpeedErrorBoundMmS(d, mm)}});
      }
      j["speed_error_bound"] = {
          {"formula", "ceil(v / n_1F + alpha T_s K), mm/s"}, {"samples", bj}};
      Json tj = Json::array();
      for (const TrainRow& t : trains) {
        tj.push_back({{"train", t.name},
                      {"file", t.file},
                      {"max_speed_kmh", t.max_speed_kmh},
                      {"emergency_overspeed_kmh", t.overspeed_kmh},
                      {"v_max_checked_mm_s", t.v_max_mm_s},
                      {"speed_error_ppm", t.ppm},
                      {"speed_error_abs_mm_s", t.abs_mm_s},
                      {"worst_shortfall_mm_s", t.check.worst_shortfall_mm_s},
                      {"at_speed_mm_s", t.check.at_speed_mm_s},
                      {"meets_target", t.check.Covered()}});
      }
      j["trains"] = tj;
      Json notes = Json::array();
      notes.push_back(
          "target basis design_max_speed: D3 states 0.25 % as 0.625 km/h; with one sampling "
          "time for all check speeds the dynamic error alpha T_s K is the same in km/h at every "
          "check speed, so a fraction of each check speed is not achievable below V_E max "
          "(see total_error_pct_of_check_speed)");
      double worst_dev = 0.0;
      double worst_at = 0.0;
      for (const an::CheckSpeedRow& r : d.rows) {
        const double dev = 100.0 * (1.0 - r.threshold_kmh / r.check_speed_kmh);
        if (dev > worst_dev) {
          worst_dev = dev;
          worst_at = r.check_speed_kmh;
        }
      }
      char note[256];
      std::snprintf(note, sizeof note,
                    "n_2E = floor(f_2E T_s): the check brakes from V_th = V_E n_2E / (f_2E T_s) "
                    "<= V_E (safe side; at most %.2f %% below the check speed, at %g km/h)",
                    worst_dev, worst_at);
      notes.push_back(note);
      j["notes"] = notes;
      WriteFile(json_path, j.dump(1) + "\n");
    }
    if (!svg_path.empty()) {
      WriteFile(svg_path, RenderSvg(d, fixed, 10.0 * an::AsymptoteN1F(in)));
    }
    return pass ? 0 : 1;
  } catch (const InputError& e) {
    Fail(e.what());
  } catch (const std::exception& e) {
    Fail(e.what());
  }
}
