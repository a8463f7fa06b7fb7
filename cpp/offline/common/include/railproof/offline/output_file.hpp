// The result files of one run of an offline tool, written all or none:
//
//   OutputFiles out;
//   out.Reserve(json);          // before the computation: a path that cannot be written
//   out.Directory(svg_dir);     //   fails now, not after it
//   ...
//   out.Write(json, text);      // into a temporary file beside the result, <path>.tmp
//   out.Commit();               // every temporary file renamed over its result
//
// A reader (or the build) never sees a half-written result, and a run that ends before Commit
// (bad input, an output that cannot be written, any error) removes every temporary file it
// made and every directory it created: the results of the previous run stay as they were,
// with no mix of new and old files and nothing left behind. Every tool creates its output
// directories the same way: the missing parents of each file it writes, and each directory
// named on its command line, at the start. Failures are InputError "<path>: cannot write:
// <reason>" and "<dir>: cannot create the output directory: <reason>" (exit status 2 through
// RunTool). The methods may be called from several threads.
// Offline module (may allocate and throw).
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

namespace railproof::offline {

class OutputFiles {
 public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  // Without Commit: removes the temporary files and the directories the run created.
  ~OutputFiles();

  // Creates `dir` and its missing parents now.
  void Directory(const std::filesystem::path& dir);
  // Checks now that `path` can be written: its directory is created and its temporary file
  // made (empty until Write). Every path is one output: a second Reserve, Write or Stream of
  // it is an error ("two outputs of this run have this name").
  void Reserve(const std::filesystem::path& path);
  // The text of `path` (reserved or not).
  void Write(const std::filesystem::path& path, std::string_view text);
  // A result JSON file in the tools' one format: indented by one space, ending with a newline
  // (nlohmann::json or ordered_json).
  template <typename Json>
  void WriteJson(const std::filesystem::path& path, const Json& json) {
    Write(path, json.dump(1) + "\n");
  }
  // A stream into the temporary file of `path`, for a large result written while it is made
  // (line_sim's event log); its errors are reported by Commit.
  std::ostream& Stream(const std::filesystem::path& path);
  // Renames every temporary file over its result (a file reserved but never written is left
  // as it was).
  void Commit();

 private:
  struct File {
    std::filesystem::path path;
    std::filesystem::path tmp;
    bool written = false;
    std::unique_ptr<std::ofstream> stream;
  };
  // The entry of a new output `path`, with its directory made (mu_ held).
  File& Add(const std::filesystem::path& path);
  void MakeDirectory(const std::filesystem::path& dir);  // mu_ held

  std::mutex mu_;
  std::map<std::filesystem::path, File> files_;  // by the lexically normal absolute path
  std::vector<std::filesystem::path> created_;   // directories made by this run, outermost first
  bool committed_ = false;
};

}  // namespace railproof::offline
