// Command line, test registration and exit protocol shared by the conformance runners
// (railproof_conformance, _mb, _br, _ra, _lc):
//   <runner> --vectors DIR [--junit FILE] [--gtest_* flags]
// Exit status 0 if every vector passed, 1 if not (or no usable vector set), 2 on bad
// arguments. The last line printed is one of
//   "<prog>: all N vectors passed (M in the set)"
//   "<prog>: vectors mismatched: K of N"      (the seeded-fault tests look for K > 0)
//   "<prog>: error: <reason>"
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <functional>
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

// Reads the runner's own flags, passes --gtest_* flags (and --junit as --gtest_output) to
// GoogleTest and initialises it.
inline RunnerArgs ParseArgsAndInitGoogleTest(const char* prog, int argc, char** argv,
                                             void (*usage)(std::FILE*)) {
  RunnerArgs out;
  std::string junit;
  std::vector<std::string> gtest_args = {argc > 0 ? argv[0] : prog};
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      usage(stdout);
      out.exit_code = 0;
      return out;
    }
    if ((arg == "--vectors" || arg == "--junit") && i + 1 < argc) {
      (arg == "--vectors" ? out.vectors_dir : junit) = argv[++i];
    } else if (arg.rfind("--vectors=", 0) == 0) {
      out.vectors_dir = arg.substr(std::strlen("--vectors="));
    } else if (arg.rfind("--junit=", 0) == 0) {
      junit = arg.substr(std::strlen("--junit="));
    } else if (arg.rfind("--gtest_", 0) == 0) {
      gtest_args.push_back(arg);
    } else {
      std::fprintf(stderr, "%s: error: unknown or incomplete argument \"%s\" (see --help)\n", prog,
                   arg.c_str());
      out.exit_code = 2;
      return out;
    }
  }
  if (out.vectors_dir.empty()) {
    std::fprintf(stderr, "%s: error: --vectors DIR is required (see --help)\n", prog);
    out.exit_code = 2;
    return out;
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
    std::fprintf(stderr, "%s: error: unknown GoogleTest flag \"%s\"\n", prog, gtest_argv[1]);
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

// Where a vector's test is reported: its GoogleTest name and the file and line of the vector.
struct VectorSite {
  std::string test_name;
  std::string file;
  int line = 0;
};

// Registers the VectorSet test and one test per loaded vector (suite `suite`), prints the
// load result, runs the tests and applies the exit protocol. site(i) names vector i's test,
// make_test(i) creates it; n is the number of vectors loaded (0 if the load failed).
inline int RunVectorTests(const char* prog, const char* suite, const RunnerArgs& args, bool ok,
                          const std::string& error, std::size_t n, std::size_t files,
                          const std::function<VectorSite(std::size_t)>& site,
                          const std::function<testing::Test*(std::size_t)>& make_test,
                          const std::atomic<std::size_t>& mismatched, const std::atomic<std::size_t>& replayed) {
  testing::RegisterTest(suite, "VectorSet", nullptr, nullptr, __FILE__, __LINE__,
                        [error, files, n]() -> testing::Test* { return new VectorSetTest(error, files, n); });
  for (std::size_t i = 0; i < n; ++i) {
    const VectorSite at = site(i);
    testing::RegisterTest(suite, at.test_name.c_str(), nullptr, nullptr, at.file.c_str(), at.line,
                          [make_test, i]() -> testing::Test* { return make_test(i); });
  }
  ReportLoad(prog, ok, error, n, files, args.vectors_dir);
  const int rc_tests = RUN_ALL_TESTS();
  return Finish(prog, ok, error, mismatched.load(), replayed.load(), n, rc_tests);
}

}  // namespace railproof::conformance
