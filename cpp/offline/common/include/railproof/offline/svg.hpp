// A small SVG writer for the time-distance diagram of the line simulation: one plot area
// with a linear x axis (time, s) and y axis (distance, km), polylines, shaded rectangles,
// horizontal reference lines with labels, and a legend. Output is deterministic text
// (fixed number formatting). Offline module.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace railproof::offline {

struct SvgStyle {
  std::string stroke = "#000000";
  double width = 1.0;
  std::string dash;  // e.g. "6 4"; empty: solid
  double opacity = 1.0;
};

class SvgPlot {
 public:
  SvgPlot(double x_min, double x_max, double y_min, double y_max);

  void SetTitle(std::string title) { title_ = std::move(title); }
  void SetXLabel(std::string label) { x_label_ = std::move(label); }
  void SetYLabel(std::string label) { y_label_ = std::move(label); }

  // Polyline in data coordinates; a NaN y breaks the line.
  void AddPolyline(const std::vector<std::pair<double, double>>& points, const SvgStyle& style);
  // Shaded rectangle [x0, x1] x [y0, y1] in data coordinates, with an optional label.
  void AddRect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity,
               const std::string& label = "");
  // Horizontal reference line across the plot (e.g. a station) with a label at the left.
  void AddHLine(double y, const std::string& label, const SvgStyle& style);
  // Point marker (e.g. an invariant violation).
  void AddMarker(double x, double y, const std::string& colour, const std::string& label = "");
  void AddLegend(const std::string& label, const SvgStyle& style, bool filled_box = false);

  [[nodiscard]] std::string Render() const;

  // "Nice" tick step (1, 2 or 5 x 10^k) giving about `target` ticks over [lo, hi].
  static double TickStep(double lo, double hi, int target);

 private:
  [[nodiscard]] double X(double x) const;
  [[nodiscard]] double Y(double y) const;

  double x_min_, x_max_, y_min_, y_max_;
  std::string title_, x_label_, y_label_;
  std::vector<std::string> body_;    // drawn inside the clipped plot area
  std::vector<std::string> labels_;  // drawn on top, unclipped
  struct Legend {
    std::string label;
    SvgStyle style;
    bool box;
  };
  std::vector<Legend> legend_;
};

// Escapes &, <, >, " for SVG text and attributes.
std::string SvgEscape(const std::string& text);

}  // namespace railproof::offline
