// The one SVG writer of the offline tools: a plot area with a linear x axis and a linear or
// logarithmic (base 10) y axis, polylines (a NaN point breaks the line), filled areas,
// shaded rectangles, horizontal and vertical reference lines with labels, markers, text
// annotations and a legend (line, box or marker entries) in the column right of the plot;
// and several plots stacked into one document (SvgStack). Output is deterministic text
// (fixed number formatting). Offline module.
#pragma once

#include <optional>
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

using SvgPoints = std::vector<std::pair<double, double>>;

class SvgPlot {
 public:
  // Data ranges of the axes; an empty range is widened to one unit (a decade on a log axis).
  SvgPlot(double x_min, double x_max, double y_min, double y_max);

  void SetTitle(std::string title) { title_ = std::move(title); }
  void SetXLabel(std::string label) { x_label_ = std::move(label); }
  void SetYLabel(std::string label) { y_label_ = std::move(label); }
  // A logarithmic y axis (y_min > 0): grid lines at 1, 2 and 5 x 10^k, darker at 10^k;
  // values <= 0 are treated as NaN.
  void SetLogY();

  // Polyline in data coordinates; a NaN coordinate breaks the line.
  void AddPolyline(const SvgPoints& points, const SvgStyle& style);
  // AddPolyline and a legend entry for it.
  void AddSeries(const SvgPoints& points, const SvgStyle& style, const std::string& legend);
  // Closed polygon in data coordinates, filled (no stroke).
  void AddArea(const SvgPoints& points, const std::string& fill, double opacity);
  // Shaded rectangle [x0, x1] x [y0, y1] in data coordinates, with an optional label.
  void AddRect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity,
               const std::string& label = "");
  // Horizontal reference line across the plot (e.g. a station) with a label right of it.
  void AddHLine(double y, const std::string& label, const SvgStyle& style);
  // Vertical reference line across the plot with a label at its top (right of the line).
  void AddVLine(double x, const std::string& label, const SvgStyle& style);
  // Point marker (e.g. an invariant violation), with a label above right of it.
  void AddMarker(double x, double y, const std::string& colour, const std::string& label = "");
  // Text at a data point; `end`: the text ends there (else it starts there).
  void AddText(double x, double y, const std::string& text, const std::string& colour, bool end = false);

  enum class LegendKind { kLine, kBox, kMarker };
  // A legend entry: a line in `style`, a box filled with style.stroke at style.opacity, or a
  // marker in style.stroke.
  void AddLegend(const std::string& label, const SvgStyle& style, LegendKind kind = LegendKind::kLine);

  // The plot as a complete SVG document.
  [[nodiscard]] std::string Render() const;

  // "Nice" tick step (1, 2 or 5 x 10^k) giving about `target` ticks over [lo, hi].
  static double TickStep(double lo, double hi, int target);

  static constexpr double kWidth = 1560.0;
  static constexpr double kHeight = 860.0;

 private:
  friend std::string SvgStack(const std::vector<SvgPlot>& plots);
  // The plot as an <svg> element: the document's root, or nested at height y_offset; `clip`
  // names its clip path (unique in the document).
  [[nodiscard]] std::string Element(std::optional<double> y_offset, const std::string& clip) const;
  [[nodiscard]] double X(double x) const;
  [[nodiscard]] double Y(double y) const;
  // The ticks of the y axis (value, major).
  [[nodiscard]] std::vector<std::pair<double, bool>> YTicks() const;

  double x_min_, x_max_, y_min_, y_max_;
  bool log_y_ = false;
  bool has_hline_labels_ = false;  // the legend moves right of them
  std::string title_, x_label_, y_label_;
  std::vector<std::string> body_;    // drawn inside the clipped plot area
  std::vector<std::string> labels_;  // drawn on top, unclipped
  struct Legend {
    std::string label;
    SvgStyle style;
    LegendKind kind;
  };
  std::vector<Legend> legend_;
};

// Several plots stacked top to bottom in one SVG document (one plot height each).
std::string SvgStack(const std::vector<SvgPlot>& plots);

// Escapes &, <, >, " for SVG text and attributes.
std::string SvgEscape(const std::string& text);

}  // namespace railproof::offline
