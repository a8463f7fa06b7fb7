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
// start_points, spacing_cycles: ra::MachineConfig, which must validate). Each vector
// starts from a fresh machine. Each step is one cycle: the predicates (deviation,
// speed_agrees, imu_ok, tg_ok, balise), the section limits and the start-point age go to
// ReadhesionMachine::Step (model ticks are cycles, the model's margins mm: header "units"),
// which must accept them; expected: every field of the machine state after the cycle
// (mode, stop reason, deviation count, both candidates, t_max and margin in force, stop
// demand, position validity, the detection, adoption and balise-reset events). On a
// mismatch the failure names the vector, the step, the field, expected and actual.
// Last line: "railproof-conformance-ra: all N vectors passed" or
// "railproof-conformance-ra: vectors mismatched: K of N" or "...: error: <reason>".
#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "railproof/testing/jsonl_vectors.hpp"
#include "railproof/ra/readhesion_machine.hpp"
#include "railproof/testing/runner_cli.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace fs = std::filesystem;
namespace ro = railproof::ra;
using json = nlohmann::json;

constexpr const char* kModel = "models/ra.pml";
constexpr const char* kUnits = "model ticks = cycles, model margin units = mm";

struct Vector {
  std::string id;
  std::string test_name;
  std::string file;
  std::size_t line = 0;
  ro::MachineConfig config;
  json steps;
};

std::vector<Vector> g_vectors;
std::set<std::string> g_files;
std::map<std::string, ro::MachineConfig> g_configs;  // per file, from its header
std::atomic<std::size_t> g_mismatched{0};
std::atomic<std::size_t> g_replayed{0};

bool IsBool(const json& o, const char* k) { return o.contains(k) && o[k].is_boolean(); }
bool IsInt(const json& o, const char* k) { return o.contains(k) && o[k].is_number_integer(); }

bool BoolPair(const json& o, const char* k) {
  return o.contains(k) && o[k].is_array() && o[k].size() == 2 && o[k][0].is_boolean() && o[k][1].is_boolean();
}

// Checks the shape of one step (the schema is checked when the vectors are written; this
// guards the harness against a hand-edited or truncated file).
bool StepWellFormed(const json& step) {
  if (!step.is_object() || !step.contains("in") || !step.contains("out") || !step["in"].is_object() ||
      !step["out"].is_object()) {
    return false;
  }
  const json& in = step["in"];
  const json& out = step["out"];
  for (const char* k : {"deviation", "imu_ok", "tg_ok", "balise"}) {
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
  for (const char* k : {"deviation_count", "max_compensation_cycles", "margin_mm"}) {
    if (!IsInt(out, k)) {
      return false;
    }
  }
  for (const char* k : {"stop_demand", "position_valid", "detected", "balise_reset"}) {
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
  if (!p.is_object() || !IsInt(p, "confirm_cycles") || !IsInt(p, "start_points") || !IsInt(p, "spacing_cycles")) {
    return "header parameters need integer confirm_cycles, start_points, spacing_cycles";
  }
  const std::int64_t confirm = p["confirm_cycles"].get<std::int64_t>();
  const std::int64_t points = p["start_points"].get<std::int64_t>();
  const std::int64_t spacing = p["spacing_cycles"].get<std::int64_t>();
  if (confirm < 0 || confirm > 255 || points < 0 || points > 255 || spacing < INT32_MIN || spacing > INT32_MAX) {
    return "header machine configuration out of range";
  }
  cfg.confirm_cycles = static_cast<std::uint8_t>(confirm);
  cfg.start_points = static_cast<std::uint8_t>(points);
  cfg.spacing_cycles = static_cast<std::int32_t>(spacing);
  if (const ro::MachineError e = ro::ReadhesionMachine::Validate(cfg); e != ro::MachineError::kNone) {
    return std::string("header machine configuration rejected: ") + ro::ToString(e);
  }
  return "";
}

// Loads every ra*.jsonl of dir; an error names the file and line.
bool Load(const fs::path& dir, std::string& error) {
  std::size_t files = 0;
  error = rcli::ReadVectorDirectory(
      dir, "ra",
      [](const std::string& file, const json& obj) -> std::string {
        if (obj.value("kind", "") != "header" || obj.value("model", "") != kModel || !obj.contains("parameters")) {
          return "first line is not a " + std::string(kModel) + " vector header";
        }
        if (obj.value("units", "") != kUnits) {
          return "header units must be \"" + std::string(kUnits) + "\"";
        }
        ro::MachineConfig cfg;
        if (std::string e = ConfigFromHeader(obj, cfg); !e.empty()) {
          return e;
        }
        g_configs[file] = cfg;
        g_files.insert(file);
        return "";
      },
      [](const rcli::VectorLine& line) -> std::string {
        for (const json& step : (*line.obj)["steps"]) {
          if (!StepWellFormed(step)) {
            return "malformed step in vector " + line.id;
          }
        }
        g_vectors.push_back(
            Vector{line.id, line.test_name, line.file, line.line, g_configs.at(line.file), (*line.obj)["steps"]});
        return "";
      },
      files);
  return error.empty();
}

std::string Bool(bool b) { return b ? "true" : "false"; }
std::string Adopted(std::int8_t a) { return a == ro::kNoCandidate ? "null" : std::to_string(a); }
std::string Adopted(const json& a) { return a.is_null() ? "null" : std::to_string(a.get<std::int64_t>()); }

class VectorTest : public testing::Test {
 public:
  explicit VectorTest(std::size_t index) : index_(index) {}
  void TestBody() override {
    const Vector& v = g_vectors[index_];
    g_replayed.fetch_add(1);
    RecordProperty("vector_id", v.id);
    std::vector<std::string> problems;
    Replay(v, problems);
    if (!problems.empty()) {
      g_mismatched.fetch_add(1);
    }
    for (const std::string& p : problems) {
      ADD_FAILURE_AT(v.file.c_str(), static_cast<int>(v.line)) << "vector " << v.id << ": " << p;
    }
  }

 private:
  static void Replay(const Vector& v, std::vector<std::string>& problems) {
    ro::ReadhesionMachine m(v.config);
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
      p.section.max_compensation_cycles = in.at("section").at("max_compensation_cycles").get<std::int32_t>();
      p.section.margin_mm = in.at("section").at("margin_mm").get<std::int64_t>();
      p.start_age_cycles = in.at("start_age_cycles").get<std::int32_t>();
      const std::string where = "step " + std::to_string(k) + " (cycle " + std::to_string(k + 1) + "): ";
      if (const ro::MachineError e = m.Step(p); e != ro::MachineError::kNone) {
        problems.push_back(where + "Step rejected the inputs: " + ro::ToString(e) + " [inputs " + in.dump() + "]");
        break;
      }
      const ro::MachineState& s = m.state();
      auto expect = [&](const std::string& field, const std::string& expected, const std::string& actual) {
        if (expected != actual) {
          problems.push_back(where + field + " expected " + expected + ", got " + actual + " [inputs " + in.dump() +
                             "]");
        }
      };
      auto num = [](const json& j) { return std::to_string(j.get<std::int64_t>()); };
      expect("mode", out.at("mode").get<std::string>(), ro::ToString(s.mode));
      expect("stop_reason", out.at("stop_reason").get<std::string>(), ro::ToString(s.stop_reason));
      expect("deviation_count", num(out.at("deviation_count")), std::to_string(s.deviation_count));
      for (std::size_t c = 0; c < static_cast<std::size_t>(ro::kMaxStartPoints); ++c) {
        const json& ec = out.at("candidates")[c];
        const ro::Candidate& ac = s.candidates[c];
        const std::string name = "candidates[" + std::to_string(c) + "].";
        expect(name + "active", Bool(ec.at("active").get<bool>()), Bool(ac.active));
        expect(name + "age_cycles", num(ec.at("age_cycles")), std::to_string(ac.age_cycles));
        expect(name + "confirm", num(ec.at("confirm")), std::to_string(ac.confirm));
      }
      expect("max_compensation_cycles", num(out.at("max_compensation_cycles")),
             std::to_string(s.max_compensation_cycles));
      expect("margin_mm", num(out.at("margin_mm")), std::to_string(s.margin_mm));
      expect("stop_demand", Bool(out.at("stop_demand").get<bool>()), Bool(s.stop_demand));
      expect("position_valid", Bool(out.at("position_valid").get<bool>()), Bool(s.position_valid));
      expect("detected", Bool(out.at("detected").get<bool>()), Bool(s.detected));
      expect("adopted", Adopted(out.at("adopted")), Adopted(s.adopted));
      expect("balise_reset", Bool(out.at("balise_reset").get<bool>()), Bool(s.balise_reset));
    }
  }

  std::size_t index_;
};

}  // namespace

int main(int argc, char** argv) {
  return rcli::RunnerMain<VectorTest>(
      "railproof-conformance-ra", "ReadhesionConformance",
      "Replays every ra*.jsonl vector of DIR against the C++ re-adhesion state machine\n"
      "(ra::ReadhesionMachine), configured by each file's header. Exit 0 only if every\n"
      "vector matches.",
      argc, argv, Load, g_vectors, g_files, g_mismatched, g_replayed);
}
