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
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "railproof/br/supervisor.hpp"
#include "railproof/testing/jsonl_vectors.hpp"
#include "railproof/testing/runner_cli.hpp"

namespace rcli = railproof::conformance;

namespace {

namespace fs = std::filesystem;
namespace rb = railproof::br;
using json = nlohmann::json;

constexpr const char* kModel = "models/br.pml";
constexpr const char* kUnits = "abstract speed units = mm/s";

struct Vector {
  std::string id;
  std::string test_name;
  std::string file;
  std::size_t line = 0;
  json steps;
};

std::vector<Vector> g_vectors;
std::set<std::string> g_files;
std::atomic<std::size_t> g_mismatched{0};
std::atomic<std::size_t> g_replayed{0};

// Checks the shape of one step (the schema is checked when the vectors are written; this
// guards the harness against a hand-edited or truncated file).
bool StepWellFormed(const json& step) {
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

// Loads every br*.jsonl of dir; an error names the file and line.
bool Load(const fs::path& dir, std::string& error) {
  std::size_t files = 0;
  error = rcli::ReadVectorDirectory(
      dir, "br",
      [](const std::string& file, const json& obj) -> std::string {
        if (obj.value("kind", "") != "header" || obj.value("model", "") != kModel || !obj.contains("parameters")) {
          return "first line is not a " + std::string(kModel) + " vector header";
        }
        if (obj.value("units", "") != kUnits) {
          return "header units must be \"" + std::string(kUnits) + "\"";
        }
        g_files.insert(file);
        return "";
      },
      [](const rcli::VectorLine& line) -> std::string {
        for (const json& step : (*line.obj)["steps"]) {
          if (!StepWellFormed(step)) {
            return "malformed step in vector " + line.id;
          }
        }
        g_vectors.push_back(Vector{line.id, line.test_name, line.file, line.line, (*line.obj)["steps"]});
        return "";
      },
      files);
  return error.empty();
}

const char* Bool(bool b) { return b ? "true" : "false"; }

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
    rb::Supervisor sup;
    for (std::size_t k = 0; k < v.steps.size() && problems.empty(); ++k) {
      const json& in = v.steps[k].at("in");
      const json& out = v.steps[k].at("out");
      rb::PatternSpeeds p;
      p.v_s = in.at("v_s").get<std::int64_t>();
      p.v_e = in.at("v_e").get<std::int64_t>();
      p.v_7n = in.at("v_7n").get<std::int64_t>();
      p.v_6n = in.at("v_6n").get<std::int64_t>();
      p.v_5n = in.at("v_5n").get<std::int64_t>();
      p.v_4n = in.at("v_4n").get<std::int64_t>();
      p.v_release = in.at("v_release").get<std::int64_t>();
      rb::DriverInputs d;
      d.standstill = in.at("standstill").get<bool>();
      d.handle_emergency = in.at("handle_emergency").get<bool>();
      d.reset = in.at("reset").get<bool>();
      const rb::Decision got = sup.Step(p, d);
      auto expect = [&](const std::string& field, const std::string& expected, const std::string& actual) {
        if (expected != actual) {
          problems.push_back("step " + std::to_string(k) + " (cycle " + std::to_string(k + 1) + "): " + field +
                             " expected " + expected + ", got " + actual + " [inputs " + in.dump() + "]");
        }
      };
      expect("level", out.at("level").get<std::string>(), rb::ToString(got.level));
      expect("pattern_approaching", Bool(out.at("pattern_approaching").get<bool>()), Bool(got.pattern_approaching));
      expect("emergency_latched", Bool(out.at("emergency_latched").get<bool>()), Bool(got.emergency_latched));
      expect("Supervisor::emergency_latched()", Bool(out.at("emergency_latched").get<bool>()),
             Bool(sup.emergency_latched()));
    }
  }

  std::size_t index_;
};


}  // namespace

int main(int argc, char** argv) {
  return rcli::RunnerMain<VectorTest>(
      "railproof-conformance-br", "BrakingConformance",
      "Replays every br*.jsonl vector of DIR against the C++ speed-supervision decision\n"
      "(br::Supervisor). Exit 0 only if every vector matches.",
      argc, argv, Load, g_vectors, g_files, g_mismatched, g_replayed);
}
