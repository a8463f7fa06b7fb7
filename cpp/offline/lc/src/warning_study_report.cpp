// Warning-time study: statistics, the JSON result and the SVG histograms (warning_study.hpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <string>

#include "railproof/lc/analysis/warning_study.hpp"
#include "railproof/generated/lc_params.hpp"
#include "railproof/offline/svg.hpp"

namespace railproof::lc::analysis {

namespace lcp = railproof::params::lc;
using Json = nlohmann::ordered_json;

namespace {

constexpr double kBandLoS = 45.0;  // D5 field result: 90 %+ of warnings within 45-74 s
constexpr double kBandHiS = 74.0;

double Round1(double v) { return std::round(v * 10.0) / 10.0; }
double Round3(double v) { return std::round(v * 1000.0) / 1000.0; }

// Nearest-rank percentile of sorted values.
double Percentile(const std::vector<double>& sorted, double p) {
  if (sorted.empty()) {
    return 0.0;
  }
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

Json StatsJson(const WarningStats& s) {
  return Json{{"count", s.count},
              {"min_s", Round1(s.min_s)},
              {"p05_s", Round1(s.p05_s)},
              {"p10_s", Round1(s.p10_s)},
              {"median_s", Round1(s.p50_s)},
              {"p90_s", Round1(s.p90_s)},
              {"p95_s", Round1(s.p95_s)},
              {"max_s", Round1(s.max_s)},
              {"mean_s", Round1(s.mean_s)},
              {"share_45_74_s", Round3(s.share_45_74)},
              {"below_design_time", s.below_design},
              {"min_margin_over_design_s", Round1(s.min_margin_s)}};
}

constexpr std::array<Method, kMethodCount> kMethods{Method::kTreadle,         Method::kOnboard, Method::kOnboardDwell,
                                                    Method::kOnboardApproach, Method::kGnss,    Method::kGnssReceiveTime};

std::size_t Braked(const StudyResult& r, Method m) {
  return static_cast<std::size_t>(std::count_if(r.passages.begin(), r.passages.end(),
                                                [m](const Passage& p) { return p.braked[static_cast<std::size_t>(m)]; }));
}

}  // namespace

WarningStats ComputeStats(const std::vector<Passage>& passages, Method m, const std::function<bool(const Passage&)>& filter) {
  const std::size_t mi = static_cast<std::size_t>(m);
  std::vector<double> w;
  WarningStats s;
  double sum = 0.0;
  std::size_t in_band = 0;
  s.min_margin_s = std::numeric_limits<double>::infinity();
  for (const auto& p : passages) {
    if (filter && !filter(p)) {
      continue;
    }
    const double ws = p.warning_ms[mi] / 1000.0;
    w.push_back(ws);
    sum += ws;
    if (ws >= kBandLoS && ws <= kBandHiS) {
      ++in_band;
    }
    if (p.warning_ms[mi] < static_cast<double>(p.design_ms)) {
      ++s.below_design;
    }
    s.min_margin_s = std::min(s.min_margin_s, (p.warning_ms[mi] - static_cast<double>(p.design_ms)) / 1000.0);
  }
  s.count = w.size();
  if (w.empty()) {
    s.min_margin_s = 0.0;
    return s;
  }
  std::sort(w.begin(), w.end());
  s.min_s = w.front();
  s.max_s = w.back();
  s.p05_s = Percentile(w, 0.05);
  s.p10_s = Percentile(w, 0.10);
  s.p50_s = Percentile(w, 0.50);
  s.p90_s = Percentile(w, 0.90);
  s.p95_s = Percentile(w, 0.95);
  s.mean_s = sum / static_cast<double>(w.size());
  s.share_45_74 = static_cast<double>(in_band) / static_cast<double>(w.size());
  return s;
}

bool StudyPasses(const StudyResult& r) {
  for (Method m : kMethods) {
    if (MustMeetDesignTime(m) && ComputeStats(r.passages, m).below_design > 0) {
      return false;
    }
  }
  return Braked(r, Method::kOnboardDwell) == 0;
}

Json StudyJson(const StudyInputs& in, const StudyResult& r, double wall_s) {
  const Timetable& tt = *in.timetable;
  const bool pass = StudyPasses(r);
  Json methods = Json::array();
  for (Method m : kMethods) {
    const WarningStats all = ComputeStats(r.passages, m);
    Json row{{"method", ToString(m)}, {"description", Describe(m)}};
    row["all"] = StatsJson(all);
    Json by_kind = Json::object();
    for (const char* k : {"fast", "stopping"}) {
      by_kind[k] = StatsJson(ComputeStats(r.passages, m, [k](const Passage& p) { return p.kind == k; }));
    }
    row["by_service_kind"] = by_kind;
    Json by_train = Json::object();
    std::set<std::string> types;
    for (const auto& p : r.passages) {
      types.insert(p.train);
    }
    for (const auto& t : types) {
      by_train[t] = StatsJson(ComputeStats(r.passages, m, [&t](const Passage& p) { return p.train == t; }));
    }
    row["by_train_type"] = by_train;
    row["stop_in_approach"] = StatsJson(ComputeStats(r.passages, m, [](const Passage& p) { return p.stop_in_approach; }));
    if (IsOnboard(m)) {
      row["trains_braked_by_the_protection_pattern"] = Braked(r, m);
    }
    if (MustMeetDesignTime(m)) {
      row["requirement"] = "REQ-LC-017";
      row["meets_target"] = all.below_design == 0;
    }
    methods.push_back(row);
  }

  Json req_rows = Json::array();
  auto below = [&](Method m) { return ComputeStats(r.passages, m).below_design; };
  req_rows.push_back(Json{{"requirement", "REQ-LC-017"},
                          {"detail", "no warning of the on-board (all three variants) or the GNSS-time method shorter than the "
                                     "crossing's design warning time"},
                          {"below_design_time",
                           {{ToString(Method::kOnboard), below(Method::kOnboard)},
                            {ToString(Method::kOnboardDwell), below(Method::kOnboardDwell)},
                            {ToString(Method::kOnboardApproach), below(Method::kOnboardApproach)},
                            {ToString(Method::kGnss), below(Method::kGnss)}}},
                          {"meets_target", below(Method::kOnboard) + below(Method::kOnboardDwell) +
                                                   below(Method::kOnboardApproach) + below(Method::kGnss) ==
                                               0}});
  req_rows.push_back(Json{{"requirement", "REQ-LC-002"},
                          {"detail", "on-board request at the design warning time plus request_lead_ms: every on-board warning "
                                     "at least the design warning time"},
                          {"meets_target", below(Method::kOnboard) == 0}});
  req_rows.push_back(Json{{"requirement", "REQ-LC-005"},
                          {"detail", "dwell-aware request (contract: while standing): no warning shorter than the design time"},
                          {"median_without_s", Round1(ComputeStats(r.passages, Method::kOnboard).p50_s)},
                          {"median_dwell_aware_s", Round1(ComputeStats(r.passages, Method::kOnboardDwell).p50_s)},
                          {"max_without_s", Round1(ComputeStats(r.passages, Method::kOnboard).max_s)},
                          {"max_dwell_aware_s", Round1(ComputeStats(r.passages, Method::kOnboardDwell).max_s)},
                          {"max_dwell_aware_approach_s", Round1(ComputeStats(r.passages, Method::kOnboardApproach).max_s)},
                          {"meets_target", below(Method::kOnboardDwell) == 0}});
  req_rows.push_back(Json{{"requirement", "REQ-LC-008"},
                          {"detail", "GNSS-time start times (planned departure, earliest arrival, clock allowance; updates "
                                     "from reports): no warning shorter than the design time"},
                          {"meets_target", below(Method::kGnss) == 0}});
  req_rows.push_back(Json{{"requirement", "REQ-LC-015"},
                          {"detail", "trains braked by a crossing's protection pattern before its closure confirmation "
                                     "(contract method, dwell-aware while standing)"},
                          {"trains_braked", Braked(r, Method::kOnboardDwell)},
                          {"trains_braked_without_dwell_awareness", Braked(r, Method::kOnboard)},
                          {"trains_braked_dwell_aware_approach", Braked(r, Method::kOnboardApproach)},
                          {"meets_target", Braked(r, Method::kOnboardDwell) == 0}});

  // per crossing and running line
  Json crossings = Json::array();
  std::map<std::pair<std::string, std::string>, std::vector<const Passage*>> groups;
  for (const auto& p : r.passages) {
    groups[{p.running_line, p.crossing}].push_back(&p);
  }
  for (const auto& [key, ps] : groups) {
    std::vector<Passage> sub;
    for (const Passage* p : ps) {
      sub.push_back(*p);
    }
    Json row{{"running_line", key.first},
             {"crossing", key.second},
             {"near_mm", sub.front().near_mm},
             {"design_warning_time_s", Round1(static_cast<double>(sub.front().design_ms) / 1000.0)},
             {"treadle_distance_mm", sub.front().treadle_distance_mm},
             {"passages", sub.size()}};
    bool ok = true;
    Json per = Json::object();
    for (Method m : kMethods) {
      const WarningStats st = ComputeStats(sub, m);
      per[ToString(m)] = Json{{"min_s", Round1(st.min_s)}, {"median_s", Round1(st.p50_s)}, {"max_s", Round1(st.max_s)},
                              {"below_design_time", st.below_design}};
      if (IsOnboard(m)) {
        per[ToString(m)]["trains_braked"] = std::count_if(sub.begin(), sub.end(), [m](const Passage& p) {
          return p.braked[static_cast<std::size_t>(m)];
        });
      }
      if (MustMeetDesignTime(m) && st.below_design > 0) {
        ok = false;
      }
    }
    row["methods"] = per;
    row["meets_target"] = ok;
    crossings.push_back(row);
  }

  Json passages = Json::array();
  for (const auto& p : r.passages) {
    Json w = Json::object();
    for (Method m : kMethods) {
      w[ToString(m)] = Round1(p.warning_ms[static_cast<std::size_t>(m)] / 1000.0);
    }
    Json braked = Json::object();
    Json onboard = Json::object();
    for (Method m : kMethods) {
      if (IsOnboard(m)) {
        const std::size_t mi = static_cast<std::size_t>(m);
        braked[ToString(m)] = p.braked[mi];
        auto before = [&p](double t) { return t < 0.0 ? Json(nullptr) : Json(Round1((p.arrival_ms - t) / 1000.0)); };
        onboard[ToString(m)] = Json{{"request_before_arrival_s", before(p.request_ms[mi])},
                                    {"cleared_before_arrival_s", before(p.cleared_ms[mi])},
                                    {"brake_before_arrival_s", p.braked[mi] ? before(p.brake_at_ms[mi]) : Json(nullptr)}};
      }
    }
    passages.push_back(Json{{"service", p.service},
                            {"train", p.train},
                            {"kind", p.kind},
                            {"running_line", p.running_line},
                            {"crossing", p.crossing},
                            {"arrival", FormatClockTime(static_cast<std::int64_t>(p.arrival_ms))},
                            {"speed_kmh", Round1(p.speed_kmh)},
                            {"stop_in_approach", p.stop_in_approach},
                            {"design_warning_time_s", Round1(static_cast<double>(p.design_ms) / 1000.0)},
                            {"warning_s", w},
                            {"braked", braked},
                            {"onboard_timing", onboard}});
  }

  Json services = Json::array();
  for (std::size_t i = 0; i < r.runs.size(); ++i) {
    const Service& sv = tt.services[i];
    Json stops = Json::array();
    for (const auto& st : r.runs[i].stops) {
      stops.push_back(Json{{"station", st.station},
                           {"planned_arrival", st.origin ? Json(nullptr) : Json(FormatClockTime(st.planned_arrival_ms))},
                           {"planned_departure", st.destination ? Json(nullptr) : Json(FormatClockTime(st.planned_departure_ms))},
                           {"simulated_arrival", st.origin ? Json(nullptr) : Json(Round1(st.arrival_ms / 1000.0))},
                           {"simulated_departure", st.destination ? Json(nullptr) : Json(Round1(st.departure_ms / 1000.0))}});
    }
    services.push_back(Json{{"id", sv.id}, {"train", sv.train}, {"running_line", sv.running_line}, {"stops", stops}});
  }

  Json out{{"schema", "railproof/warning-study/1"},
           {"requirements", {"REQ-LC-002", "REQ-LC-005", "REQ-LC-008", "REQ-LC-015", "REQ-LC-017"}},
           {"verdict", pass ? "pass" : "fail"},
           {"inputs",
            {{"line", in.line->file},
             {"line_name", in.line->name},
             {"timetable", tt.file},
             {"seed", tt.seed},
             {"services", tt.services.size()},
             {"passages", r.passages.size()}}},
           {"model",
            {{"kinematics",
              "per section between stops: accelerate at accel_max to cruise factor x permitted speed (line limit until the "
              "rear has left it, lowered to the speed at which the runtime supervision gives no brake command on the line "
              "profile, capped at the train's maximum speed), brake at the lower bound of the service deceleration for "
              "lower limits and stops; 1 m grid; gradients not modelled"},
             {"driver",
              {{"cruise_percent", {tt.driver.cruise_min_percent, tt.driver.cruise_max_percent}},
               {"start_delay_ms", {tt.driver.start_delay_ms.min, tt.driver.start_delay_ms.max}},
               {"min_dwell_ms", tt.driver.min_dwell_ms}}},
             {"communication",
              {{"uplink_ms", {tt.comms.uplink_ms.min, tt.comms.uplink_ms.max}},
               {"downlink_ms", {tt.comms.downlink_ms.min, tt.comms.downlink_ms.max}},
               {"ground_cycle_ms", tt.comms.ground_cycle_ms},
               {"onboard_cycle_ms", tt.comms.onboard_cycle_ms},
               {"barrier_travel_ms", {tt.comms.barrier_travel_ms.min, tt.comms.barrier_travel_ms.max}},
               {"report_latency_ms", {tt.comms.report_latency_ms.min, tt.comms.report_latency_ms.max}},
               {"onboard_clock_error_ms", tt.comms.onboard_clock_error_ms},
               {"gnss_clock_error_ms", tt.comms.gnss_clock_error_ms}}},
             {"parameters",
              {{"request_lead_ms", lcp::request_lead_ms},
               {"barrier_lowering_ms", lcp::barrier_lowering_ms},
               {"confirmation_max_age_ms", lcp::confirmation_max_age_ms},
               {"protection_offset_mm", lcp::protection_offset_mm},
               {"clock_allowance_ms", lcp::clock_allowance_ms},
               {"position_report_ms", lcp::position_report_ms}}},
             {"running_time_allowance_percent", tt.running_time_allowance_percent},
             {"band_s", {kBandLoS, kBandHiS}}}},
           {"methods", methods},
           {"requirement_rows", req_rows},
           {"crossings", crossings},
           {"statistics",
            {{"onboard_cycles", r.onboard_cycles}, {"pattern_evaluations", r.pattern_evaluations}, {"wall_s", Round3(wall_s)}}},
           {"services", services},
           {"passages", passages}};
  return out;
}

Json LeadSensitivityRow(const StudyResult& r, std::int64_t lead_ms) {
  Json row{{"request_lead_s", Round1(static_cast<double>(lead_ms) / 1000.0)}};
  for (Method m : {Method::kOnboard, Method::kOnboardDwell, Method::kOnboardApproach}) {
    const WarningStats st = ComputeStats(r.passages, m);
    row[ToString(m)] = Json{{"trains_braked", Braked(r, m)},
                            {"min_s", Round1(st.min_s)},
                            {"median_s", Round1(st.p50_s)},
                            {"p95_s", Round1(st.p95_s)},
                            {"max_s", Round1(st.max_s)},
                            {"share_45_74_s", Round3(st.share_45_74)},
                            {"below_design_time", st.below_design}};
  }
  return row;
}

std::string HistogramSvg(const StudyResult& r, Method m, const std::string& line_name) {
  const std::size_t mi = static_cast<std::size_t>(m);
  constexpr double kBin = 2.0;
  double top = 100.0;
  for (const auto& p : r.passages) {
    top = std::max(top, p.warning_ms[mi] / 1000.0 + kBin);
  }
  top = std::ceil(top / 10.0) * 10.0;
  const auto nbins = static_cast<std::size_t>(top / kBin);
  std::vector<double> fast(nbins, 0.0), stop(nbins, 0.0);
  std::set<std::int64_t> designs;
  for (const auto& p : r.passages) {
    const double w = std::max(0.0, p.warning_ms[mi] / 1000.0);
    const std::size_t b = std::min(nbins - 1, static_cast<std::size_t>(w / kBin));
    (p.kind == "fast" ? fast : stop)[b] += 1.0;
    designs.insert(p.design_ms);
  }
  double ymax = 1.0;
  for (std::size_t b = 0; b < nbins; ++b) {
    ymax = std::max(ymax, fast[b] + stop[b]);
  }
  ymax = std::ceil(ymax * 1.15);
  offline::SvgPlot plot(0.0, top, 0.0, ymax);
  const WarningStats st = ComputeStats(r.passages, m);
  char title[512];
  std::snprintf(title, sizeof title,
                "%s — %s: %zu passages, min %.1f s, median %.1f s, max %.1f s, %.0f %% within 45–74 s, %zu below design",
                line_name.c_str(), ToString(m), st.count, st.min_s, st.p50_s, st.max_s, st.share_45_74 * 100.0, st.below_design);
  plot.SetTitle(title);
  plot.SetXLabel("warning time: arrival at the near edge minus warning start (s)");
  plot.SetYLabel("passages per 2 s");
  plot.AddRect(kBandLoS, kBandHiS, 0.0, ymax, "#d0f0d0", 0.5, "45–74 s (D5 field result)");
  for (std::size_t b = 0; b < nbins; ++b) {
    const double x0 = static_cast<double>(b) * kBin, x1 = x0 + kBin * 0.9;
    if (stop[b] > 0) {
      plot.AddRect(x0, x1, 0.0, stop[b], "#e08020", 0.9);
    }
    if (fast[b] > 0) {
      plot.AddRect(x0, x1, stop[b], stop[b] + fast[b], "#2060c0", 0.9);
    }
  }
  const offline::SvgStyle design{"#c00000", 1.5, "6 4", 1.0};
  for (std::int64_t d : designs) {
    plot.AddVLine(static_cast<double>(d) / 1000.0, "", design);
  }
  plot.AddLegend("stopping services", offline::SvgStyle{"#e08020", 8.0, "", 0.9}, offline::SvgPlot::LegendKind::kBox);
  plot.AddLegend("fast services", offline::SvgStyle{"#2060c0", 8.0, "", 0.9}, offline::SvgPlot::LegendKind::kBox);
  plot.AddLegend("design warning times", design);
  return plot.Render();
}

}  // namespace railproof::lc::analysis
