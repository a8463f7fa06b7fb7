// Unit tests of the offline tools' SVG writer (railproof/offline/svg.hpp): axes, lines,
// shades, reference lines, text, the legend kinds, the logarithmic axis and stacked plots.
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <string>

#include "railproof/offline/svg.hpp"

namespace railproof::offline {
namespace {

std::size_t Count(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(part); pos != std::string::npos; pos = text.find(part, pos + 1)) {
    ++n;
  }
  return n;
}

// Expects every part in the text.
void ExpectContains(const std::string& text, std::initializer_list<const char*> parts) {
  for (const char* part : parts) {
    EXPECT_NE(text.find(part), std::string::npos) << part;
  }
}

TEST(SvgPlot, WritesAxesLinesShadesAndLegend) {
  SvgPlot plot(0.0, 600.0, 0.0, 14.5);
  plot.SetTitle("a <title> & more");
  plot.SetXLabel("time [s]");
  plot.SetYLabel("distance [km]");
  plot.AddPolyline({{0.0, 1.0}, {100.0, 2.0}, {200.0, std::nan("")}, {300.0, 3.0}}, SvgStyle{"#ff0000", 1.5, "", 1.0});
  plot.AddRect(100.0, 200.0, 5.0, 6.0, "#ff9900", 0.3, "possession 1");
  plot.AddHLine(2.0, "A", SvgStyle{"#999999", 0.5, "2 3", 1.0});
  plot.AddLegend("train 2", SvgStyle{"#ff0000", 1.5, "", 1.0});
  const std::string svg = plot.Render();
  EXPECT_EQ(svg.rfind("<?xml", 0), 0U);
  ExpectContains(svg, {"<svg xmlns=\"http://www.w3.org/2000/svg\"",
                       "a &lt;title&gt; &amp; more",
                       "time [s]",
                       "distance [km]",
                       "possession 1",
                       "train 2",
                       "stroke-dasharray=\"2 3\""});
  // the NaN breaks the polyline into two pieces
  const auto path = svg.find("<path d=\"M");
  ASSERT_NE(path, std::string::npos);
  EXPECT_NE(svg.find(" M", path + 10), std::string::npos);
  EXPECT_EQ(Count(svg, "</svg>"), 1U);
  EXPECT_DOUBLE_EQ(SvgPlot::TickStep(0.0, 600.0, 12), 50.0);
  EXPECT_DOUBLE_EQ(SvgPlot::TickStep(0.0, 14.5, 10), 2.0);
}

TEST(SvgPlot, SeriesAreasVerticalLinesTextAndLegendKinds) {
  SvgPlot plot(0.0, 10.0, 0.0, 10.0);
  plot.AddSeries({{0.0, 0.0}, {10.0, 10.0}}, SvgStyle{"#112233", 2.0, "", 1.0}, "the series");
  plot.AddArea({{0.0, 0.0}, {10.0, 0.0}, {10.0, 10.0}}, "#445566", 0.25);
  plot.AddVLine(5.0, "asymptote", SvgStyle{"#778899", 1.0, "8 4", 1.0});
  plot.AddText(2.0, 3.0, "note", "#000000", true);
  plot.AddLegend("a box", SvgStyle{"#aabbcc", 1.0, "", 0.5}, SvgPlot::LegendKind::kBox);
  plot.AddLegend("a point", SvgStyle{"#ddeeff", 1.0, "", 1.0}, SvgPlot::LegendKind::kMarker);
  const std::string svg = plot.Render();
  EXPECT_NE(svg.find("stroke=\"#112233\""), std::string::npos);  // the series and its legend line
  EXPECT_EQ(Count(svg, "stroke=\"#112233\""), 2U);
  EXPECT_NE(svg.find(" Z\" fill=\"#445566\" fill-opacity=\"0.2\""), std::string::npos);  // F() rounds to 0.1
  // the vertical line spans the plot area at x = 5 (half way: 90 + 1070 / 2)
  ExpectContains(svg, {"<line x1=\"625.0\" x2=\"625.0\" y1=\"50.0\" y2=\"800.0\"",
                       ">asymptote</text>",
                       "text-anchor=\"end\">note</text>",
                       "fill=\"#aabbcc\" fill-opacity=\"0.5\"",
                       "r=\"4\" fill=\"#ddeeff\""});
}

TEST(SvgPlot, LogarithmicAxisTicksAndNonPositiveValues) {
  SvgPlot plot(0.0, 1.0, 1e3, 1e5);
  plot.SetLogY();
  plot.AddPolyline({{0.0, 1e3}, {0.5, 0.0}, {1.0, 1e5}}, SvgStyle{});
  const std::string svg = plot.Render();
  // ticks 1, 2, 5 x 10^k from 1000 to 100000; the decades darker
  ExpectContains(svg, {">1000<", ">2000<", ">5000<", ">10000<", ">20000<", ">50000<", ">100000<"});
  EXPECT_EQ(Count(svg, "stroke=\"#b0b0b0\""), 3U);
  // 1000 at the bottom (y 800), 100000 at the top (y 50); 0 breaks the line
  EXPECT_NE(svg.find("<path d=\"M90.0 800.0 M1160.0 50.0\""), std::string::npos);
}

TEST(SvgPlot, LongLegendLabelsWrap) {
  SvgPlot plot(0.0, 1.0, 0.0, 1.0);
  const std::string word = "wordy ";
  std::string label;
  for (int i = 0; i < 30; ++i) {
    label += word;
  }
  plot.AddLegend(label, SvgStyle{});
  const std::string svg = plot.Render();
  EXPECT_GE(Count(svg, ">wordy wordy"), 3U);  // one entry over several lines
}

TEST(SvgStack, StacksPlotsWithTheirOwnClipPaths) {
  SvgPlot a(0.0, 1.0, 0.0, 1.0);
  SvgPlot b(0.0, 1.0, 0.0, 1.0);
  a.SetTitle("first");
  b.SetTitle("second");
  const std::string svg = SvgStack({a, b});
  EXPECT_EQ(svg.rfind("<?xml", 0), 0U);
  ExpectContains(svg, {"height=\"1720.0\"",
                       "<svg y=\"0.0\"",
                       "<svg y=\"860.0\"",
                       "clipPath id=\"plot0\"",
                       "clipPath id=\"plot1\"",
                       "url(#plot1)"});
  EXPECT_EQ(Count(svg, "xmlns="), 1U);
  EXPECT_EQ(Count(svg, "</svg>"), 3U);
  EXPECT_LT(svg.find("first"), svg.find("second"));
}

}  // namespace
}  // namespace railproof::offline
