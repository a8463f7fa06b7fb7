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

#include "d1_margin_case.hpp"

namespace railproof::br::analysis {
namespace {

using testing::Train;
std::filesystem::path DataDir() { return std::filesystem::path(__FILE__).parent_path() / "data"; }

// The falsifier at the end of track of D1's up line for `train`, seed 1, within `budget_s`,
// over the moving states only (a standing restart is not searched).
FalsifierResult FalsifyMovingAtEndOfTrack(const std::string& train, double budget_s) {
  const D1UpModel d1(train);
  FalsifierOptions o;
  o.budget_s = budget_s;
  o.seed = 1;
  o.admit_standstill_restart = false;
  return Falsify(d1.model, kD1EndOfTrack, d1.line.name, o);
}

// @verifies REQ-BR-009 REQ-BR-014
TEST(Falsifier, FindsAViolationForTheWeakenedTrain) {
  const FalsifierResult r = FalsifyMovingAtEndOfTrack("emu3_d1_weak", 2.0);  // the weak brake alone must be found
  ASSERT_TRUE(r.violation);
  EXPECT_GT(r.max_overrun_mm, 1000.0);
  // the case replays as unsafe for the weak train
  const nlohmann::json c = nlohmann::json::parse(r.regression_case.dump());
  EXPECT_GT(ReplayCase(c, Train("emu3_d1_weak"), "found", false).max_overrun_mm, 0.0);
}

// @verifies REQ-BR-009 REQ-BR-014
TEST(Falsifier, FindsNoViolationForACorrectTrainInItsMovingStates) {
  const FalsifierResult r = FalsifyMovingAtEndOfTrack("emu3_d1", 1.0);
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
