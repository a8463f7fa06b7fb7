// The SVG writer of the offline tools (svg.hpp).
#include "railproof/offline/svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

namespace railproof::offline {

namespace {
constexpr double kWidth = SvgPlot::kWidth;
constexpr double kHeight = SvgPlot::kHeight;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kLeft = 90.0;
constexpr double kRight = 400.0;  // station labels and legend column
constexpr double kTop = 50.0;
constexpr double kBottom = 60.0;
constexpr double kPlotW = kWidth - kLeft - kRight;
constexpr double kPlotH = kHeight - kTop - kBottom;

std::string F(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

std::string TickLabel(double v, double step) {
  char buf[32];
  const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step) - 1e-9));
  std::snprintf(buf, sizeof buf, "%.*f", decimals, std::abs(v) < step * 1e-6 ? 0.0 : v);
  return buf;
}

// Average width of a legend character (11 px sans-serif), for wrapping.
constexpr double kLegendCharWidth = 6.2;

// `text` in lines of at most `width` characters, broken at blanks (a longer word stays whole).
std::vector<std::string> Wrap(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t pos = 0;
  while (pos < text.size()) {
    const std::size_t blank = std::min(text.find(' ', pos), text.size());
    const std::string word = text.substr(pos, blank - pos);
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    pos = blank + 1;
  }
  lines.push_back(line);
  return lines;
}

// A tick of a logarithmic axis: 1, 2 or 5 x 10^k.
std::string LogTickLabel(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string StyleAttrs(const SvgStyle& s) {
  std::string a = "stroke=\"" + s.stroke + "\" stroke-width=\"" + F(s.width) + "\" fill=\"none\"";
  if (!s.dash.empty()) {
    a += " stroke-dasharray=\"" + s.dash + "\"";
  }
  if (s.opacity < 1.0) {
    a += " stroke-opacity=\"" + F(s.opacity) + "\"";
  }
  return a;
}
}  // namespace

std::string SvgEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
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

SvgPlot::SvgPlot(double x_min, double x_max, double y_min, double y_max)
    : x_min_(x_min), x_max_(x_max > x_min ? x_max : x_min + 1.0), y_min_(y_min), y_max_(y_max > y_min ? y_max : y_min + 1.0) {}

void SvgPlot::SetLogY() {
  log_y_ = true;
  if (!(y_min_ > 0.0)) {
    y_min_ = 1.0;
  }
  if (!(y_max_ > y_min_)) {
    y_max_ = 10.0 * y_min_;
  }
}

double SvgPlot::X(double x) const { return kLeft + (x - x_min_) / (x_max_ - x_min_) * kPlotW; }
double SvgPlot::Y(double y) const {
  if (log_y_) {
    if (!(y > 0.0)) {
      return kNaN;
    }
    const double lo = std::log10(y_min_);
    return kTop + kPlotH - (std::log10(y) - lo) / (std::log10(y_max_) - lo) * kPlotH;
  }
  return kTop + kPlotH - (y - y_min_) / (y_max_ - y_min_) * kPlotH;
}

double SvgPlot::TickStep(double lo, double hi, int target) {
  const double raw = (hi - lo) / std::max(1, target);
  if (!(raw > 0.0)) {
    return 1.0;
  }
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) {
      return m * mag;
    }
  }
  return 10.0 * mag;
}

std::vector<std::pair<double, bool>> SvgPlot::YTicks() const {
  std::vector<std::pair<double, bool>> ticks;
  if (log_y_) {
    for (int k = static_cast<int>(std::floor(std::log10(y_min_))); k <= static_cast<int>(std::ceil(std::log10(y_max_))); ++k) {
      for (const double m : {1.0, 2.0, 5.0}) {
        const double v = m * std::pow(10.0, k);
        if (v >= y_min_ * (1.0 - 1e-9) && v <= y_max_ * (1.0 + 1e-9)) {
          ticks.emplace_back(v, m == 1.0);
        }
      }
    }
    return ticks;
  }
  const double ys = TickStep(y_min_, y_max_, 10);
  for (double y = std::ceil(y_min_ / ys) * ys; y <= y_max_ + ys * 1e-9; y += ys) {
    ticks.emplace_back(y, false);
  }
  return ticks;
}

void SvgPlot::AddPolyline(const SvgPoints& points, const SvgStyle& style) {
  std::string d;
  bool pen = false;
  for (const auto& [x, y] : points) {
    const double px = X(x);
    const double py = Y(y);
    if (std::isnan(px) || std::isnan(py)) {
      pen = false;
      continue;
    }
    d += (pen ? " L" : " M") + F(px) + " " + F(py);
    pen = true;
  }
  if (!d.empty()) {
    body_.push_back("<path d=\"" + d.substr(1) + "\" " + StyleAttrs(style) + "/>");
  }
}

void SvgPlot::AddSeries(const SvgPoints& points, const SvgStyle& style, const std::string& legend) {
  AddPolyline(points, style);
  AddLegend(legend, style);
}

void SvgPlot::AddArea(const SvgPoints& points, const std::string& fill, double opacity) {
  std::string d;
  for (const auto& [x, y] : points) {
    const double px = X(x);
    const double py = Y(y);
    if (!std::isnan(px) && !std::isnan(py)) {
      d += (d.empty() ? "M" : " L") + F(px) + " " + F(py);
    }
  }
  if (!d.empty()) {
    body_.push_back("<path d=\"" + d + " Z\" fill=\"" + fill + "\" fill-opacity=\"" + F(opacity) + "\" stroke=\"none\"/>");
  }
}

void SvgPlot::AddRect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity,
                      const std::string& label) {
  const double px0 = X(std::min(x0, x1));
  const double px1 = X(std::max(x0, x1));
  const double py0 = Y(std::max(y0, y1));
  const double py1 = Y(std::min(y0, y1));
  body_.push_back("<rect x=\"" + F(px0) + "\" y=\"" + F(py0) + "\" width=\"" + F(std::max(1.0, px1 - px0)) +
                  "\" height=\"" + F(std::max(1.0, py1 - py0)) + "\" fill=\"" + fill + "\" fill-opacity=\"" +
                  F(opacity) + "\" stroke=\"none\"/>");
  if (!label.empty()) {
    labels_.push_back("<text x=\"" + F(px0 + 3) + "\" y=\"" + F(std::max(kTop + 10.0, py0 + 11)) +
                      "\" font-size=\"10\" fill=\"#333\">" + SvgEscape(label) + "</text>");
  }
}

void SvgPlot::AddHLine(double y, const std::string& label, const SvgStyle& style) {
  body_.push_back("<line x1=\"" + F(kLeft) + "\" x2=\"" + F(kLeft + kPlotW) + "\" y1=\"" + F(Y(y)) + "\" y2=\"" +
                  F(Y(y)) + "\" " + StyleAttrs(style) + "/>");
  if (!label.empty()) {
    has_hline_labels_ = true;
    labels_.push_back("<text x=\"" + F(kLeft + kPlotW + 4) + "\" y=\"" + F(Y(y) + 3) +
                      "\" font-size=\"9\" fill=\"#555\">" + SvgEscape(label) + "</text>");
  }
}

void SvgPlot::AddVLine(double x, const std::string& label, const SvgStyle& style) {
  body_.push_back("<line x1=\"" + F(X(x)) + "\" x2=\"" + F(X(x)) + "\" y1=\"" + F(kTop) + "\" y2=\"" +
                  F(kTop + kPlotH) + "\" " + StyleAttrs(style) + "/>");
  if (!label.empty()) {
    labels_.push_back("<text x=\"" + F(X(x) + 5) + "\" y=\"" + F(kTop + 14) + "\" font-size=\"11\" fill=\"" +
                      style.stroke + "\">" + SvgEscape(label) + "</text>");
  }
}

void SvgPlot::AddMarker(double x, double y, const std::string& colour, const std::string& label) {
  body_.push_back("<circle cx=\"" + F(X(x)) + "\" cy=\"" + F(Y(y)) + "\" r=\"4\" fill=\"" + colour + "\"/>");
  if (!label.empty()) {
    labels_.push_back("<text x=\"" + F(X(x) + 5) + "\" y=\"" + F(Y(y) - 5) + "\" font-size=\"10\" fill=\"" + colour +
                      "\">" + SvgEscape(label) + "</text>");
  }
}

void SvgPlot::AddText(double x, double y, const std::string& text, const std::string& colour, bool end) {
  labels_.push_back("<text x=\"" + F(X(x)) + "\" y=\"" + F(Y(y)) + "\" font-size=\"11\" fill=\"" + colour + "\"" +
                    (end ? " text-anchor=\"end\"" : "") + ">" + SvgEscape(text) + "</text>");
}

void SvgPlot::AddLegend(const std::string& label, const SvgStyle& style, LegendKind kind) {
  legend_.push_back(Legend{label, style, kind});
}

std::string SvgPlot::Element(std::optional<double> y_offset, const std::string& clip) const {
  std::ostringstream o;
  o << "<svg";
  if (y_offset) {
    o << " y=\"" << F(*y_offset) << "\"";  // nested in a stack
  } else {
    o << " xmlns=\"http://www.w3.org/2000/svg\"";
  }
  o << " width=\"" << F(kWidth) << "\" height=\"" << F(kHeight) << "\" viewBox=\"0 0 " << F(kWidth) << " "
    << F(kHeight) << "\" font-family=\"sans-serif\">\n"
    << "<rect x=\"0\" y=\"0\" width=\"" << F(kWidth) << "\" height=\"" << F(kHeight) << "\" fill=\"#ffffff\"/>\n"
    << "<defs><clipPath id=\"" << clip << "\"><rect x=\"" << F(kLeft) << "\" y=\"" << F(kTop) << "\" width=\""
    << F(kPlotW) << "\" height=\"" << F(kPlotH) << "\"/></clipPath></defs>\n";
  if (!title_.empty()) {
    o << "<text x=\"" << F(kLeft) << "\" y=\"28\" font-size=\"16\" font-weight=\"bold\">" << SvgEscape(title_)
      << "</text>\n";
  }
  // grid and ticks
  const double xs = TickStep(x_min_, x_max_, 12);
  const auto yticks = YTicks();
  o << "<g stroke=\"#e0e0e0\" stroke-width=\"1\">\n";
  for (double x = std::ceil(x_min_ / xs) * xs; x <= x_max_ + xs * 1e-9; x += xs) {
    o << "<line x1=\"" << F(X(x)) << "\" x2=\"" << F(X(x)) << "\" y1=\"" << F(kTop) << "\" y2=\"" << F(kTop + kPlotH)
      << "\"/>\n";
  }
  for (const auto& [y, major] : yticks) {
    o << "<line x1=\"" << F(kLeft) << "\" x2=\"" << F(kLeft + kPlotW) << "\" y1=\"" << F(Y(y)) << "\" y2=\"" << F(Y(y))
      << (major ? "\" stroke=\"#b0b0b0" : "") << "\"/>\n";
  }
  o << "</g>\n<g font-size=\"11\" fill=\"#000\">\n";
  for (double x = std::ceil(x_min_ / xs) * xs; x <= x_max_ + xs * 1e-9; x += xs) {
    o << "<text x=\"" << F(X(x)) << "\" y=\"" << F(kTop + kPlotH + 16) << "\" text-anchor=\"middle\">"
      << TickLabel(x, xs) << "</text>\n";
  }
  const double ys = TickStep(y_min_, y_max_, 10);
  for (const auto& [y, major] : yticks) {
    o << "<text x=\"" << F(kLeft - 6) << "\" y=\"" << F(Y(y) + 4) << "\" text-anchor=\"end\">"
      << (log_y_ ? LogTickLabel(y) : TickLabel(y, ys)) << "</text>\n";
  }
  o << "</g>\n";
  o << "<text x=\"" << F(kLeft + kPlotW / 2) << "\" y=\"" << F(kHeight - 18)
    << "\" font-size=\"13\" text-anchor=\"middle\">" << SvgEscape(x_label_) << "</text>\n";
  o << "<text transform=\"translate(24," << F(kTop + kPlotH / 2) << ") rotate(-90)\" font-size=\"13\" "
    << "text-anchor=\"middle\">" << SvgEscape(y_label_) << "</text>\n";
  o << "<g clip-path=\"url(#" << clip << ")\">\n";
  for (const auto& b : body_) {
    o << b << "\n";
  }
  o << "</g>\n";
  for (const auto& l : labels_) {
    o << l << "\n";
  }
  o << "<rect x=\"" << F(kLeft) << "\" y=\"" << F(kTop) << "\" width=\"" << F(kPlotW) << "\" height=\"" << F(kPlotH)
    << "\" fill=\"none\" stroke=\"#000\" stroke-width=\"1\"/>\n";
  // legend: right of the reference-line labels if there are any; long labels wrap
  const double lx = kLeft + kPlotW + (has_hline_labels_ ? 90.0 : 16.0);
  const auto max_chars = static_cast<std::size_t>((kWidth - lx - 40.0) / kLegendCharWidth);
  double ly = kTop + 10;
  o << "<g font-size=\"11\">\n";
  for (const auto& l : legend_) {
    switch (l.kind) {
      case LegendKind::kBox:
        o << "<rect x=\"" << F(lx) << "\" y=\"" << F(ly - 8) << "\" width=\"26\" height=\"10\" fill=\"" << l.style.stroke
          << "\" fill-opacity=\"" << F(l.style.opacity) << "\"/>\n";
        break;
      case LegendKind::kMarker:
        o << "<circle cx=\"" << F(lx + 13) << "\" cy=\"" << F(ly - 3) << "\" r=\"4\" fill=\"" << l.style.stroke
          << "\"/>\n";
        break;
      case LegendKind::kLine:
        o << "<line x1=\"" << F(lx) << "\" x2=\"" << F(lx + 26) << "\" y1=\"" << F(ly - 3) << "\" y2=\"" << F(ly - 3)
          << "\" " << StyleAttrs(l.style) << "/>\n";
        break;
    }
    for (const std::string& line : Wrap(l.label, max_chars)) {
      o << "<text x=\"" << F(lx + 32) << "\" y=\"" << F(ly + 1) << "\">" << SvgEscape(line) << "</text>\n";
      ly += 13;
    }
    ly += 3;
    if (ly > kHeight - kBottom) {
      break;  // legend full
    }
  }
  o << "</g>\n</svg>\n";
  return o.str();
}

std::string SvgPlot::Render() const {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" + Element(std::nullopt, "plot");
}

std::string SvgStack(const std::vector<SvgPlot>& plots) {
  const double h = kHeight * static_cast<double>(plots.size());
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
                    F(kWidth) + "\" height=\"" + F(h) + "\" viewBox=\"0 0 " + F(kWidth) + " " + F(h) + "\">\n";
  for (std::size_t i = 0; i < plots.size(); ++i) {
    out += plots[i].Element(kHeight * static_cast<double>(i), "plot" + std::to_string(i));
  }
  return out + "</svg>\n";
}

}  // namespace railproof::offline
