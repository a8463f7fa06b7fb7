// railproof_conformance_br: replays the vectors generated from models/br.pml (every
// br*.jsonl of the vector directory) against the C++ speed-supervision decision
// br::Supervisor (railproof_braking), spec/design/br.md §4. One GoogleTest test
// per vector, named BrakingConformance.<file>_<vector id>, plus BrakingConformance.VectorSet,
// which fails if the vector set is missing, empty or malformed.
//
//   railproof_conformance_br --vectors DIR [--junit FILE] [gtest flags]
//
// Each vector starts from a fresh Supervisor (nothing latched, no level applied). Each step
// is one cycle: the inputs v_s, v_e, v_7n, v_6n, v_5n, v_4n, v_release (the model's abstract
// speeds, fed unchanged as mm/s: the decision only compares them, header "units") and
// standstill, handle_emergency, reset go to Supervisor::Step; expected: the level, the
// "pattern approaching" indication and whether the emergency brake is latched (in the
// Decision and in Supervisor::emergency_latched()). On a mismatch the failure names the
// vector, the step, the field, expected and actual.
// Last line: "railproof-conformance-br: all N vectors passed" or
// "railproof-conformance-br: vectors mismatched: K of N" or "...: error: <reason>".
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "railproof/br/supervisor.hpp"
#include "railproof/testing/jsonl_runner.hpp"
#include "vector_keys.hpp"
#include "vector_steps.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace rb = railproof::br;
using json = nlohmann::json;

bool StepWellFormed(const std::string& /*file*/, const json& step) {
  if (!step.is_object() || !step.contains("in") || !step.contains("out")) {
    return false;
  }
  const json& in = step["in"];
  const json& out = step["out"];
  for (const char* k : {"v_s", "v_e", "v_7n", "v_6n", "v_5n", "v_4n", "v_release"}) {
    if (!in.contains(k) || !in[k].is_number_integer()) {
      return false;
    }
  }
  for (const char* k : {"standstill", "handle_emergency", "reset"}) {
    if (!in.contains(k) || !in[k].is_boolean()) {
      return false;
    }
  }
  return out.contains("level") && out["level"].is_string() && out.contains("pattern_approaching") &&
         out["pattern_approaching"].is_boolean() && out.contains("emergency_latched") &&
         out["emergency_latched"].is_boolean();
}

void Replay(const rcli::JsonVector& v, std::vector<std::string>& problems) {
  rb::Supervisor sup;
  for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
    const json& in = v.steps[k].at("in");
    const json& out = v.steps[k].at("out");
    const rb::PatternSpeeds p = rcli::BrPatternSpeedsOf(in);
    const rb::DriverInputs d = rcli::BrDriverInputsOf(in);
    const rb::Decision got = sup.Step(p, d);
    rcli::Checker chk(problems, "step " + std::to_string(k) + " (cycle " + std::to_string(k + 1) + "): ", &in);
    chk.Expect("level", out.at("level").get<std::string>(), rb::ToString(got.level));
    chk.Expect("pattern_approaching", rcli::Bool(out.at("pattern_approaching").get<bool>()),
               rcli::Bool(got.pattern_approaching));
    chk.Expect("emergency_latched", rcli::Bool(out.at("emergency_latched").get<bool>()),
               rcli::Bool(got.emergency_latched));
    chk.Expect("Supervisor::emergency_latched()", rcli::Bool(out.at("emergency_latched").get<bool>()),
               rcli::Bool(sup.emergency_latched()));
  }
}

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunJsonVectors({.prog = "railproof-conformance-br",
                               .suite = "BrakingConformance",
                               .description = "Replays every br*.jsonl vector of DIR against the C++ speed-supervision "
                                              "decision\n(br::Supervisor). Exit 0 only if every vector matches.",
                               .prefix = "br",
                               .models = {"models/br.pml"},
                               .units = "abstract speed units = mm/s",
                               .keys = rcli::BrVectorKeys(),
                               .header = nullptr,  // nothing else in the header
                               .step_ok = StepWellFormed,
                               .replay = Replay},
                              argc, argv);
}
