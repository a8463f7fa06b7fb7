// Odometry study plots (odometry_study.hpp): per scenario and the summary plots, drawn with
// offline::SvgPlot; the panels of one file are stacked by offline::SvgStack.
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

using Points = offline::SvgPoints;
using offline::SvgPlot;
using offline::SvgStyle;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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

// A curve of a panel; an empty legend: no legend entry.
struct Series {
  Points points;
  SvgStyle style;
  std::string legend;
};

// A panel over the scenario's time axis: the simulated slip/slide events shaded over the
// full height, the series drawn in order, the zero line if asked.
SvgPlot TimePanel(const ScenarioStudy& st, const std::string& title, const std::string& y_label, double y0, double y1,
                  const std::vector<Series>& series, bool zero_line = false) {
  SvgPlot plot(0.0, std::max(1.0, st.sim.simulated_s), y0, y1);
  plot.SetTitle(st.scenario.name + ": " + title);
  plot.SetXLabel("time (s)");
  plot.SetYLabel(y_label);
  for (const ra::analysis::SlipEvent& e : st.sim.events) {
    plot.AddRect(Sec(e.start_ms), Sec(e.end_ms), y0, y1, e.kind == ra::analysis::SlipKind::kSlip ? "#ffb000" : "#00a0ff",
                 e.tg_axle ? 0.22 : 0.10);
  }
  for (const Series& s : series) {
    plot.AddPolyline(s.points, s.style);
    if (!s.legend.empty()) {
      plot.AddLegend(s.legend, s.style);
    }
  }
  if (zero_line) {
    plot.AddHLine(0.0, "", SvgStyle{"#000000", 0.8, "", 1.0});
  }
  return plot;
}

// The y range of a panel's series.
std::pair<double, double> YRange(const std::vector<Series>& series, double pad_fraction, double min_span) {
  std::vector<Points> points;
  for (const Series& s : series) {
    points.push_back(s.points);
  }
  return YRange(points, pad_fraction, min_span);
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

std::string Fixed2(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

SvgPlot AccelPanel(const ScenarioStudy& st) {
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
  const SvgStyle band{"#0050c0", 1.0, "4 3", 0.7};
  const std::vector<Series> series{{hi, band, "threshold band Ap +- Ta"},
                                   {lo, band, ""},
                                   {ap, SvgStyle{"#0050c0", 1.8, "", 1.0}, "Ap (TG, 3 s avg)"},
                                   {ax, SvgStyle{"#c00000", 1.8, "", 1.0}, "a_x (IMU, 3 s avg)"}};
  const auto [y0, y1] = YRange(series, 0.08, 1.0);
  SvgPlot plot = TimePanel(st, "averaged IMU acceleration a_x vs TG acceleration Ap (Ta = " + Fixed2(ta) + " m/s^2)",
                           "acceleration (m/s^2)", y0, y1, series);
  MarkEpisodes(plot, r, y_at);
  plot.AddLegend("sim. slip (orange) / slide (blue)", SvgStyle{"#ffb000", 6.0, "", 0.4}, SvgPlot::LegendKind::kBox);
  return plot;
}

SvgPlot SpeedPanel(const ScenarioStudy& st) {
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
  const std::vector<Series> series{{vt, SvgStyle{"#000000", 2.4, "", 1.0}, "true speed"},
                                   {vtg, SvgStyle{"#0050c0", 1.5, "", 1.0}, "TG speed"},
                                   {vout, SvgStyle{"#008000", 1.0, "2 2", 1.0}, "reported speed"},
                                   {vc0, SvgStyle{"#c00000", 2.0, "", 1.0}, "compensated, start point 1"},
                                   {vc1, SvgStyle{"#e07000", 2.0, "5 3", 1.0}, "compensated, start point 2"}};
  const auto range = YRange({series[0], series[1], series[3], series[4]}, 0.06, 5.0);
  SvgPlot plot = TimePanel(st, "true speed, TG speed and compensated speeds", "speed (km/h)",
                           std::min(0.0, range.first), range.second, series);
  MarkEpisodes(plot, r, y_at);
  return plot;
}

SvgPlot EnvelopePanel(const ScenarioStudy& st) {
  // true front - nominal front, +front error and -rear error of a run (NaN without a position)
  const auto envelope = [](const StudyRun& r) {
    std::array<Points, 3> p;  // error, +front, -rear
    for (const StudyCycle& c : r.cycles) {
      const double t = Sec(c.time_ms);
      const bool ok = c.out.position_valid;
      p[0].emplace_back(t, ok ? c.true_front_m - Ms(c.out.front_mm) : kNaN);
      p[1].emplace_back(t, ok ? Ms(c.out.front_error_mm) : kNaN);
      p[2].emplace_back(t, ok ? -Ms(c.out.rear_error_mm) : kNaN);
    }
    return p;
  };
  const auto imu = envelope(st.primary);
  const auto former = envelope(st.baseline);
  const SvgStyle s_benv{"#808080", 1.4, "6 4", 1.0};
  const SvgStyle s_env{"#0050c0", 2.0, "", 1.0};
  const std::vector<Series> series{{former[1], s_benv, "former: +front / -rear error"},
                                   {former[2], s_benv, ""},
                                   {former[0], SvgStyle{"#e07000", 1.2, "2 2", 1.0}, "former: true - nominal front"},
                                   {imu[1], s_env, "IMU: +front / -rear error"},
                                   {imu[2], s_env, ""},
                                   {imu[0], SvgStyle{"#c00000", 2.0, "", 1.0}, "IMU: true - nominal front"}};
  const auto [y0, y1] = YRange(series, 0.06, 2.0);
  return TimePanel(st, "true front - nominal front inside [-rear error, +front error]",
                   "position relative to the nominal front (m)", y0, y1, series, true);
}

SvgPlot BoundPanel(const ScenarioStudy& st) {
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
      for (Points* p : {&err, &bp, &bn, &tgerr}) {
        p->emplace_back(t, kNaN);
      }
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
  const SvgStyle s_b{"#0050c0", 2.0, "", 1.0};
  const std::vector<Series> series{{bp, s_b, "+-ErrorBound(t, g)"},
                                   {bn, s_b, ""},
                                   {tgerr, SvgStyle{"#808080", 1.2, "3 3", 1.0}, "TG - true distance (clipped)"},
                                   {err, SvgStyle{"#c00000", 2.0, "", 1.0}, "compensated - true distance"}};
  // the TG error can be far larger than the bound: clip the axis to 1.5 x the bound
  const auto [y0, y1] = YRange({series[0], series[1], series[3]}, 0.1, 0.2);
  const double ylim = std::max(std::abs(y0), std::abs(y1)) * 1.5;
  SvgPlot plot = TimePanel(st,
                           "compensated distance error since the start point (or a balise fix) vs +-ErrorBound(t, g)" +
                               (r.episodes.empty() ? std::string(" (no compensation in this run)") : std::string()),
                           "distance error (m)", -ylim, ylim, series, true);
  for (std::size_t i = 0; i < r.episodes.size(); ++i) {
    const EpisodeError& e = r.errors[i];
    if (e.valid) {
      char buf[96];
      std::snprintf(buf, sizeof buf, "ratio %.3f", e.ratio);
      plot.AddMarker(Sec(r.cycles[e.stop].time_ms), std::clamp(e.error_m, -ylim, ylim),
                     e.ratio <= 1.0 ? "#008000" : "#ff0000", buf);
    }
  }
  return plot;
}

}  // namespace

std::string ScenarioPlotSvg(const ScenarioStudy& st) {
  return offline::SvgStack({AccelPanel(st), SpeedPanel(st), EnvelopePanel(st), BoundPanel(st)});
}

std::string MarginPlotSvg(const std::vector<double>& gradients_permille, double t_max_s, const VehicleAccelBounds& b) {
  const int n = 160;
  const auto grid = [&](auto f) {
    Points p;
    for (int i = 0; i <= n; ++i) {
      const double t = t_max_s * i / n;
      p.emplace_back(t, f(t));
    }
    return p;
  };
  const auto label = [](const char* format, double g) {
    char buf[96];
    std::snprintf(buf, sizeof buf, format, g);
    return std::string(buf);
  };
  // one series per gradient and kind, coloured by the gradient; the y axis from 0
  const auto panel = [&](const std::string& title, const std::string& x_label, const std::string& y_label,
                         const std::vector<Series>& series) {
    SvgPlot plot(0.0, t_max_s, 0.0, YRange(series, 0.05, 1.0).second);
    plot.SetTitle(title);
    plot.SetXLabel(x_label);
    plot.SetYLabel(y_label);
    for (const Series& s : series) {
      plot.AddSeries(s.points, s.style, s.legend);
    }
    return plot;
  };
  std::vector<Series> margins, growth;
  for (std::size_t i = 0; i < gradients_permille.size(); ++i) {
    const double g = gradients_permille[i];
    const std::string col = kGradientColours[i % 7];
    margins.push_back({grid([&](double t) { return ImuMarginM(t, g, RateErrorFullDegS()); }), SvgStyle{col, 2.0, "", 1.0},
                       label("g = %g permille, 0.025 deg/s", g)});
    margins.push_back({grid([&](double t) { return ImuMarginM(t, g, RateErrorTenthDegS()); }),
                       SvgStyle{col, 1.6, "6 3", 1.0}, label("g = %g permille, 0.0025 deg/s", g)});
    growth.push_back({grid([&](double t) { return 2.0 * ImuMarginM(t, g, RateErrorTenthDegS()); }),
                      SvgStyle{col, 2.4, "", 1.0}, label("g = %g: IMU 2 Delta_d", g)});
    growth.push_back({grid([&](double t) { return BaselineExtensionM(t, g, b).slip_m; }), SvgStyle{col, 1.4, "2 3", 1.0},
                      label("g = %g: former, slip", g)});
    growth.push_back({grid([&](double t) { return BaselineExtensionM(t, g, b).slide_m; }),
                      SvgStyle{col, 1.6, "8 4", 1.0}, label("g = %g: former, slide (coasting)", g)});
  }
  char title[256];
  std::snprintf(title, sizeof title,
                "Growth of the occupied range: IMU 2 Delta_d (permanent, 0.0025 deg/s) vs former method after "
                "a slip/slide of T (a %.2f-%.2f, d %.2f-%.2f m/s^2)",
                b.accel_min, b.accel_max, b.decel_min, b.decel_max);
  return offline::SvgStack(
      {panel("IMU method: permanent margin per side Delta_d(T_max, g) (D1 error model)",
             "maximum compensation time T_max (s)", "margin per side (m)", margins),
       panel(title, "compensation time / slip duration T (s)", "front + rear extension (m)", growth)});
}

std::string ClearingPlotSvg(const std::vector<TrainMarginCheck>& trains, double max_margin_m) {
  const double a = ClearingAccelMS2();
  std::vector<Series> curves;
  for (std::size_t i = 0; i < trains.size(); ++i) {
    const TrainMarginCheck& t = trains[i];
    Points p;
    for (int k = 0; k <= 150; ++k) {
      const double m = max_margin_m * k / 150.0;
      p.emplace_back(m, ClearingCostS(t.length_m, m, a));
    }
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s (L = %.0f m, line %s)", t.train.c_str(), t.length_m, t.line.c_str());
    curves.push_back({p, SvgStyle{kGradientColours[i % 7], 2.2, "", 1.0}, buf});
  }
  SvgPlot plot(0.0, max_margin_m, 0.0, YRange(curves, 0.05, 1.0).second);
  char title[200];
  std::snprintf(title, sizeof title,
                "Clearing-time cost of the permanent margin: extra time to clear L + 2 x margin from rest at %.2f m/s^2",
                a);
  plot.SetTitle(title);
  plot.SetXLabel("margin per side (m)");
  plot.SetYLabel("extra clearing time (s)");
  for (std::size_t i = 0; i < trains.size(); ++i) {
    plot.AddSeries(curves[i].points, curves[i].style, curves[i].legend);
    const double m = static_cast<double>(trains[i].readhesion_margin_mm) / 1000.0;
    char buf[160];
    std::snprintf(buf, sizeof buf, "%s: %.1f m, +%.1f s", trains[i].train.c_str(), m, trains[i].clearing_extra_s);
    plot.AddMarker(m, trains[i].clearing_extra_s, curves[i].style.stroke, buf);
  }
  return plot.Render();
}

}  // namespace railproof::ra::analysis
