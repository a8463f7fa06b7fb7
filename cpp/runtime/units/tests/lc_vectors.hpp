// The lc vectors for the replays through both units: every lc*.jsonl vector of the pipeline's
// vector directory, read once per test run with the runners' reader and the lc key list, and
// the configuration each file's header gives (spec/schemas/vectors_lc.schema.json, as the lc
// conformance runner reads it): the crossings, the line's permitted speeds, the controllers'
// and the on-board protection's parameters and the two trains.
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "railproof/core/track.hpp"
#include "railproof/lc/crossing.hpp"
#include "railproof/lc/onboard/crossing_protection.hpp"
#include "railproof/lc/wayside/crossing_controller.hpp"
#include "railproof/testing/jsonl_runner.hpp"
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
};

inline LcFile LcHeader(const nlohmann::json& h) {
  const nlohmann::json& p = h.at("parameters");
  const auto i64 = [](const nlohmann::json& o, const char* k) { return o.at(k).get<std::int64_t>(); };
  LcFile f;
  f.gnss = h.at("variant").get<std::string>() == "GNSS";
  const nlohmann::json& t = p.at("train");
  f.train_id = t.at("id").get<std::uint32_t>();
  f.other_train_id = p.at("other_train_id").get<std::uint32_t>();
  f.train_length_mm = i64(t, "length_mm");
  f.accel_max_mm_s2 = i64(t, "accel_max_mm_s2");
  for (const nlohmann::json& x : p.at("crossings")) {
    f.crossings.push_back(lc::CrossingData{x.at("id").get<std::uint32_t>(), i64(x, "near_mm"), i64(x, "far_mm"),
                                           i64(x, "warning_time_ms")});
  }
  for (const nlohmann::json& x : p.at("restrictions")) {
    f.restrictions.push_back(core::RestrictionSegment{i64(x, "begin_mm"), i64(x, "end_mm"), i64(x, "limit_mm_s")});
  }
  const nlohmann::json& c = p.at("controller");
  f.controller = lc::wayside::DefaultControllerConfig(0);
  f.controller.barrier_lowering_ms = i64(c, "barrier_lowering_ms");
  f.controller.barrier_timeout_ms = i64(c, "barrier_timeout_ms");
  f.controller.max_warning_ms = i64(c, "max_warning_ms");
  f.controller.holdover_max_ms = i64(c, "holdover_max_ms");
  const nlohmann::json& pr = p.at("protection");
  f.protection = lc::onboard::DefaultProtectionConfig(f.train_id, f.train_length_mm, f.accel_max_mm_s2);
  f.protection.request_lead_ms = i64(pr, "request_lead_ms");
  f.protection.confirmation_max_age_ms = i64(pr, "confirmation_max_age_ms");
  f.protection.protection_offset_mm = i64(pr, "protection_offset_mm");
  f.protection.lookahead_mm = i64(pr, "lookahead_mm");
  return f;
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
          s.files[file] = LcHeader(h);
          return std::string();
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
