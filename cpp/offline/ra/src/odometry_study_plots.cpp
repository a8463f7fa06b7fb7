// Odometry study plots (odometry_study.hpp): per scenario and the summary plots, drawn with
// offline::SvgPlot; stacked panels are nested <svg> elements in one file (as the margins tool).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "railproof/ra/analysis/odometry_study.hpp"
#include "railproof/offline/svg.hpp"

namespace railproof::ra::analysis {

namespace {

using Points = std::vector<std::pair<double, double>>;
using offline::SvgPlot;
using offline::SvgStyle;

constexpr double kPanelHeight = 860.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Stacks rendered SvgPlot documents vertically into one SVG document.
std::string Stack(const std::vector<std::string>& panels) {
  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"1560\" height=\""
    << static_cast<int>(kPanelHeight * static_cast<double>(panels.size())) << "\" viewBox=\"0 0 1560 "
    << static_cast<int>(kPanelHeight * static_cast<double>(panels.size())) << "\">\n";
  for (std::size_t i = 0; i < panels.size(); ++i) {
    std::string p = panels[i].substr(panels[i].find("<svg"));
    p.replace(0, 4, "<svg y=\"" + std::to_string(static_cast<int>(kPanelHeight * static_cast<double>(i))) + "\"");
    o << p << "\n";
  }
  o << "</svg>\n";
  return o.str();
}

double Ms(std::int64_t mm) { return static_cast<double>(mm) / 1000.0; }
double Sec(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }

std::pair<double, double> YRange(const std::vector<Points>& series, double pad_fraction, double min_span) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const Points& s : series) {
    for (const auto& [x, y] : s) {
      if (std::isfinite(y)) {
        lo = std::min(lo, y);
        hi = std::max(hi, y);
      }
    }
  }
  if (!std::isfinite(lo)) {
    return {-1.0, 1.0};
  }
  if (hi - lo < min_span) {
    const double mid = 0.5 * (lo + hi);
    lo = mid - 0.5 * min_span;
    hi = mid + 0.5 * min_span;
  }
  const double pad = (hi - lo) * pad_fraction;
  return {lo - pad, hi + pad};
}

const char* kGradientColours[] = {"#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#d62728", "#8c564b", "#17becf"};

// Shades the simulated slip/slide events over the full height of a panel.
void ShadeEvents(SvgPlot& plot, const ScenarioStudy& st, double y0, double y1) {
  for (const ra::analysis::SlipEvent& e : st.sim.events) {
    plot.AddRect(Sec(e.start_ms), Sec(e.end_ms), y0, y1, e.kind == ra::analysis::SlipKind::kSlip ? "#ffb000" : "#00a0ff",
                 e.tg_axle ? 0.22 : 0.10);
  }
}

void MarkEpisodes(SvgPlot& plot, const StudyRun& r, const std::vector<double>& y_at) {
  for (const Episode& ep : r.episodes) {
    const StudyCycle& d = r.cycles[ep.detect];
    plot.AddMarker(Sec(d.time_ms), y_at[ep.detect], "#d00000", "detect");
    const StudyCycle& e = r.cycles[ep.end];
    switch (ep.outcome) {
      case EpisodeOutcome::kAdopted:
        plot.AddMarker(Sec(e.time_ms), y_at[ep.end], "#008000", "re-adhesion (" + std::to_string(ep.adopted) + ")");
        break;
      case EpisodeOutcome::kTimeout:
        plot.AddMarker(Sec(e.time_ms), y_at[ep.end], "#000000", "timeout: stop");
        break;
      case EpisodeOutcome::kSensorFailure:
        plot.AddMarker(Sec(e.time_ms), y_at[ep.end], "#800080", "sensor failure: stop");
        break;
      case EpisodeOutcome::kOpen:
        break;
    }
  }
}

std::string AccelPanel(const ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  const double ta = static_cast<double>(r.config.detect_threshold_mm_s2) / 1000.0;
  Points ax, ap, hi, lo;
  std::vector<double> y_at;
  for (const StudyCycle& c : r.cycles) {
    const double t = Sec(c.time_ms);
    const bool ok = c.out.input_error == ra::InputError::kNone;
    ax.emplace_back(t, ok ? c.out.ax_avg : kNaN);
    ap.emplace_back(t, ok ? c.out.ap_avg : kNaN);
    hi.emplace_back(t, ok ? c.out.ap_avg + ta : kNaN);
    lo.emplace_back(t, ok ? c.out.ap_avg - ta : kNaN);
    y_at.push_back(ok ? c.out.ax_avg : 0.0);
  }
  auto [y0, y1] = YRange({ax, ap, hi, lo}, 0.08, 1.0);
  const double x1 = std::max(1.0, st.sim.simulated_s);
  SvgPlot plot(0.0, x1, y0, y1);
  plot.SetTitle(st.scenario.name + ": averaged IMU acceleration a_x vs TG acceleration Ap (Ta = " +
                [&] {
                  char b[32];
                  std::snprintf(b, sizeof b, "%.2f", ta);
                  return std::string(b);
                }() + " m/s^2)");
  plot.SetXLabel("time (s)");
  plot.SetYLabel("acceleration (m/s^2)");
  ShadeEvents(plot, st, y0, y1);
  const SvgStyle s_ax{"#c00000", 1.8, "", 1.0};
  const SvgStyle s_ap{"#0050c0", 1.8, "", 1.0};
  const SvgStyle s_band{"#0050c0", 1.0, "4 3", 0.7};
  plot.AddPolyline(hi, s_band);
  plot.AddPolyline(lo, s_band);
  plot.AddPolyline(ap, s_ap);
  plot.AddPolyline(ax, s_ax);
  MarkEpisodes(plot, r, y_at);
  plot.AddLegend("a_x (IMU, 3 s avg)", s_ax);
  plot.AddLegend("Ap (TG, 3 s avg)", s_ap);
  plot.AddLegend("threshold band Ap +- Ta", s_band);
  plot.AddLegend("sim. slip (orange) / slide (blue)", SvgStyle{"#ffb000", 6.0, "", 0.4}, true);
  return plot.Render();
}

std::string SpeedPanel(const ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  Points vt, vtg, vc0, vc1, vout;
  std::vector<double> y_at;
  for (const StudyCycle& c : r.cycles) {
    const double t = Sec(c.time_ms);
    const bool comp = c.machine.mode == ra::Mode::kCompensating;
    const bool ok = c.out.input_error == ra::InputError::kNone;
    vt.emplace_back(t, c.true_speed_m_s * 3.6);
    vtg.emplace_back(t, ok ? c.out.v_tg * 3.6 : kNaN);
    vc0.emplace_back(t, comp && c.machine.candidates[0].active ? c.out.v_comp[0] * 3.6 : kNaN);
    vc1.emplace_back(t, comp && c.machine.candidates[1].active ? c.out.v_comp[1] * 3.6 : kNaN);
    vout.emplace_back(t, c.out.position_valid ? static_cast<double>(c.out.speed_mm_s) * 0.0036 : kNaN);
    y_at.push_back(c.true_speed_m_s * 3.6);
  }
  auto [y0, y1] = YRange({vt, vtg, vc0, vc1}, 0.06, 5.0);
  y0 = std::min(0.0, y0);
  SvgPlot plot(0.0, std::max(1.0, st.sim.simulated_s), y0, y1);
  plot.SetTitle(st.scenario.name + ": true speed, TG speed and compensated speeds");
  plot.SetXLabel("time (s)");
  plot.SetYLabel("speed (km/h)");
  ShadeEvents(plot, st, y0, y1);
  const SvgStyle s_true{"#000000", 2.4, "", 1.0};
  const SvgStyle s_tg{"#0050c0", 1.5, "", 1.0};
  const SvgStyle s_c0{"#c00000", 2.0, "", 1.0};
  const SvgStyle s_c1{"#e07000", 2.0, "5 3", 1.0};
  const SvgStyle s_out{"#008000", 1.0, "2 2", 1.0};
  plot.AddPolyline(vt, s_true);
  plot.AddPolyline(vtg, s_tg);
  plot.AddPolyline(vout, s_out);
  plot.AddPolyline(vc0, s_c0);
  plot.AddPolyline(vc1, s_c1);
  MarkEpisodes(plot, r, y_at);
  plot.AddLegend("true speed", s_true);
  plot.AddLegend("TG speed", s_tg);
  plot.AddLegend("compensated, start point 1", s_c0);
  plot.AddLegend("compensated, start point 2", s_c1);
  plot.AddLegend("reported speed", s_out);
  return plot.Render();
}

std::string EnvelopePanel(const ScenarioStudy& st) {
  Points err, fe, re, berr, bfe, bre;
  const auto fill = [](const StudyRun& r, Points& e, Points& f, Points& b) {
    for (const StudyCycle& c : r.cycles) {
      const double t = Sec(c.time_ms);
      if (!c.out.position_valid) {
        e.emplace_back(t, kNaN);
        f.emplace_back(t, kNaN);
        b.emplace_back(t, kNaN);
        continue;
      }
      e.emplace_back(t, c.true_front_m - Ms(c.out.front_mm));
      f.emplace_back(t, Ms(c.out.front_error_mm));
      b.emplace_back(t, -Ms(c.out.rear_error_mm));
    }
  };
  fill(st.primary, err, fe, re);
  fill(st.baseline, berr, bfe, bre);
  auto [y0, y1] = YRange({err, fe, re, berr, bfe, bre}, 0.06, 2.0);
  SvgPlot plot(0.0, std::max(1.0, st.sim.simulated_s), y0, y1);
  plot.SetTitle(st.scenario.name + ": true front - nominal front inside [-rear error, +front error]");
  plot.SetXLabel("time (s)");
  plot.SetYLabel("position relative to the nominal front (m)");
  ShadeEvents(plot, st, y0, y1);
  const SvgStyle s_env{"#0050c0", 2.0, "", 1.0};
  const SvgStyle s_err{"#c00000", 2.0, "", 1.0};
  const SvgStyle s_benv{"#808080", 1.4, "6 4", 1.0};
  const SvgStyle s_berr{"#e07000", 1.2, "2 2", 1.0};
  plot.AddPolyline(bfe, s_benv);
  plot.AddPolyline(bre, s_benv);
  plot.AddPolyline(berr, s_berr);
  plot.AddPolyline(fe, s_env);
  plot.AddPolyline(re, s_env);
  plot.AddPolyline(err, s_err);
  plot.AddHLine(0.0, "", SvgStyle{"#000000", 0.8, "", 1.0});
  plot.AddLegend("IMU: +front / -rear error", s_env);
  plot.AddLegend("IMU: true - nominal front", s_err);
  plot.AddLegend("former: +front / -rear error", s_benv);
  plot.AddLegend("former: true - nominal front", s_berr);
  return plot.Render();
}

std::string BoundPanel(const ScenarioStudy& st) {
  const StudyRun& r = st.primary;
  const double rate = static_cast<double>(r.config.imu_rate_error_udeg_s) / 1e6;
  Points err, bp, bn, tgerr;
  for (std::size_t k = 0; k < r.cycles.size(); ++k) {
    const StudyCycle& c = r.cycles[k];
    const double t = Sec(c.time_ms);
    int cand = -1;
    for (int i = 0; i < ra::kMaxStartPoints && c.machine.mode == ra::Mode::kCompensating; ++i) {
      if (c.machine.candidates[static_cast<std::size_t>(i)].active) {
        cand = i;
        break;
      }
    }
    const std::int32_t age = cand >= 0 ? c.machine.candidates[static_cast<std::size_t>(cand)].age_cycles : 0;
    if (cand < 0 || age < 1 || static_cast<std::size_t>(age) > k) {
      err.emplace_back(t, kNaN);
      bp.emplace_back(t, kNaN);
      bn.emplace_back(t, kNaN);
      tgerr.emplace_back(t, kNaN);
      continue;
    }
    const std::size_t s = k - static_cast<std::size_t>(age);
    double g = 0.0;
    for (std::size_t j = s; j <= k; ++j) {
      g = std::max(g, r.cycles[j].gradient_permille);
    }
    const double bound = ra::ErrorBoundM(static_cast<double>(age) / 10.0, g, rate);
    const std::size_t ref = ErrorReference(r.cycles, s, k);
    err.emplace_back(t, (Ms(c.out.front_mm) - Ms(r.cycles[ref].out.front_mm)) -
                            (c.true_front_m - r.cycles[ref].true_front_m));
    bp.emplace_back(t, bound);
    bn.emplace_back(t, -bound);
    const double tg = (st.sim.truth[k].tg_distance_m - st.sim.truth[s].tg_distance_m) -
                      (c.true_front_m - r.cycles[s].true_front_m);
    tgerr.emplace_back(t, tg);
  }
  // the TG error can be far larger than the bound: clip the axis to 1.5 x the bound
  auto [y0, y1] = YRange({err, bp, bn}, 0.1, 0.2);
  const double ylim = std::max(std::abs(y0), std::abs(y1)) * 1.5;
  SvgPlot plot(0.0, std::max(1.0, st.sim.simulated_s), -ylim, ylim);
  plot.SetTitle(st.scenario.name + ": compensated distance error since the start point (or a balise fix) vs +-ErrorBound(t, g)" +
                (r.episodes.empty() ? std::string(" (no compensation in this run)") : std::string()));
  plot.SetXLabel("time (s)");
  plot.SetYLabel("distance error (m)");
  ShadeEvents(plot, st, -ylim, ylim);
  const SvgStyle s_b{"#0050c0", 2.0, "", 1.0};
  const SvgStyle s_e{"#c00000", 2.0, "", 1.0};
  const SvgStyle s_tg{"#808080", 1.2, "3 3", 1.0};
  plot.AddPolyline(bp, s_b);
  plot.AddPolyline(bn, s_b);
  plot.AddPolyline(tgerr, s_tg);
  plot.AddPolyline(err, s_e);
  plot.AddHLine(0.0, "", SvgStyle{"#000000", 0.8, "", 1.0});
  for (std::size_t i = 0; i < r.episodes.size(); ++i) {
    const EpisodeError& e = r.errors[i];
    if (e.valid) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "ratio %.3f", e.ratio);
      plot.AddMarker(Sec(r.cycles[e.stop].time_ms), std::clamp(e.error_m, -ylim, ylim),
                     e.ratio <= 1.0 ? "#008000" : "#ff0000", buf);
    }
  }
  plot.AddLegend("+-ErrorBound(t, g)", s_b);
  plot.AddLegend("compensated - true distance", s_e);
  plot.AddLegend("TG - true distance (clipped)", s_tg);
  return plot.Render();
}

}  // namespace

std::string ScenarioPlotSvg(const ScenarioStudy& st) {
  return Stack({AccelPanel(st), SpeedPanel(st), EnvelopePanel(st), BoundPanel(st)});
}

std::string MarginPlotSvg(const std::vector<double>& gradients_permille, double t_max_s, const VehicleAccelBounds& b) {
  std::vector<std::string> panels;
  const int n = 160;
  const auto grid = [&](auto f) {
    Points p;
    for (int i = 0; i <= n; ++i) {
      const double t = t_max_s * i / n;
      p.emplace_back(t, f(t));
    }
    return p;
  };
  {
    std::vector<Points> full, tenth;
    for (const double g : gradients_permille) {
      full.push_back(grid([&](double t) { return ImuMarginM(t, g, RateErrorFullDegS()); }));
      tenth.push_back(grid([&](double t) { return ImuMarginM(t, g, RateErrorTenthDegS()); }));
    }
    auto [y0, y1] = YRange(full, 0.05, 1.0);
    SvgPlot plot(0.0, t_max_s, 0.0, y1);
    plot.SetTitle("IMU method: permanent margin per side Delta_d(T_max, g) (D1 error model)");
    plot.SetXLabel("maximum compensation time T_max (s)");
    plot.SetYLabel("margin per side (m)");
    for (std::size_t i = 0; i < gradients_permille.size(); ++i) {
      const std::string col = kGradientColours[i % 7];
      const SvgStyle sf{col, 2.0, "", 1.0};
      const SvgStyle st{col, 1.6, "6 3", 1.0};
      plot.AddPolyline(full[i], sf);
      plot.AddPolyline(tenth[i], st);
      char buf[96];
      std::snprintf(buf, sizeof buf, "g = %g permille, 0.025 deg/s", gradients_permille[i]);
      plot.AddLegend(buf, sf);
      std::snprintf(buf, sizeof buf, "g = %g permille, 0.0025 deg/s", gradients_permille[i]);
      plot.AddLegend(buf, st);
    }
    (void)y0;
    panels.push_back(plot.Render());
  }
  {
    std::vector<Points> imu, slip, slide;
    for (const double g : gradients_permille) {
      imu.push_back(grid([&](double t) { return 2.0 * ImuMarginM(t, g, RateErrorTenthDegS()); }));
      slip.push_back(grid([&](double t) { return BaselineExtensionM(t, g, b).slip_m; }));
      slide.push_back(grid([&](double t) { return BaselineExtensionM(t, g, b).slide_m; }));
    }
    std::vector<Points> all = imu;
    all.insert(all.end(), slip.begin(), slip.end());
    all.insert(all.end(), slide.begin(), slide.end());
    auto [y0, y1] = YRange(all, 0.05, 1.0);
    SvgPlot plot(0.0, t_max_s, 0.0, y1);
    char title[256];
    std::snprintf(title, sizeof title,
                  "Growth of the occupied range: IMU 2 Delta_d (permanent, 0.0025 deg/s) vs former method after "
                  "a slip/slide of T (a %.2f-%.2f, d %.2f-%.2f m/s^2)",
                  b.accel_min, b.accel_max, b.decel_min, b.decel_max);
    plot.SetTitle(title);
    plot.SetXLabel("compensation time / slip duration T (s)");
    plot.SetYLabel("front + rear extension (m)");
    for (std::size_t i = 0; i < gradients_permille.size(); ++i) {
      const std::string col = kGradientColours[i % 7];
      const SvgStyle si{col, 2.4, "", 1.0};
      const SvgStyle ss{col, 1.4, "2 3", 1.0};
      const SvgStyle sd{col, 1.6, "8 4", 1.0};
      plot.AddPolyline(imu[i], si);
      plot.AddPolyline(slip[i], ss);
      plot.AddPolyline(slide[i], sd);
      char buf[96];
      std::snprintf(buf, sizeof buf, "g = %g: IMU 2 Delta_d", gradients_permille[i]);
      plot.AddLegend(buf, si);
      std::snprintf(buf, sizeof buf, "g = %g: former, slip", gradients_permille[i]);
      plot.AddLegend(buf, ss);
      std::snprintf(buf, sizeof buf, "g = %g: former, slide (coasting)", gradients_permille[i]);
      plot.AddLegend(buf, sd);
    }
    (void)y0;
    panels.push_back(plot.Render());
  }
  return Stack(panels);
}

std::string ClearingPlotSvg(const std::vector<TrainMarginCheck>& trains, double max_margin_m) {
  const double a = ClearingAccelMS2();
  std::vector<Points> curves;
  for (const TrainMarginCheck& t : trains) {
    Points p;
    for (int i = 0; i <= 150; ++i) {
      const double m = max_margin_m * i / 150.0;
      p.emplace_back(m, ClearingCostS(t.length_m, m, a));
    }
    curves.push_back(p);
  }
  auto [y0, y1] = YRange(curves, 0.05, 1.0);
  SvgPlot plot(0.0, max_margin_m, 0.0, y1);
  char title[200];
  std::snprintf(title, sizeof title,
                "Clearing-time cost of the permanent margin: extra time to clear L + 2 x margin from rest at %.2f m/s^2",
                a);
  plot.SetTitle(title);
  plot.SetXLabel("margin per side (m)");
  plot.SetYLabel("extra clearing time (s)");
  for (std::size_t i = 0; i < trains.size(); ++i) {
    const std::string col = kGradientColours[i % 7];
    const SvgStyle s{col, 2.2, "", 1.0};
    plot.AddPolyline(curves[i], s);
    const double m = static_cast<double>(trains[i].readhesion_margin_mm) / 1000.0;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s: %.1f m, +%.1f s", trains[i].train.c_str(), m, trains[i].clearing_extra_s);
    plot.AddMarker(m, trains[i].clearing_extra_s, col, buf);
    std::snprintf(buf, sizeof buf, "%s (L = %.0f m, line %s)", trains[i].train.c_str(), trains[i].length_m,
                  trains[i].line.c_str());
    plot.AddLegend(buf, s);
  }
  (void)y0;
  return plot.Render();
}

}  // namespace railproof::ra::analysis
