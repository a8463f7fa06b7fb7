// The pieces of the lc conformance runner that the units' replays of the same vectors share:
// the configuration of a file's header (spec/schemas/vectors_lc.schema.json, checked field by
// field and by the units' own Create), and the crossing reports of the vectors' steps (a
// report as the units' message, and the text both sides of a comparison are shown as).
#pragma once

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "railproof/core/track.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/lc/wayside/centre_scheduler.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"
#include "railproof/testing/jsonl_runner.hpp"

namespace railproof::lc::conformance {

inline bool IsInt(const nlohmann::json& o, const char* k) {
  return o.is_object() && o.contains(k) && o[k].is_number_integer();
}
inline bool IsBool(const nlohmann::json& o, const char* k) {
  return o.is_object() && o.contains(k) && o[k].is_boolean();
}
inline bool IsArr(const nlohmann::json& o, const char* k) { return o.is_object() && o.contains(k) && o[k].is_array(); }
inline bool IsObj(const nlohmann::json& o, const char* k) {
  return o.is_object() && o.contains(k) && o[k].is_object();
}
inline std::int64_t I(const nlohmann::json& o, const char* k) { return o.at(k).get<std::int64_t>(); }

// The configuration of one file (its header).
struct FileConfig {
  bool gnss = false;
  std::vector<CrossingData> crossings;
  std::vector<core::RestrictionSegment> restrictions;
  onboard::ProtectionConfig protection;
  std::vector<wayside::ControllerConfig> controllers;  // one per crossing, in its order
  wayside::SchedulerConfig scheduler;
  wayside::Departure departure;
  std::int64_t started_at_ms = 0;
};

// The configuration of a file's header; "" or the reason it is unusable.
inline std::string ConfigFromHeader(const nlohmann::json& h, FileConfig& cfg) {
  namespace ob = onboard;
  namespace ws = wayside;
  using json = nlohmann::json;
  const json& p = h["parameters"];
  if (!p.is_object() || !IsObj(p, "train") || !IsArr(p, "crossings") || !IsArr(p, "restrictions") ||
      !IsObj(p, "protection") || !IsObj(p, "controller")) {
    return "header parameters need train, crossings, restrictions, protection, controller";
  }
  const std::string variant = railproof::conformance::StringField(h, "variant");
  if (variant != "ONBOARD" && variant != "GNSS") {
    return "header variant must be ONBOARD or GNSS";
  }
  cfg.gnss = variant == "GNSS";
  const json& t = p["train"];
  const json& pr = p["protection"];
  const json& c = p["controller"];
  if (!IsInt(t, "id") || !IsInt(t, "length_mm") || !IsInt(t, "accel_max_mm_s2") || !IsInt(pr, "request_lead_ms") ||
      !IsInt(pr, "confirmation_max_age_ms") || !IsInt(pr, "protection_offset_mm") || !IsInt(pr, "lookahead_mm") ||
      !IsInt(c, "barrier_lowering_ms") || !IsInt(c, "barrier_timeout_ms") || !IsInt(c, "max_warning_ms") ||
      !IsInt(c, "holdover_max_ms")) {
    return "header parameters: a train, protection or controller field is missing or not an integer";
  }
  for (const json& x : p["crossings"]) {
    if (!IsInt(x, "id") || !IsInt(x, "near_mm") || !IsInt(x, "far_mm") || !IsInt(x, "warning_time_ms")) {
      return "header crossing needs integer id, near_mm, far_mm, warning_time_ms";
    }
    cfg.crossings.push_back(
        CrossingData{static_cast<std::uint32_t>(I(x, "id")), I(x, "near_mm"), I(x, "far_mm"), I(x, "warning_time_ms")});
  }
  for (const json& x : p["restrictions"]) {
    if (!IsInt(x, "begin_mm") || !IsInt(x, "end_mm") || !IsInt(x, "limit_mm_s")) {
      return "header restriction needs integer begin_mm, end_mm, limit_mm_s";
    }
    cfg.restrictions.push_back(core::RestrictionSegment{I(x, "begin_mm"), I(x, "end_mm"), I(x, "limit_mm_s")});
  }
  cfg.protection = ob::DefaultProtectionConfig(static_cast<std::uint32_t>(I(t, "id")), I(t, "length_mm"),
                                               I(t, "accel_max_mm_s2"));
  cfg.protection.request_lead_ms = I(pr, "request_lead_ms");
  cfg.protection.confirmation_max_age_ms = I(pr, "confirmation_max_age_ms");
  cfg.protection.protection_offset_mm = I(pr, "protection_offset_mm");
  cfg.protection.lookahead_mm = I(pr, "lookahead_mm");
  if (const auto r = ob::CrossingProtection::Create(cfg.protection); r.error != ob::ProtectionError::kNone) {
    return std::string("header protection configuration rejected: ") + ToString(r.error);
  }
  for (const CrossingData& x : cfg.crossings) {
    ws::ControllerConfig cc = ws::DefaultControllerConfig(x.id);
    cc.barrier_lowering_ms = I(c, "barrier_lowering_ms");
    cc.barrier_timeout_ms = I(c, "barrier_timeout_ms");
    cc.max_warning_ms = I(c, "max_warning_ms");
    cc.holdover_max_ms = I(c, "holdover_max_ms");
    if (const auto r = ws::CrossingController::Create(cc); r.error != ws::ControllerError::kNone) {
      return std::string("header controller configuration rejected: ") + ToString(r.error);
    }
    cfg.controllers.push_back(cc);
  }
  if (cfg.gnss) {
    if (!IsObj(p, "scheduler") || !IsInt(p["scheduler"], "clock_allowance_ms") || !IsObj(p, "departure")) {
      return "GNSS header needs scheduler.clock_allowance_ms and departure";
    }
    const json& d = p["departure"];
    if (!IsInt(d, "train_id") || !IsInt(d, "departure_id") || !IsInt(d, "departure_ms") || !IsInt(d, "front_mm") ||
        !IsInt(d, "started_at_ms")) {
      return "header departure needs integer train_id, departure_id, departure_ms, front_mm, started_at_ms";
    }
    cfg.scheduler = ws::DefaultSchedulerConfig(I(t, "accel_max_mm_s2"));
    cfg.scheduler.clock_allowance_ms = I(p["scheduler"], "clock_allowance_ms");
    if (const auto r = ws::CentreScheduler::Create(cfg.scheduler); r.error != ws::SchedulerError::kNone) {
      return std::string("header scheduler configuration rejected: ") + ToString(r.error);
    }
    cfg.departure = ws::Departure{static_cast<std::uint32_t>(I(d, "train_id")),
                                  static_cast<std::uint32_t>(I(d, "departure_id")), I(d, "departure_ms"),
                                  I(d, "front_mm")};
    cfg.started_at_ms = I(d, "started_at_ms");
  }
  return "";
}

// ---- crossing reports and id lists -------------------------------------------------------------

// A list of ids as text, "[a,b]", in the list's order: a vector's (json) or a unit's.
inline std::string Ids(const nlohmann::json& a) {
  std::string s = "[";
  for (std::size_t i = 0; i < a.size(); ++i) {
    s += (i ? "," : "") + std::to_string(a[i].get<std::int64_t>());
  }
  return s + "]";
}
template <typename Range>
std::string Ids(const Range& a) {
  std::string s = "[";
  for (const auto& x : a) {
    s += (s.size() > 1 ? "," : "") + std::to_string(static_cast<std::int64_t>(x));
  }
  return s + "]";
}

// A report's status name in the vectors (an unknown name is OPEN; the step checks reject it).
inline messages::CrossingStatus StatusOf(const std::string& s) {
  if (s == "WARNING") {
    return messages::CrossingStatus::kWarning;
  }
  if (s == "CLOSED") {
    return messages::CrossingStatus::kClosed;
  }
  if (s == "FAILED") {
    return messages::CrossingStatus::kFailed;
  }
  return messages::CrossingStatus::kOpen;
}

// A vector's report (at most kMaxReportRequesters requesters: the step checks) as the message,
// times as in the vector.
inline messages::CrossingReport ReportOf(const nlohmann::json& r) {
  messages::CrossingReport rep{static_cast<std::uint32_t>(I(r, "crossing_id")),
                               StatusOf(r.at("status").get<std::string>()), I(r, "warning_start_ms"),
                               I(r, "issued_ms"), r.at("clock_fault").get<bool>()};
  for (const nlohmann::json& id : r.at("requesters")) {
    rep.requesters[rep.requester_count++] = static_cast<std::uint32_t>(id.get<std::int64_t>());
  }
  return rep;
}

inline std::string ReportString(const messages::CrossingReport& r) {
  return "{" + std::to_string(r.crossing_id) + "," + ToString(r.status) + ",ws=" + std::to_string(r.warning_start_ms) +
         ",issued=" + std::to_string(r.issued_ms) + ",cf=" + railproof::conformance::Bool(r.clock_fault) +
         ",requesters=" + Ids(std::span<const std::uint32_t>(r.requesters.data(), r.requester_count)) + "}";
}
inline std::string ReportString(const nlohmann::json& r) { return ReportString(ReportOf(r)); }

}  // namespace railproof::lc::conformance
