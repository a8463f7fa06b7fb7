// Reading a directory of JSON Lines vector files (<prefix>*.jsonl: a header line, then one
// vector per line), shared by the conformance runners of br, ra, lc and mb (jsonl_runner.hpp). Every
// error names the file and line; the capability-specific checks (header fields, step
// shape) are the callbacks'.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <string>
#include <vector>

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

struct VectorLine {
  std::string file;       // file name (no directory)
  std::string where;      // "file:line" for messages
  std::string test_name;  // Sanitize(stem + "_" + id), unique over the directory
  std::string id;
  std::size_t line = 0;
  const nlohmann::json* obj = nullptr;  // the whole vector (id, steps non-empty list, ...)
};

// Reads every <prefix>*.jsonl of dir in name order. on_header(file, where, obj) is called
// for the first line of each file, on_vector for every other non-empty line whose object
// has a string id and a non-empty steps list; a callback returns "" or an error reason
// (reported with its file and line). Returns "" or the first error; `files` receives the
// number of files read.
inline std::string ReadVectorDirectory(
    const std::filesystem::path& dir, const std::string& prefix,
    const std::function<std::string(const std::string&, const nlohmann::json&)>& on_header,
    const std::function<std::string(const VectorLine&)>& on_vector, std::size_t& files) {
  namespace fs = std::filesystem;
  files = 0;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return "vector directory " + dir.string() + " does not exist";
  }
  std::vector<fs::path> paths;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && e.path().extension() == ".jsonl" && name.rfind(prefix, 0) == 0) {
      paths.push_back(e.path());
    }
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) {
    return "no *.jsonl vector file (" + prefix + "*.jsonl) in " + dir.string();
  }
  std::set<std::string> names;
  std::size_t vectors = 0;
  for (const fs::path& f : paths) {
    std::ifstream in(f);
    std::string text;
    std::size_t n = 0;
    bool have_header = false;
    while (std::getline(in, text)) {
      ++n;
      const std::string where = f.filename().string() + ":" + std::to_string(n);
      if (text.empty()) {
        continue;
      }
      const nlohmann::json obj = nlohmann::json::parse(text, nullptr, false);
      if (obj.is_discarded() || !obj.is_object()) {
        return where + ": not a JSON object";
      }
      if (!have_header) {
        if (std::string e = on_header(f.filename().string(), obj); !e.empty()) {
          return where + ": " + e;
        }
        have_header = true;
        continue;
      }
      if (!obj.contains("id") || !obj["id"].is_string() || !obj.contains("steps") ||
          !obj["steps"].is_array() || obj["steps"].empty()) {
        return where + ": vector needs an id and a non-empty steps list";
      }
      VectorLine v;
      v.file = f.filename().string();
      v.where = where;
      v.id = obj["id"].get<std::string>();
      v.test_name = Sanitize(f.stem().string() + "_" + v.id);
      v.line = n;
      v.obj = &obj;
      if (!names.insert(v.test_name).second) {
        return where + ": duplicate vector id " + v.id;
      }
      if (std::string e = on_vector(v); !e.empty()) {
        return where + ": " + e;
      }
      ++vectors;
    }
    if (!have_header) {
      return f.filename().string() + ": empty file (no header)";
    }
    ++files;
  }
  if (vectors == 0) {
    return "no vector in the " + std::to_string(paths.size()) + " " + prefix + "*.jsonl file(s) of " +
           dir.string();
  }
  return "";
}

}  // namespace railproof::conformance
