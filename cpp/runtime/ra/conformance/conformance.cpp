// railproof_conformance_ra: replays the vectors generated from models/ra.pml (every
// ra*.jsonl of the vector directory) against the C++ re-adhesion state machine
// ra::ReadhesionMachine (railproof_odometry), spec/design/ra.md §5. One
// GoogleTest test per vector, named ReadhesionConformance.<file>_<vector id>, plus
// ReadhesionConformance.VectorSet, which fails if the vector set is missing, empty or
// malformed.
//
//   railproof_conformance_ra --vectors DIR [--junit FILE] [gtest flags]
//
// Each file's header gives the machine configuration of its vectors (confirm_cycles,
// start_points, spacing_cycles, warmup_cycles: ra::MachineConfig, which must validate). Each
// vector starts from a fresh machine (stopped at start-up). Each step is one cycle: the
// predicates (deviation, speed_agrees, imu_ok, tg_ok, balise, tg_moving), the section limits and the start-point age go to
// ReadhesionMachine::Step (model ticks are cycles, the model's margins mm: header "units"),
// which must accept them; expected: every field of the machine state after the cycle
// (mode, stop reason, deviation count, both candidates, t_max and margin in force, stop
// demand, position validity, the trust in the TG history and the warm-up count, the
// detection, adoption and balise-reset events). On a
// mismatch the failure names the vector, the step, the field, expected and actual.
// Last line: "railproof-conformance-ra: all N vectors passed" or
// "railproof-conformance-ra: vectors mismatched: K of N" or "...: error: <reason>".
#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "railproof/ra/readhesion_machine.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "vector_keys.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace ro = railproof::ra;
using json = nlohmann::json;

std::map<std::string, ro::MachineConfig> g_configs;  // per file, from its header

bool IsBool(const json& o, const char* k) { return o.contains(k) && o[k].is_boolean(); }
bool IsInt(const json& o, const char* k) { return o.contains(k) && o[k].is_number_integer(); }

bool BoolPair(const json& o, const char* k) {
  return o.contains(k) && o[k].is_array() && o[k].size() == 2 && o[k][0].is_boolean() && o[k][1].is_boolean();
}

bool StepWellFormed(const std::string& /*file*/, const json& step) {
  if (!step.is_object() || !step.contains("in") || !step.contains("out") || !step["in"].is_object() ||
      !step["out"].is_object()) {
    return false;
  }
  const json& in = step["in"];
  const json& out = step["out"];
  for (const char* k : {"deviation", "imu_ok", "tg_ok", "balise", "tg_moving"}) {
    if (!IsBool(in, k)) {
      return false;
    }
  }
  if (!BoolPair(in, "speed_agrees") || !IsInt(in, "start_age_cycles") || !in.contains("section") ||
      !IsInt(in["section"], "max_compensation_cycles") || !IsInt(in["section"], "margin_mm")) {
    return false;
  }
  for (const char* k : {"mode", "stop_reason"}) {
    if (!out.contains(k) || !out[k].is_string()) {
      return false;
    }
  }
  for (const char* k : {"deviation_count", "max_compensation_cycles", "margin_mm", "rest_cycles"}) {
    if (!IsInt(out, k)) {
      return false;
    }
  }
  for (const char* k : {"stop_demand", "position_valid", "trusted", "detected", "balise_reset"}) {
    if (!IsBool(out, k)) {
      return false;
    }
  }
  if (!out.contains("adopted") || !(out["adopted"].is_null() || out["adopted"].is_number_integer())) {
    return false;
  }
  if (!out.contains("candidates") || !out["candidates"].is_array() ||
      out["candidates"].size() != static_cast<std::size_t>(ro::kMaxStartPoints)) {
    return false;
  }
  for (const json& c : out["candidates"]) {
    if (!c.is_object() || !IsBool(c, "active") || !IsInt(c, "age_cycles") || !IsInt(c, "confirm")) {
      return false;
    }
  }
  return true;
}

// The machine configuration of a file's header; "" or the reason it is unusable.
std::string ConfigFromHeader(const json& obj, ro::MachineConfig& cfg) {
  const json& p = obj["parameters"];
  if (!p.is_object() || !IsInt(p, "confirm_cycles") || !IsInt(p, "start_points") || !IsInt(p, "spacing_cycles") ||
      !IsInt(p, "warmup_cycles")) {
    return "header parameters need integer confirm_cycles, start_points, spacing_cycles, warmup_cycles";
  }
  const std::int64_t confirm = p["confirm_cycles"].get<std::int64_t>();
  const std::int64_t points = p["start_points"].get<std::int64_t>();
  const std::int64_t spacing = p["spacing_cycles"].get<std::int64_t>();
  const std::int64_t warmup = p["warmup_cycles"].get<std::int64_t>();
  if (confirm < 0 || confirm > 255 || points < 0 || points > 255 || spacing < INT32_MIN || spacing > INT32_MAX ||
      warmup < INT32_MIN || warmup > INT32_MAX) {
    return "header machine configuration out of range";
  }
  cfg.confirm_cycles = static_cast<std::uint8_t>(confirm);
  cfg.start_points = static_cast<std::uint8_t>(points);
  cfg.spacing_cycles = static_cast<std::int32_t>(spacing);
  cfg.warmup_cycles = static_cast<std::int32_t>(warmup);
  if (const ro::MachineError e = ro::ReadhesionMachine::Validate(cfg); e != ro::MachineError::kNone) {
    return std::string("header machine configuration rejected: ") + ro::ToString(e);
  }
  return "";
}

// A file's header: the machine configuration of its vectors.
std::string Header(const std::string& file, const json& obj) {
  ro::MachineConfig cfg;
  if (std::string e = ConfigFromHeader(obj, cfg); !e.empty()) {
    return e;
  }
  g_configs[file] = cfg;
  return "";
}

using rcli::Bool;
std::string Adopted(std::int8_t a) { return a == ro::kNoCandidate ? "null" : std::to_string(a); }

void Replay(const rcli::JsonVector& v, std::vector<std::string>& problems) {
  ro::ReadhesionMachine m(g_configs.at(v.file));
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& in = v.steps[k].at("in");
    const json& out = v.steps[k].at("out");
    ro::Predicates p;
    p.deviation = in.at("deviation").get<bool>();
    p.speed_agrees[0] = in.at("speed_agrees")[0].get<bool>();
    p.speed_agrees[1] = in.at("speed_agrees")[1].get<bool>();
    p.imu_ok = in.at("imu_ok").get<bool>();
    p.tg_ok = in.at("tg_ok").get<bool>();
    p.balise = in.at("balise").get<bool>();
    p.tg_moving = in.at("tg_moving").get<bool>();
    p.section.max_compensation_cycles = in.at("section").at("max_compensation_cycles").get<std::int32_t>();
    p.section.margin_mm = in.at("section").at("margin_mm").get<std::int64_t>();
    p.start_age_cycles = in.at("start_age_cycles").get<std::int32_t>();
    rcli::Checker chk(problems, "step " + std::to_string(k) + " (cycle " + std::to_string(k + 1) + "): ", &in);
    if (const ro::MachineError e = m.Step(p); e != ro::MachineError::kNone) {
      chk.Fail(std::string("Step rejected the inputs: ") + ro::ToString(e));
      break;
    }
    const ro::MachineState& s = m.state();
    auto num = [](const json& j) { return std::to_string(j.get<std::int64_t>()); };
    chk.Expect("mode", out.at("mode").get<std::string>(), ro::ToString(s.mode));
    chk.Expect("stop_reason", out.at("stop_reason").get<std::string>(), ro::ToString(s.stop_reason));
    chk.Expect("deviation_count", num(out.at("deviation_count")), std::to_string(s.deviation_count));
    for (std::size_t c = 0; c < static_cast<std::size_t>(ro::kMaxStartPoints); ++c) {
      const json& ec = out.at("candidates")[c];
      const ro::Candidate& ac = s.candidates[c];
      const std::string name = "candidates[" + std::to_string(c) + "].";
      chk.Expect(name + "active", Bool(ec.at("active").get<bool>()), Bool(ac.active));
      chk.Expect(name + "age_cycles", num(ec.at("age_cycles")), std::to_string(ac.age_cycles));
      chk.Expect(name + "confirm", num(ec.at("confirm")), std::to_string(ac.confirm));
    }
    chk.Expect("max_compensation_cycles", num(out.at("max_compensation_cycles")),
               std::to_string(s.max_compensation_cycles));
    chk.Expect("margin_mm", num(out.at("margin_mm")), std::to_string(s.margin_mm));
    chk.Expect("stop_demand", Bool(out.at("stop_demand").get<bool>()), Bool(s.stop_demand));
    chk.Expect("position_valid", Bool(out.at("position_valid").get<bool>()), Bool(s.position_valid));
    chk.Expect("trusted", Bool(out.at("trusted").get<bool>()), Bool(s.trusted));
    chk.Expect("rest_cycles", num(out.at("rest_cycles")), std::to_string(s.rest_cycles));
    chk.Expect("detected", Bool(out.at("detected").get<bool>()), Bool(s.detected));
    chk.Expect("adopted", rcli::OptInt(out.at("adopted")), Adopted(s.adopted));
    chk.Expect("balise_reset", Bool(out.at("balise_reset").get<bool>()), Bool(s.balise_reset));
  }
}

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunJsonVectors({.prog = "railproof-conformance-ra",
                               .suite = "ReadhesionConformance",
                               .description = "Replays every ra*.jsonl vector of DIR against the C++ re-adhesion state "
                                              "machine\n(ra::ReadhesionMachine), configured by each file's header. "
                                              "Exit 0 only if every\nvector matches.",
                               .prefix = "ra",
                               .models = {"models/ra.pml"},
                               .units = "model ticks = cycles, model margin units = mm",
                               .keys = rcli::RaVectorKeys(),
                               .header = Header,
                               .step_ok = StepWellFormed,
                               .replay = Replay},
                              argc, argv);
}
