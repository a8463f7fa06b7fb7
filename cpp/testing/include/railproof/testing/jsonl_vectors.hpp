// Reading a directory of JSON Lines vector files (<prefix>*.jsonl: a header line, then one
// vector per line), shared by the conformance runners of br, ra, lc and mb (jsonl_runner.hpp).
// Each file is read whole or not at all by ReadVectorFile (vector_file.hpp: schema version,
// count, digest, duplicate and unknown keys); the capability-specific checks (header fields,
// step shape) are the callbacks'. Every error names the file and line.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <vector>

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {

// Letters and digits kept, everything else '_' (a GoogleTest test name).
inline std::string Sanitize(const std::string& s) {
  std::string out = s;
  for (char& c : out) {
    if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'))) {
      c = '_';
    }
  }
  return out;
}

struct VectorLineRef {
  std::string file;       // file name (no directory)
  std::string where;      // "file:line" for messages
  std::string test_name;  // Sanitize(stem + "_" + id), unique over the directory
  std::string id;
  std::size_t line = 0;
  const nlohmann::json* obj = nullptr;  // the whole vector (id, steps non-empty list, ...)
};

// Reads every <prefix>*.jsonl of dir in name order, each with ReadVectorFile and the runner's
// keys. on_header(file, obj) is called for the header of each file, on_vector for every
// vector whose object has a string id and a non-empty steps list; a callback returns "" or
// an error reason (reported with its file and line; a JSON type error it throws too).
// Returns "" or the first error; `files` receives the number of files read.
inline std::string ReadVectorDirectory(
    const std::filesystem::path& dir, const std::string& prefix, const VectorKeys& keys,
    const std::function<std::string(const std::string&, const nlohmann::json&)>& on_header,
    const std::function<std::string(const VectorLineRef&)>& on_vector, std::size_t& files) {
  files = 0;
  std::vector<std::filesystem::path> paths;
  if (std::string e = ListVectorFiles(dir, prefix, paths); !e.empty()) {
    return e;
  }
  std::set<std::string> names;
  std::size_t vectors = 0;
  for (const std::filesystem::path& f : paths) {
    const std::string name = f.filename().string();
    std::string text;
    if (std::string e = ReadFileText(f, text); !e.empty()) {
      return e;
    }
    VectorFile file;
    if (std::string e = ReadVectorFile(name, text, keys, file); !e.empty()) {
      return e;
    }
    std::string where = name + ":1";
    try {
      if (std::string e = on_header(name, file.header); !e.empty()) {
        return where + ": " + e;
      }
      for (const VectorLine& line : file.vectors) {
        where = name + ":" + std::to_string(line.line);
        const nlohmann::json& obj = line.obj;
        if (!obj.contains("id") || !obj["id"].is_string() || !obj.contains("steps") || !obj["steps"].is_array() ||
            obj["steps"].empty()) {
          return where + ": vector needs an id and a non-empty steps list";
        }
        VectorLineRef v{name, where, Sanitize(f.stem().string() + "_" + obj["id"].get<std::string>()),
                        obj["id"].get<std::string>(), line.line, &obj};
        if (!names.insert(v.test_name).second) {
          return where + ": duplicate vector id " + Quoted(v.id);
        }
        if (std::string e = on_vector(v); !e.empty()) {
          return where + ": " + e;
        }
        ++vectors;
      }
    } catch (const nlohmann::json::exception& e) {
      return where + ": malformed: " + e.what();
    }
    ++files;
  }
  if (vectors == 0) {
    return "no vector in the " + std::to_string(paths.size()) + " " + prefix + "*.jsonl file(s) of " + dir.string();
  }
  return "";
}

}  // namespace railproof::conformance
