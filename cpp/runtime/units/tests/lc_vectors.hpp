// The lc vectors for the replays through both units: every lc*.jsonl vector of the pipeline's
// vector directory, read once per test run with the runners' reader and the lc key list, and
// the configuration each file's header gives (spec/schemas/vectors_lc.schema.json, read and
// checked by the lc conformance runner's ConfigFromHeader): the crossings, the line's permitted
// speeds, the controllers' and the on-board protection's parameters, the two trains and, in the
// GNSS-time variant, the centre scheduler's parameters and the departure; and the messages
// between the centre and the crossings of the GNSS-time steps as the lc module's structs.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "railproof/core/track.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "lc/conformance/vector_config.hpp"
#include "lc/conformance/vector_keys.hpp"

namespace railproof::units::test {

struct LcFile {
  bool gnss = false;  // the GNSS-time variant (centre scheduler and controllers apart)
  std::uint32_t train_id = 0;
  std::uint32_t other_train_id = 0;
  std::int64_t train_length_mm = 0;
  std::int64_t accel_max_mm_s2 = 0;
  std::vector<lc::CrossingData> crossings;
  std::vector<core::RestrictionSegment> restrictions;
  lc::wayside::ControllerConfig controller{};  // crossing_id is each crossing's
  lc::onboard::ProtectionConfig protection{};
  // GNSS-time variant
  lc::wayside::SchedulerConfig scheduler{};
  lc::wayside::Departure departure{};
  std::int64_t started_at_ms = 0;
};

// A file's header through the lc runner's reading of it (its checks included), and the other
// train's id, which that runner does not use; "" or the reason the header is unusable.
inline std::string LcHeader(const nlohmann::json& h, LcFile& f) {
  lc::conformance::FileConfig cfg;
  if (std::string e = lc::conformance::ConfigFromHeader(h, cfg); !e.empty()) {
    return e;
  }
  const nlohmann::json& p = h["parameters"];
  if (!lc::conformance::IsInt(p, "other_train_id") || cfg.controllers.empty()) {
    return "header needs an integer other_train_id and a crossing";
  }
  f.gnss = cfg.gnss;
  f.train_id = cfg.protection.train_id;
  f.other_train_id = static_cast<std::uint32_t>(lc::conformance::I(p, "other_train_id"));
  f.train_length_mm = cfg.protection.train_length_mm;
  f.accel_max_mm_s2 = cfg.protection.accel_max_mm_s2;
  f.crossings = cfg.crossings;
  f.restrictions = cfg.restrictions;
  f.controller = cfg.controllers.front();
  f.controller.crossing_id = 0;
  f.protection = cfg.protection;
  f.scheduler = cfg.scheduler;
  f.departure = cfg.departure;
  f.started_at_ms = cfg.started_at_ms;
  return "";
}

// ---- the GNSS-time steps' centre <-> crossing messages ----------------------------------------

inline lc::wayside::StartTimeMessage StartTimeOf(const nlohmann::json& m) {
  using lc::conformance::I;
  return {static_cast<std::uint32_t>(I(m, "crossing_id")), static_cast<std::uint32_t>(I(m, "departure_id")),
          I(m, "start_ms")};
}
inline lc::wayside::WarningStopMessage StopOf(const nlohmann::json& m) {
  using lc::conformance::I;
  return {static_cast<std::uint32_t>(I(m, "crossing_id")), static_cast<std::uint32_t>(I(m, "departure_id"))};
}
inline lc::wayside::StartTimeAck StartAckOf(const nlohmann::json& m) {
  return {StartTimeOf(m).crossing_id, StartTimeOf(m).departure_id, StartTimeOf(m).start_ms, m.at("stored").get<bool>()};
}
inline lc::wayside::WarningStopAck StopAckOf(const nlohmann::json& m) {
  return {StopOf(m).crossing_id, StopOf(m).departure_id};
}

// A vector's list as structs (Of: one of the above, or lc::conformance::ReportOf).
template <typename Of>
auto ListOf(const nlohmann::json& list, Of of) {
  std::vector<decltype(of(list.front()))> v;
  for (const nlohmann::json& m : list) {
    v.push_back(of(m));
  }
  return v;
}

// The text both sides of a comparison are shown as (and messages are matched by).
inline std::string Text(const lc::wayside::StartTimeMessage& m) {
  return "{" + std::to_string(m.crossing_id) + "," + std::to_string(m.departure_id) + "," + std::to_string(m.start_ms) +
         "}";
}
inline std::string Text(const lc::wayside::WarningStopMessage& m) {
  return "{" + std::to_string(m.crossing_id) + "," + std::to_string(m.departure_id) + "}";
}
inline std::string Text(const lc::wayside::StartTimeAck& a) {
  return "{" + std::to_string(a.crossing_id) + "," + std::to_string(a.departure_id) + "," + std::to_string(a.start_ms) +
         "," + conformance::Bool(a.stored) + "}";
}
inline std::string Text(const lc::wayside::WarningStopAck& a) {
  return Text(lc::wayside::WarningStopMessage{a.crossing_id, a.departure_id});
}
inline std::string Text(const messages::CrossingReport& r) { return lc::conformance::ReportString(r); }
template <typename T>
std::string Text(std::span<const T> list) {
  std::string s = "[";
  for (const T& m : list) {
    s += Text(m);
  }
  return s + "]";
}

struct LcVectors {
  std::string error;  // the reader's, empty if the set was read
  std::map<std::string, LcFile> files;
  std::vector<conformance::JsonVector> vectors;
};

inline const LcVectors& LcVectorSet() {
  static const LcVectors set = [] {
    LcVectors s;
    std::size_t count = 0;
    s.error = conformance::ReadVectorDirectory(
        RAILPROOF_UNITS_VECTORS, "lc", conformance::LcVectorKeys(),
        [&](const std::string& file, const nlohmann::json& h) {
          return LcHeader(h, s.files[file]);
        },
        [&](const conformance::VectorLineRef& line) {
          s.vectors.push_back(
              conformance::JsonVector{line.id, line.test_name, line.file, line.line, (*line.obj)["steps"]});
          return std::string();
        },
        count);
    return s;
  }();
  return set;
}

}  // namespace railproof::units::test
