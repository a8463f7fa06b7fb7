// The runner of a capability whose vectors are JSON Lines files read by ReadVectorDirectory
// (br, ra, lc, mb): the runner states its files' prefix, model and units, what else a file's
// header must give, how a step's shape is checked and how one vector is replayed; RunJsonVectors is its
// main() (railproof/testing/runner_cli.hpp: command line, one test per vector, exit
// protocol). The comparison helpers below give every runner's failures the same form:
//   "vector <id>: <where><field> expected <e>, got <a><inputs>"
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "railproof/testing/jsonl_vectors.hpp"
#include "railproof/testing/runner_cli.hpp"

namespace railproof::conformance {

// A vector as the runner keeps it: its id, test name, file (no directory), line and steps.
struct JsonVector {
  std::string id;
  std::string test_name;
  std::string file;
  std::size_t line = 0;
  nlohmann::json steps;
};

// The string obj[key], or "" if obj has none there.
inline std::string StringField(const nlohmann::json& obj, const char* key) {
  const auto it = obj.find(key);
  return it != obj.end() && it->is_string() ? it->get<std::string>() : std::string();
}

// "" if obj is the header line of a vector file of one of `models` (the model, parameters)
// stating `units` (if not empty); else the reason. (Kind, version, count and digest:
// ReadVectorFile.)
inline std::string CheckHeader(const nlohmann::json& obj, const std::vector<std::string>& models,
                               const std::string& units) {
  const std::string model = StringField(obj, "model");
  bool known = false;
  std::string names;
  for (const std::string& m : models) {
    known = known || model == m;
    names += (names.empty() ? "" : " or ") + m;
  }
  if (!known || !obj.contains("parameters") || !obj["parameters"].is_object()) {
    return "first line is not a " + names + " vector header";
  }
  if (!units.empty() && StringField(obj, "units") != units) {
    return "header units must be \"" + units + "\"";
  }
  return "";
}

struct JsonRunner {
  const char* prog = "";    // names the runner in every line it prints
  const char* suite = "";   // the GoogleTest suite
  std::string description;  // opens --help
  std::string prefix;       // the vector files are <prefix>*.jsonl
  std::vector<std::string> models;  // a file's header names one of these models
  std::string units;                // ... and states these units ("": it states none)
  // the keys of its header, vectors and steps besides those every vector file has: any
  // other key is refused (vector_file.hpp)
  VectorKeys keys;
  // checks the rest of a file's header (its first line) and keeps what the file's vectors
  // need: "" or the reason the file is unusable; empty: nothing more to check
  std::function<std::string(const std::string& file, const nlohmann::json& header)> header;
  // checks the shape of one step of a vector of `file` (the schema is checked when the
  // vectors are written; this guards the harness against a hand-edited or truncated file);
  // empty: the replay checks the steps itself
  std::function<bool(const std::string& file, const nlohmann::json& step)> step_ok;
  // replays one vector (ReplayFn)
  std::function<void(const JsonVector& vector, std::vector<std::string>& problems)> replay;
};

// The main() of a JSON Lines runner.
inline int RunJsonVectors(const JsonRunner& r, int argc, char** argv) {
  std::vector<JsonVector> vectors;
  std::set<std::string> files;  // those whose header was accepted
  return RunnerMain(
      r.prog, r.suite, r.description, argc, argv,
      [&](const std::string& dir) {
        std::size_t read = 0;
        const std::string error = ReadVectorDirectory(
            dir, r.prefix, r.keys,
            [&](const std::string& file, const nlohmann::json& obj) -> std::string {
              std::string e = CheckHeader(obj, r.models, r.units);
              if (e.empty() && r.header) {
                e = r.header(file, obj);
              }
              if (e.empty()) {
                files.insert(file);
              }
              return e;
            },
            [&](const VectorLineRef& line) -> std::string {
              const nlohmann::json& steps = (*line.obj)["steps"];
              if (r.step_ok) {
                for (std::size_t k = 0; k < steps.size(); ++k) {
                  if (!r.step_ok(line.file, steps[k])) {
                    return "malformed step " + std::to_string(k) + " in vector " + Quoted(line.id);
                  }
                }
              }
              vectors.push_back(JsonVector{line.id, line.test_name, line.file, line.line, steps});
              return "";
            },
            read);
        return LoadedSet{error.empty(), error, vectors.size(), files.size()};
      },
      [&](std::size_t i) { return SiteOf(vectors, i); },
      [&](std::size_t i, std::vector<std::string>& problems) { r.replay(vectors[i], problems); });
}

// Values as the failures print them.
inline std::string Bool(bool b) { return b ? "true" : "false"; }
inline std::string OptInt(const nlohmann::json& j) {
  return j.is_null() ? "null" : std::to_string(j.get<std::int64_t>());
}
inline std::string OptInt(const std::optional<std::int64_t>& x) { return x ? std::to_string(*x) : "null"; }

// Collects the problems of one step (or unit) of a replay: each is `where` (e.g. "step 3
// (cycle 4): "), the text, and, if the step's inputs are given, " [inputs <json>]".
class Checker {
 public:
  Checker(std::vector<std::string>& problems, std::string where, const nlohmann::json* inputs = nullptr)
      : problems_(problems), where_(std::move(where)), inputs_(inputs) {}
  void Expect(const std::string& field, const std::string& expected, const std::string& actual) {
    if (expected != actual) {
      Fail(field + " expected " + expected + ", got " + actual);
    }
  }
  void Fail(const std::string& what) {
    problems_.push_back(where_ + what + (inputs_ != nullptr ? " [inputs " + inputs_->dump() + "]" : std::string()));
  }

 private:
  std::vector<std::string>& problems_;
  std::string where_;
  const nlohmann::json* inputs_;
};

}  // namespace railproof::conformance
