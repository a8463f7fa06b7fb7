// Timetable of the warning-time study: the reader of the timetable JSON that the build writes
// from spec/timetables (railproof_testgen timetables: schema, dwell per stop, times in ms,
// stations and train types checked against spec/), and the check that the timetable fits the
// line and train types the study is given (spec/timetables/README.md, spec/design/data.md).
#include <cstdio>
#include <map>
#include <string>

#include "railproof/lc/analysis/warning_study.hpp"
#include "railproof/offline/json_reader.hpp"

namespace railproof::lc::analysis {

using offline::InputError;
using offline::JsonDocument;
using offline::JsonNode;

std::string FormatClockTime(std::int64_t ms) {
  const std::int64_t s = ms / 1000;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%02lld:%02lld:%02lld", static_cast<long long>(s / 3600),
                static_cast<long long>((s / 60) % 60), static_cast<long long>(s % 60));
  return buf;
}

namespace {

// The guards of the reader: every value the study computes with is an integer within the
// range its arithmetic is made for (the file may not have seen the validator); a [min, max]
// pair has min <= max (the study draws uniformly between them).
RangeMs RangeIn(const JsonNode& n, std::int64_t lo, std::int64_t hi, const char* unit) {
  const auto [min, max] = n.IntPairIn(lo, hi, unit);
  return RangeMs{min, max};
}

constexpr std::int64_t kMaxDelayMs = 60'000;
constexpr std::int64_t kMaxDwellMs = 3'600'000;
constexpr std::int64_t kDayMs = 24 * 3'600'000;

}  // namespace

Timetable ParseTimetable(std::string_view text, const std::string& file) {
  const JsonDocument root(text, file, kTimetableSchema,
                          " (the JSON that railproof_testgen timetables writes from spec/timetables)");
  Timetable tt;
  tt.file = file;
  tt.name = root.Key("name").String();
  tt.line = root.Key("line").String();
  tt.title = root.Key("title").String();
  tt.seed = static_cast<std::uint64_t>(root.Key("seed").IntIn(0, std::int64_t{1} << 53, ""));
  tt.running_time_allowance_percent = root.Key("running_time_allowance_percent").IntIn(0, 100, "%");
  tt.planned_time_step_ms = root.Key("planned_time_step_ms").IntIn(1, 300'000, "ms");
  {
    const JsonNode d = root.Key("driver");
    const RangeMs cruise = RangeIn(d.Key("cruise_percent"), 50, 100, "%");
    tt.driver.cruise_min_percent = cruise.min;
    tt.driver.cruise_max_percent = cruise.max;
    tt.driver.start_delay_ms = RangeIn(d.Key("start_delay_ms"), 0, 600'000, "ms");
    tt.driver.min_dwell_ms = d.Key("min_dwell_ms").IntIn(0, kMaxDwellMs, "ms");
  }
  {
    const JsonNode c = root.Key("communication");
    tt.comms.uplink_ms = RangeIn(c.Key("uplink_ms"), 0, kMaxDelayMs, "ms");
    tt.comms.downlink_ms = RangeIn(c.Key("downlink_ms"), 0, kMaxDelayMs, "ms");
    tt.comms.ground_cycle_ms = c.Key("ground_cycle_ms").IntIn(1, 10'000, "ms");
    tt.comms.onboard_cycle_ms = c.Key("onboard_cycle_ms").IntIn(1, 10'000, "ms");
    tt.comms.barrier_travel_ms = RangeIn(c.Key("barrier_travel_ms"), 0, kMaxDelayMs, "ms");
    tt.comms.report_latency_ms = RangeIn(c.Key("report_latency_ms"), 0, kMaxDelayMs, "ms");
    tt.comms.onboard_clock_error_ms = c.Key("onboard_clock_error_ms").IntIn(0, 10'000, "ms");
    tt.comms.gnss_clock_error_ms = c.Key("gnss_clock_error_ms").IntIn(0, 10'000, "ms");
  }
  for (const auto& n0 : root.Key("services").NonEmptyArray("no services")) {
    Service s;
    s.id = n0.Key("id").String();
    const JsonNode n = n0.Labelled(s.id);
    const JsonNode train = n.Key("train");
    s.train = train.String();
    // the study reads <trains-dir>/<train>.json: no other file may be opened
    if (s.train.empty() || s.train.find_first_of("/\\") != std::string::npos) {
      train.Fail("train type must be a plain name (file <trains-dir>/<train>.json), got " + offline::Quoted(s.train));
    }
    s.running_line = n.Key("running_line").String();
    s.depart_ms = n.Key("depart_ms").IntIn(0, 2 * kDayMs - 1, "ms");
    if (const auto f = n.OptKey("from")) {
      s.from = f->String();
    }
    if (const auto f = n.OptKey("to")) {
      s.to = f->String();
    }
    for (const auto& st : n.Key("stops").Array()) {
      s.stops.push_back(ServiceStop{st.Key("station").String(), st.Key("dwell_ms").IntIn(0, kMaxDwellMs, "ms")});
    }
    tt.services.push_back(s);
  }
  return tt;
}

Timetable LoadTimetable(const std::filesystem::path& path) {
  return ParseTimetable(ReadInputFile(path, "timetable file"), path.string());
}

namespace {
[[noreturn]] void FailAt(const std::string& file, const std::string& entry, const std::string& reason) {
  throw InputError(file + ": " + entry + ": " + reason);
}
}  // namespace

void CheckTimetable(const Timetable& tt, const offline::Line& line, const std::map<std::string, TrainType>& trains) {
  if (tt.line != line.name) {
    FailAt(tt.file, "line", "timetable for line '" + tt.line + "', but the line file is '" + line.name + "' (" + line.file + ")");
  }
  std::map<const offline::RunningLine*, std::map<std::string, std::size_t>> station_index;
  for (std::size_t i = 0; i < tt.services.size(); ++i) {
    const Service& s = tt.services[i];
    const std::string entry = "services[" + std::to_string(i) + "] (" + s.id + ")";
    const auto tr = trains.find(s.train);
    if (tr == trains.end()) {
      std::string have;
      for (const auto& [k, v] : trains) {
        have += (have.empty() ? "" : ", ") + k;
        (void)v;
      }
      FailAt(tt.file, entry + ".train", "unknown train type '" + s.train + "' (known: " + have + ")");
    }
    const offline::RunningLine* rl = nullptr;
    for (const auto& r : line.running_lines) {
      if (r.id == s.running_line) {
        rl = &r;
      }
    }
    if (rl == nullptr) {
      FailAt(tt.file, entry + ".running_line", "unknown running line '" + s.running_line + "' of line " + line.name);
    }
    if (rl->stations.size() < 2) {
      FailAt(tt.file, entry + ".running_line", "running line '" + s.running_line + "' has fewer than two stations");
    }
    // station name -> index on the running line, made once per running line (a lookup per stop)
    auto [cached, fresh] = station_index.try_emplace(rl);
    if (fresh) {
      for (std::size_t k = rl->stations.size(); k-- > 0;) {
        cached->second[rl->stations[k].name] = k;
      }
    }
    const std::map<std::string, std::size_t>& stations = cached->second;
    auto index_of = [&](const std::string& name, const std::string& where) -> std::size_t {
      if (const auto it = stations.find(name); it != stations.end()) {
        return it->second;
      }
      std::string have;
      for (const auto& st : rl->stations) {
        have += (have.empty() ? "" : ", ") + st.name;
      }
      FailAt(tt.file, entry + "." + where,
             "station " + offline::Quoted(name) + " has no stop on running line " + s.running_line + " (stops: " + have + ")");
    };
    const std::size_t from = s.from.empty() ? 0 : index_of(s.from, "from");
    const std::size_t to = s.to.empty() ? rl->stations.size() - 1 : index_of(s.to, "to");
    if (from >= to) {
      FailAt(tt.file, entry, "origin " + rl->stations[from].name + " is not before destination " + rl->stations[to].name + " on running line " +
                      s.running_line);
    }
    std::size_t prev = from;
    for (std::size_t k = 0; k < s.stops.size(); ++k) {
      const std::string where = "stops[" + std::to_string(k) + "]";
      const std::size_t idx = index_of(s.stops[k].station, where);
      if (idx <= from || idx >= to) {
        FailAt(tt.file, entry + "." + where, "stop at " + s.stops[k].station + " is not between the origin " + rl->stations[from].name +
                                      " and the destination " + rl->stations[to].name);
      }
      if (idx <= prev) {
        FailAt(tt.file, entry + "." + where, "stop at " + s.stops[k].station + " is not in running order (after " + rl->stations[prev].name +
                                      ")");
      }
      prev = idx;
    }
    const TrainType& t = tr->second;
    auto check_platform = [&](std::size_t idx, const std::string& where) {
      const offline::Station& st = rl->stations[idx];
      if (st.stop_mm - t.length_mm < st.platform.begin_mm) {
        FailAt(tt.file, entry + "." + where, "train " + t.name + " (" + std::to_string(t.length_mm / 1000) + " m) does not fit platform " +
                                      st.name + " [" + std::to_string(st.platform.begin_mm) + ", " +
                                      std::to_string(st.platform.end_mm) + ") mm with its front at the stop " +
                                      std::to_string(st.stop_mm) + " mm");
      }
    };
    check_platform(from, "from");
    check_platform(to, "to");
    for (std::size_t k = 0; k < s.stops.size(); ++k) {
      check_platform(index_of(s.stops[k].station, "stops"), "stops[" + std::to_string(k) + "]");
    }
  }
}

}  // namespace railproof::lc::analysis
