// The result files of a tool run, all or none (railproof/offline/output_file.hpp): a path that
// cannot be written is named with the reason before the computation; a run that fails after
// some of its files were written leaves the previous results as they were, no temporary file
// and no directory it created; a committed run replaces every result. Each case asserts the
// whole message and the files on disk.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "railproof/offline/line.hpp"
#include "railproof/offline/output_file.hpp"

namespace railproof::offline {
namespace {

namespace fs = std::filesystem;

// A scratch folder holding a regular file `blocker` and a previous result kept/result.json.
class OutputFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("railproof_output_files_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "kept");
    Put(dir_ / "blocker", "blocker\n");
    Put(dir_ / "kept" / "result.json", "previous result\n");
  }
  void TearDown() override { fs::remove_all(dir_); }

  static void Put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }
  static std::string Get(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  // Every file and folder below the scratch folder, relative.
  [[nodiscard]] std::set<std::string> Tree() const {
    std::set<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) {
      out.insert(fs::relative(e.path(), dir_).string());
    }
    return out;
  }
  // The scratch folder as SetUp left it.
  void ExpectUntouched() const {
    EXPECT_EQ(Tree(), (std::set<std::string>{"blocker", "kept", "kept/result.json"}));
    EXPECT_EQ(Get(dir_ / "kept" / "result.json"), "previous result\n");
  }
  template <typename F>
  static std::string ErrorOf(F run) {
    try {
      run();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  fs::path dir_;
};

TEST_F(OutputFilesTest, ACommittedRunReplacesEveryResultAndLeavesNoTemporaryFile) {
  {
    OutputFiles out;
    out.Reserve(dir_ / "kept" / "result.json");
    out.Directory(dir_ / "plots");
    out.WriteJson(dir_ / "kept" / "result.json", nlohmann::json{{"a", 1}});
    out.Write(dir_ / "plots" / "p.svg", "<svg/>");
    out.Stream(dir_ / "new" / "log.json") << "[1,\n2]";
    EXPECT_EQ(Get(dir_ / "kept" / "result.json"), "previous result\n");  // not before Commit
    out.Commit();
  }
  EXPECT_EQ(Get(dir_ / "kept" / "result.json"), "{\n \"a\": 1\n}\n");
  EXPECT_EQ(Get(dir_ / "plots" / "p.svg"), "<svg/>");
  EXPECT_EQ(Get(dir_ / "new" / "log.json"), "[1,\n2]");
  EXPECT_EQ(Tree(), (std::set<std::string>{"blocker", "kept", "kept/result.json", "plots", "plots/p.svg", "new",
                                           "new/log.json"}));
}

TEST_F(OutputFilesTest, AnUnwritablePathIsNamedBeforeTheComputation) {
  OutputFiles out;
  out.Reserve(dir_ / "kept" / "result.json");
  EXPECT_EQ(ErrorOf([&] { out.Reserve(dir_ / "blocker" / "x.json"); }),
            (dir_ / "blocker").string() + ": cannot create the output directory: Not a directory");
  EXPECT_EQ(ErrorOf([&] { out.Directory(dir_ / "blocker" / "svg"); }),
            (dir_ / "blocker" / "svg").string() + ": cannot create the output directory: Not a directory");
  EXPECT_EQ(ErrorOf([&] { out.Reserve(dir_ / "kept"); }), (dir_ / "kept").string() + ": cannot write: Is a directory");
  EXPECT_EQ(ErrorOf([&] { out.Reserve(dir_ / "kept" / "result.json"); }),
            (dir_ / "kept" / "result.json").string() + ": cannot write: two outputs of this run have this name");
}

TEST_F(OutputFilesTest, ARunThatFailsAfterWritingLeavesThePreviousResultsAndNothingElse) {
  {
    OutputFiles out;
    out.Reserve(dir_ / "kept" / "result.json");
    out.Directory(dir_ / "a" / "b");
    out.Write(dir_ / "a" / "b" / "one.svg", "one");
    out.Write(dir_ / "kept" / "result.json", "new result");
    std::ostream& log = out.Stream(dir_ / "logs" / "run.log");
    log << "half a log";
    // a later output fails: the tool's exception ends the run before Commit
    EXPECT_EQ(ErrorOf([&] { out.Write(dir_ / "a" / "b" / "one.svg", "again"); }),
              (dir_ / "a" / "b" / "one.svg").string() + ": cannot write: two outputs of this run have this name");
  }
  ExpectUntouched();
}

TEST_F(OutputFilesTest, AReservedFileThatIsNeverWrittenKeepsItsPreviousContent) {
  {
    OutputFiles out;
    out.Reserve(dir_ / "kept" / "result.json");
    out.Commit();
  }
  ExpectUntouched();
}

}  // namespace
}  // namespace railproof::offline
