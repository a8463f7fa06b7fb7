// Unit tests of the OMPL falsifier (analysis/falsifier.hpp) and replay of the regression
// cases in cpp/offline/br/tests/data/ (margin_case_*.json).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "railproof/br/analysis/falsifier.hpp"
#include "railproof/br/analysis/margins.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/testing/gen_data.hpp"

namespace railproof::br::analysis {
namespace {

using testing::GenDir;
using testing::Train;
std::filesystem::path DataDir() { return std::filesystem::path(__FILE__).parent_path() / "data"; }


const Location kEndOfTrack{LocationClass::kEndOfTrack, "end of track", 14'500'000, 10'000, 14'490'000};

// @verifies REQ-BR-009 REQ-BR-014
TEST(Falsifier, FindsAViolationForTheWeakenedTrain) {
  const offline::Line line = offline::LoadLine(GenDir() / "lines" / "d1_test_line.json");
  const MarginModel m(line.Running("up"), Train("emu3_d1_weak"), ReferenceSpeedErrorModel());
  FalsifierOptions o;
  o.budget_s = 2.0;
  o.seed = 1;
  o.admit_standstill_restart = false;  // the weak brake alone must be found
  const FalsifierResult r = Falsify(m, kEndOfTrack, line.name, o);
  ASSERT_TRUE(r.violation);
  EXPECT_GT(r.max_overrun_mm, 1000.0);
  // the case replays as unsafe for the weak train
  const nlohmann::json c = nlohmann::json::parse(r.regression_case.dump());
  EXPECT_GT(ReplayCase(c, Train("emu3_d1_weak"), "found", false).max_overrun_mm, 0.0);
}

// @verifies REQ-BR-009 REQ-BR-014
TEST(Falsifier, FindsNoViolationForACorrectTrainInItsMovingStates) {
  const offline::Line line = offline::LoadLine(GenDir() / "lines" / "d1_test_line.json");
  const MarginModel m(line.Running("up"), Train("emu3_d1"), ReferenceSpeedErrorModel());
  FalsifierOptions o;
  o.budget_s = 1.0;
  o.seed = 1;
  o.admit_standstill_restart = false;
  const FalsifierResult r = Falsify(m, kEndOfTrack, line.name, o);
  EXPECT_FALSE(r.violation);
  EXPECT_LT(r.max_overrun_mm, 0.0);
  EXPECT_GT(r.propagations, 1000U);
}

// Every regression case: unsafe for the train it was found on if that train violates the
// design rule (REQ-BR-010), safe for every correct train type.
// @verifies REQ-BR-009 REQ-BR-014 REQ-BR-010
TEST(Falsifier, ReplaysEveryRegressionCase) {
  int cases = 0;
  for (const auto& entry : std::filesystem::directory_iterator(DataDir())) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("margin_case_", 0) != 0 || entry.path().extension() != ".json") {
      continue;
    }
    ++cases;
    std::ifstream in(entry.path());
    const nlohmann::json c = nlohmann::json::parse(in);
    const bool standstill = c.value("admit_standstill_restart", true);
    const TrainType found_on = Train(c.at("train").get<std::string>());
    if (!DesignRuleFindings(found_on).empty()) {
      EXPECT_GT(ReplayCase(c, found_on, name, standstill).max_overrun_mm, 0.0) << name;
    }
    for (const char* t : {"emu3_d1", "dmu2_d4", "emu10_d2"}) {
      const ReplayResult r = ReplayCase(c, Train(t), name, standstill);
      EXPECT_LE(r.max_overrun_mm, 0.0) << name << " with " << t;
    }
  }
  EXPECT_GE(cases, 1);
}

// @verifies REQ-BR-009
TEST(Falsifier, ReplayRejectsAMalformedCase) {
  nlohmann::json c = {{"schema", "railproof/margin-case/1"}};
  try {
    (void)ReplayCase(c, Train("emu3_d1"), "bad_case.json");
    ADD_FAILURE();
  } catch (const offline::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_case.json: "), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace railproof::br::analysis
