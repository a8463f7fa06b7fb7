// Line scenario simulation: the time-distance diagram (Simulation::Svg, drawn with
// offline::SvgPlot; simulation_impl.hpp).
#include "simulation_impl.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "railproof/offline/svg.hpp"

namespace railproof::sim {

std::string Simulation::Svg() const {
  const Impl& s = *impl_;
  const double t_end = std::max(1.0, ToS(s.now));
  const double len_km = ToM(s.rl->length_mm) / 1000.0;
  // distance range: what the trains covered (whole line if they spread over it)
  double lo = len_km;
  double hi = 0.0;
  for (const auto& t : s.trains) {
    for (const auto& p : t->samples) {
      lo = std::min(lo, p.rear_m / 1000.0);
      hi = std::max(hi, p.front_m / 1000.0);
      if (!std::isnan(p.limit_m)) {
        hi = std::max(hi, std::min(len_km, p.limit_m / 1000.0));
      }
    }
  }
  for (const auto& f : s.faults) {
    if (f.spec.type == FaultType::kPossession || f.spec.type == FaultType::kSpeedRestriction) {
      lo = std::min(lo, ToM(f.spec.begin_mm) / 1000.0);
      hi = std::max(hi, ToM(f.spec.end_mm) / 1000.0);
    }
  }
  if (hi <= lo) {
    lo = 0.0;
    hi = len_km;
  }
  const double pad = std::max(0.05, (hi - lo) * 0.03);
  lo = std::max(0.0, lo - pad);
  hi = std::min(len_km, hi + pad);
  SvgPlot plot(0.0, t_end, lo, hi);
  plot.SetTitle("Time-distance diagram: " + s.sc.name + " (" + s.line.name + ", running line " + s.rl->id + ")");
  plot.SetXLabel("time [s]");
  plot.SetYLabel("distance along the running line [km]");
  static const std::array<const char*, 10> kColours = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e",
                                                       "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"};
  for (const auto& st : s.rl->stations) {
    const double y = ToM(st.stop_mm) / 1000.0;
    if (y >= lo && y <= hi) {
      plot.AddRect(0.0, t_end, ToM(st.platform.begin_mm) / 1000.0, ToM(st.platform.end_mm) / 1000.0, "#999999", 0.12);
      plot.AddHLine(y, st.name, SvgStyle{"#999999", 0.6, "2 3", 1.0});
    }
  }
  for (std::size_t p = 0; p < s.rl->points.size(); ++p) {
    const double y = ToM(s.rl->points[p].section.begin_mm) / 1000.0;
    if (y >= lo && y <= hi) {
      plot.AddHLine(y, "points " + s.rl->points[p].id, SvgStyle{"#bbbbbb", 0.5, "1 3", 1.0});
    }
  }
  bool any_poss = false;
  bool any_radio = false;
  bool any_track = false;
  bool any_siding = false;
  bool any_tsr = false;
  for (const auto& f : s.faults) {
    const double from = ToS(f.spec.from_ms);
    const double to = std::min(t_end, ToS(f.spec.to_ms));
    if (from > t_end) {
      continue;
    }
    switch (f.spec.type) {
      case FaultType::kPossession:
        plot.AddRect(from, to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#ff9900", 0.25,
                     "possession " + std::to_string(f.possession_id));
        if (f.active_at) {
          plot.AddRect(ToS(*f.active_at), to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#ff6600", 0.35);
        }
        any_poss = true;
        break;
      case FaultType::kSpeedRestriction:
        plot.AddRect(from, to, ToM(f.spec.begin_mm) / 1000.0, ToM(f.spec.end_mm) / 1000.0, "#33aa33", 0.18,
                     "TSR " + std::to_string(static_cast<int>(std::lround(f.spec.speed_mps * 3.6))) + " km/h");
        any_tsr = true;
        break;
      case FaultType::kSidingRequest: {
        for (const auto& r : s.rl->routes) {
          if (r.id == s.SidingRoute(f.spec)) {
            plot.AddRect(from, to, ToM(r.section.begin_mm) / 1000.0 - 0.05, ToM(r.section.end_mm) / 1000.0 + 0.05,
                         "#3366ff", 0.2, "siding route " + std::to_string(r.id));
          }
        }
        any_siding = true;
        break;
      }
      case FaultType::kRadioLoss:
      case FaultType::kTrackingLoss: {
        const TrainRt* t = s.Find(*f.spec.train);
        double a = hi;
        double b = lo;
        if (t != nullptr) {
          for (const auto& p : t->samples) {
            if (ToS(p.t_ms) >= from - 30.0 && ToS(p.t_ms) <= to + 30.0) {
              a = std::min(a, p.rear_m / 1000.0);
              b = std::max(b, p.front_m / 1000.0);
            }
          }
        }
        if (b < a) {
          break;  // the train was not on the line during the window: nothing to shade
        }
        const bool radio = f.spec.type == FaultType::kRadioLoss;
        plot.AddRect(from, to, a - 0.1, b + 0.1, radio ? "#ff0000" : "#9900cc", 0.15,
                     std::string(radio ? "radio loss T" : "tracking loss T") + std::to_string(*f.spec.train));
        (radio ? any_radio : any_track) = true;
        break;
      }
    }
  }
  const bool many = s.trains.size() > 12;
  for (std::size_t i = 0; i < s.trains.size(); ++i) {
    const auto& t = *s.trains[i];
    const std::string colour = kColours[i % kColours.size()];
    std::vector<std::pair<double, double>> front;
    std::vector<std::pair<double, double>> rear;
    std::vector<std::pair<double, double>> limit;
    std::int64_t prev = -1;
    for (const auto& p : t.samples) {
      if (prev >= 0 && p.t_ms - prev > s.sc.sample_ms) {
        front.emplace_back(0.0, std::nan(""));
        rear.emplace_back(0.0, std::nan(""));
        limit.emplace_back(0.0, std::nan(""));
      }
      prev = p.t_ms;
      front.emplace_back(ToS(p.t_ms), p.front_m / 1000.0);
      rear.emplace_back(ToS(p.t_ms), p.rear_m / 1000.0);
      limit.emplace_back(ToS(p.t_ms), std::isnan(p.limit_m) ? std::nan("") : p.limit_m / 1000.0);
    }
    plot.AddPolyline(limit, SvgStyle{colour, 0.9, "5 4", 0.8});
    plot.AddPolyline(rear, SvgStyle{colour, 0.8, "", 0.9});
    plot.AddPolyline(front, SvgStyle{colour, 1.6, "", 1.0});
    if (!many) {
      plot.AddLegend("train " + std::to_string(t.spec.id) + " front (thick), rear (thin)", SvgStyle{colour, 1.6, "", 1.0});
    }
  }
  if (many) {
    plot.AddLegend(std::to_string(s.trains.size()) + " trains: front (thick), rear (thin)", SvgStyle{"#1f77b4", 1.6, "", 1.0});
  }
  plot.AddLegend("on-board stop limit (dashed)", SvgStyle{"#555555", 0.9, "5 4", 1.0});
  plot.AddLegend("station platform", SvgStyle{"#999999", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  if (any_poss) {
    plot.AddLegend("possession requested / active", SvgStyle{"#ff9900", 1.0, "", 0.4}, SvgPlot::LegendKind::kBox);
  }
  if (any_tsr) {
    plot.AddLegend("temporary speed restriction", SvgStyle{"#33aa33", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  }
  if (any_siding) {
    plot.AddLegend("siding route requested", SvgStyle{"#3366ff", 1.0, "", 0.3}, SvgPlot::LegendKind::kBox);
  }
  if (any_radio) {
    plot.AddLegend("radio loss window", SvgStyle{"#ff0000", 1.0, "", 0.25}, SvgPlot::LegendKind::kBox);
  }
  if (any_track) {
    plot.AddLegend("tracking loss window", SvgStyle{"#9900cc", 1.0, "", 0.25}, SvgPlot::LegendKind::kBox);
  }
  for (std::size_t i = 0; i < s.violations.size() && i < 200; ++i) {
    plot.AddMarker(ToS(s.violations[i].t_ms), lo + (hi - lo) * 0.02, "#ff0000", i == 0 ? s.violations[i].requirement : "");
  }
  if (!s.violations.empty()) {
    plot.AddLegend("invariant violation", SvgStyle{"#ff0000", 3.0, "", 1.0});
  }
  return plot.Render();
}

}  // namespace railproof::sim
