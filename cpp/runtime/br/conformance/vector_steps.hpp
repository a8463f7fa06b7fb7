// A br vector step's inputs as the speed supervisor takes them, and what its decision reads of
// them: one reader for the br runner and the replay through the on-board unit. (The key list,
// which the vector-reader fuzz target also includes, stays free of the module: vector_keys.hpp.)
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "railproof/br/supervisor.hpp"

namespace railproof::conformance {

// A step's pattern speeds as the supervisor takes them: the abstract speed units unchanged as
// mm/s (header "units"; the decision only compares them).
inline br::PatternSpeeds BrPatternSpeedsOf(const nlohmann::json& in) {
  br::PatternSpeeds p;
  p.v_s = in.at("v_s").get<std::int64_t>();
  p.v_e = in.at("v_e").get<std::int64_t>();
  p.v_7n = in.at("v_7n").get<std::int64_t>();
  p.v_6n = in.at("v_6n").get<std::int64_t>();
  p.v_5n = in.at("v_5n").get<std::int64_t>();
  p.v_4n = in.at("v_4n").get<std::int64_t>();
  p.v_release = in.at("v_release").get<std::int64_t>();
  return p;
}

inline br::DriverInputs BrDriverInputsOf(const nlohmann::json& in) {
  return br::DriverInputs{.standstill = in.at("standstill").get<bool>(),
                          .handle_emergency = in.at("handle_emergency").get<bool>(),
                          .reset = in.at("reset").get<bool>()};
}

// What the decision reads of the pattern speeds: which of them v_s exceeds (br.md §4 compares
// v_s with each, nothing else), in the order v_e, v_7n, v_6n, v_5n, v_4n, v_release.
using BrExceeded = std::array<bool, 6>;
inline BrExceeded BrExceededOf(const br::PatternSpeeds& p) {
  return {p.v_s > p.v_e, p.v_s > p.v_7n, p.v_s > p.v_6n, p.v_s > p.v_5n, p.v_s > p.v_4n, p.v_s > p.v_release};
}

}  // namespace railproof::conformance
