// Command line, test registration and exit protocol shared by the conformance runners
// (railproof_conformance_<cap>): RunnerMain is their main().
//   <runner> --vectors DIR [--junit FILE] [--gtest_* flags]
// The command line is parsed by CLI11, as every tool's (railproof/offline/cli.hpp): --help
// prints the generated help and exits 0; bad usage prints "<prog>: error: <reason> (see
// --help)" and exits 2, and so does a report path (--junit, --gtest_output) that cannot be
// written ("<prog>: error: cannot write the test report <path>: <reason>", checked before
// anything runs). Exit status 0 if every vector passed, 1 if not (or no usable vector set).
// The last line printed is one of
//   "<prog>: all N vectors passed (M in the set)"
//   "<prog>: vectors mismatched: K of N"      (the seeded-fault tests look for K > 0)
//   "<prog>: error: <reason>"
#pragma once

#include <CLI/CLI.hpp>
#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace railproof::conformance {

struct RunnerArgs {
  std::string vectors_dir;
  int exit_code = -1;  // >= 0: main returns it at once (--help, bad arguments)
};

// The first test of every run: the vector set loaded without error and is not empty (a
// conformance run over no vectors is a failure). Records the counts for the evidence.
class VectorSetTest : public testing::Test {
 public:
  VectorSetTest(std::string error, std::size_t files, std::size_t vectors)
      : error_(std::move(error)), files_(files), vectors_(vectors) {}
  void TestBody() override {
    RecordProperty("vector_files", static_cast<int>(files_));
    RecordProperty("vectors", static_cast<int>(vectors_));
    ASSERT_TRUE(error_.empty()) << error_;
    EXPECT_GT(files_, 0U);
    EXPECT_GT(vectors_, 0U) << "a conformance run over no vectors is a failure";
  }

 private:
  std::string error_;
  std::size_t files_;
  std::size_t vectors_;
};

// "" if GoogleTest can write the report its --gtest_output flag names (`xml`, `xml:FILE`,
// `xml:DIR/`; GoogleTest aborts the run when it cannot), else the reason. Creates the
// report's directory as GoogleTest would; leaves no file behind.
inline std::string ReportPathProblem(const std::string& flag) {
  namespace fs = std::filesystem;
  if (flag.empty()) {
    return "";
  }
  const std::size_t colon = flag.find(':');
  const std::string format = flag.substr(0, colon);
  const fs::path path = colon == std::string::npos || colon + 1 == flag.size() ? "test_detail." + format
                                                                                : flag.substr(colon + 1);
  const std::string cannot = "cannot write the test report " + path.string() + ": ";
  const bool dir_form = path.string().back() == '/';
  const fs::path dir = dir_form ? path : path.parent_path();
  std::error_code ec;
  if (!dir.empty()) {
    fs::create_directories(dir, ec);
    if (ec) {
      return cannot + ec.message();
    }
  }
  if (dir_form) {
    return ::access(dir.c_str(), W_OK) == 0 ? "" : cannot + std::strerror(errno);
  }
  if (fs::is_directory(path, ec)) {
    return cannot + "it is a directory";
  }
  const bool existed = fs::exists(path, ec);
  {
    std::ofstream probe(path, std::ios::app);  // does not change an existing file
    if (!probe) {
      return cannot + std::strerror(errno);
    }
  }
  if (!existed) {
    fs::remove(path, ec);
  }
  return "";
}

// Reads the runner's own flags (CLI11), passes --gtest_* flags (and --junit as --gtest_output)
// to GoogleTest and initialises it. `description` opens the help.
inline RunnerArgs ParseArgsAndInitGoogleTest(const char* prog, const std::string& description, int argc, char** argv) {
  RunnerArgs out;
  std::string junit;
  CLI::App app(description, prog);
  app.allow_extras();  // the --gtest_* flags, checked below
  app.add_option("--vectors", out.vectors_dir, "directory of the conformance vectors (*.jsonl)")->required();
  app.add_option("--junit", junit, "write JUnit XML (as --gtest_output=xml:FILE)");
  app.footer("Other --gtest_* flags are passed to GoogleTest. Exit status: 0 every vector passed; 1 a\n"
             "vector failed or the vector set is missing, empty or malformed; 2 bad usage or a test\n"
             "report that cannot be written.");
  const auto usage_error = [&](const std::string& reason) {
    std::fprintf(stderr, "%s: error: %s (see --help)\n", prog, reason.c_str());
    out.exit_code = 2;
    return out;
  };
  // the first argument left over that is not a GoogleTest flag
  const auto stray = [&]() -> std::optional<std::string> {
    for (const std::string& a : app.remaining()) {
      if (a.rfind("--gtest_", 0) != 0) {
        return a;
      }
    }
    return std::nullopt;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    std::fputs(app.help().c_str(), stdout);
    out.exit_code = 0;
    return out;
  } catch (const CLI::ParseError& e) {
    const std::optional<std::string> a = stray();
    return usage_error(a ? "unknown argument \"" + *a + "\"" : std::string(e.what()));
  }
  if (const std::optional<std::string> a = stray()) {
    return usage_error("unknown argument \"" + *a + "\"");
  }
  std::vector<std::string> gtest_args = {argc > 0 ? argv[0] : prog};
  for (const std::string& a : app.remaining()) {
    gtest_args.push_back(a);
  }
  if (!junit.empty()) {
    gtest_args.push_back("--gtest_output=xml:" + junit);
  }
  std::vector<char*> gtest_argv;
  for (std::string& a : gtest_args) {
    gtest_argv.push_back(a.data());
  }
  gtest_argv.push_back(nullptr);
  int gtest_argc = static_cast<int>(gtest_args.size());
  testing::InitGoogleTest(&gtest_argc, gtest_argv.data());
  if (gtest_argc > 1) {
    return usage_error("unknown GoogleTest flag \"" + std::string(gtest_argv[1]) + "\"");
  }
  if (const std::string problem = ReportPathProblem(GTEST_FLAG_GET(output)); !problem.empty()) {
    std::fprintf(stderr, "%s: error: %s\n", prog, problem.c_str());
    out.exit_code = 2;
  }
  return out;
}

// Prints the load result before the run (vector count or the error).
inline void ReportLoad(const char* prog, bool ok, const std::string& error, std::size_t vectors,
                       std::size_t files, const std::string& dir) {
  if (!ok) {
    std::fprintf(stderr, "%s: error: %s\n", prog, error.c_str());
  } else {
    std::printf("%s: %zu vectors from %zu file(s) in %s\n", prog, vectors, files, dir.c_str());
  }
}

// The exit protocol after RUN_ALL_TESTS (see the file comment).
inline int Finish(const char* prog, bool ok, const std::string& error, std::size_t mismatched,
                  std::size_t replayed, std::size_t in_set, int rc_tests) {
  if (!ok) {
    std::printf("%s: error: %s\n", prog, error.c_str());
    return 1;
  }
  if (mismatched > 0) {
    std::printf("%s: vectors mismatched: %zu of %zu\n", prog, mismatched, replayed);
    return 1;
  }
  if (rc_tests != 0) {
    std::printf("%s: error: test run failed\n", prog);
    return 1;
  }
  std::printf("%s: all %zu vectors passed (%zu in the set)\n", prog, replayed, in_set);
  return 0;
}

// Where a vector's test is reported: the vector's id, its GoogleTest name and the file and
// line of the vector.
struct VectorSite {
  std::string id;
  std::string test_name;
  std::string file;
  int line = 0;
};

// The site of vector i of a container whose vectors know their id, test name, file and line.
template <typename Vectors>
VectorSite SiteOf(const Vectors& vectors, std::size_t i) {
  return {vectors[i].id, vectors[i].test_name, vectors[i].file, static_cast<int>(vectors[i].line)};
}

// What a runner's loader found in the vector directory.
struct LoadedSet {
  bool ok = false;
  std::string error;        // why the set is not usable (ok false)
  std::size_t vectors = 0;  // loaded (0 if not ok)
  std::size_t files = 0;
};

// How many vectors a run replayed and how many of them mismatched (the exit protocol).
struct ReplayCounts {
  std::atomic<std::size_t> replayed{0};
  std::atomic<std::size_t> mismatched{0};
};

// Replays one vector: appends one line per problem (a mismatch names the step, the field,
// expected and actual); none: the vector passed.
using ReplayFn = std::function<void(std::vector<std::string>& problems)>;

// The test of one vector: records its id, replays it, counts it (and its mismatch) and
// reports every problem at the vector's file and line as "vector <id>: <problem>".
class VectorTest : public testing::Test {
 public:
  VectorTest(VectorSite site, ReplayFn replay, ReplayCounts& counts)
      : site_(std::move(site)), replay_(std::move(replay)), counts_(counts) {}
  void TestBody() override {
    counts_.replayed.fetch_add(1);
    RecordProperty("vector_id", site_.id);
    std::vector<std::string> problems;
    try {
      replay_(problems);
    } catch (const std::exception& e) {  // a step the replay cannot read (e.g. a JSON type error)
      problems.push_back(std::string("malformed vector: ") + e.what());
    }
    if (!problems.empty()) {
      counts_.mismatched.fetch_add(1);
    }
    for (const std::string& p : problems) {
      ADD_FAILURE_AT(site_.file.c_str(), site_.line) << "vector " << site_.id << ": " << p;
    }
  }

 private:
  VectorSite site_;
  ReplayFn replay_;
  ReplayCounts& counts_;
};

// The main() of a runner: parses the arguments (prog names it in every line, suite is the
// GoogleTest suite, description opens --help), loads the vector directory, registers the
// VectorSet test and one VectorTest per vector (site(i) names vector i's test, replay(i, ...)
// replays it), prints the load result, runs the tests and applies the exit protocol.
inline int RunnerMain(const char* prog, const char* suite, const std::string& description, int argc, char** argv,
                      const std::function<LoadedSet(const std::string& dir)>& load,
                      const std::function<VectorSite(std::size_t)>& site,
                      const std::function<void(std::size_t, std::vector<std::string>&)>& replay) {
  const RunnerArgs args = ParseArgsAndInitGoogleTest(prog, description, argc, argv);
  if (args.exit_code >= 0) {
    return args.exit_code;
  }
  const LoadedSet set = load(args.vectors_dir);
  const std::size_t n = set.ok ? set.vectors : 0;
  testing::RegisterTest(suite, "VectorSet", nullptr, nullptr, __FILE__, __LINE__,
                        [error = set.error, files = set.files, n]() -> testing::Test* {
                          return new VectorSetTest(error, files, n);
                        });
  ReplayCounts counts;
  for (std::size_t i = 0; i < n; ++i) {
    const VectorSite at = site(i);
    testing::RegisterTest(suite, at.test_name.c_str(), nullptr, nullptr, at.file.c_str(), at.line,
                          [&replay, &counts, at, i]() -> testing::Test* {
                            return new VectorTest(
                                at, [&replay, i](std::vector<std::string>& problems) { replay(i, problems); },
                                counts);
                          });
  }
  ReportLoad(prog, set.ok, set.error, n, set.files, args.vectors_dir);
  const int rc_tests = RUN_ALL_TESTS();
  return Finish(prog, set.ok, set.error, counts.mismatched.load(), counts.replayed.load(), n, rc_tests);
}

}  // namespace railproof::conformance
