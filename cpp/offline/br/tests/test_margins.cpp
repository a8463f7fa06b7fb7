// Unit tests of the worst-case braking-margin verification (analysis/margins.hpp,
// analysis/train_type.hpp): train-type loader, design rule, Ipopt derivative checker,
// closed-form flat-line case, NLP versus grid, margins of the real train types on a real
// line section, the weakened train type.
//
// Inputs: the generated line and train JSON of the default build directory
// (<source>/build/gen/{lines,trains}; RAILPROOF_GEN_DIR overrides it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/br/analysis/margins.hpp"
#include "railproof/offline/train_type.hpp"
#include "railproof/offline/line.hpp"
#include "railproof/testing/gen_data.hpp"
#include "railproof/testing/input_error.hpp"

#include "d1_margin_case.hpp"

namespace railproof::br::analysis {
namespace {

using testing::GenDir;
using testing::Train;

std::string ReadAll(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A train JSON text (emu3_d1 values) for the loader tests.
nlohmann::json TrainJson() { return nlohmann::json::parse(ReadAll(GenDir() / "trains" / "emu3_d1.json")); }

void ExpectRejected(const nlohmann::json& j, const std::vector<std::string>& fragments) {
  testing::ExpectInputError([&] { (void)ParseTrainType(j.dump(), "bad_train.json"); }, "bad_train.json", fragments);
}

// @verifies REQ-BR-010
TEST(TrainType, LoadsGeneratedTrainJson) {
  const TrainType t = Train("emu3_d1");
  EXPECT_EQ(t.name, "emu3_d1");
  EXPECT_EQ(t.length_mm, 60000);
  EXPECT_EQ(t.emergency_deceleration_mm_s2.min, 1100);
  EXPECT_EQ(t.emergency_free_running_ms.max, 1500);
  EXPECT_EQ(t.MaxSpeedMmS(), 27778);
  const br::TrainData d = ToTrainData(t);
  EXPECT_EQ(d.beta_e_mm_s2, 1000);
  EXPECT_EQ(d.overspeed_mm_s, 1389);
}

// @verifies REQ-BR-010
TEST(TrainType, RejectsBadJsonNamingFileEntryReason) {
  auto j = TrainJson();
  j.erase("length_mm");
  ExpectRejected(j, {"(top level)", "missing key 'length_mm'"});
  j = TrainJson();
  j["braking"]["emergency_free_running_ms"] = {1500, 500};
  ExpectRejected(j, {"braking.emergency_free_running_ms", "min 1500 ms is greater than max 500 ms"});
  j = TrainJson();
  j["uncertainty"]["odometry_ppm"] = -1;
  ExpectRejected(j, {"uncertainty.odometry_ppm", "outside"});
  // an absurd maximum speed is refused at load: the design tools loop up to it
  j = TrainJson();
  j["max_speed_kmh"] = 100000;
  ExpectRejected(j, {"bad_train.json: max_speed_kmh: value 100000 km/h is outside [1, 300]"});
  j = TrainJson();
  j["braking"]["emergency_overspeed_kmh"] = 31;
  ExpectRejected(j, {"bad_train.json: braking.emergency_overspeed_kmh: value 31 km/h is outside [0, 30]"});
  j = TrainJson();
  j["supervision"]["speed_error_ppm"] = "2500";
  ExpectRejected(j, {"supervision.speed_error_ppm", "expected an integer"});
  j = TrainJson();
  j["braking"]["typo_ms"] = 1;
  ExpectRejected(j, {"braking", "unknown key 'typo_ms'"});
  j = TrainJson();
  j["schema"] = "railproof/line-json/1";
  ExpectRejected(j, {"schema", "unsupported schema"});
  testing::ExpectInputError([] { (void)LoadTrainType("/nonexistent/train.json"); }, "/nonexistent/train.json",
                            {"/nonexistent/train.json: cannot read"});
}

// @verifies REQ-BR-010
TEST(TrainType, DesignRuleFindings) {
  for (const char* name : {"emu3_d1", "dmu2_d4", "emu10_d2"}) {
    EXPECT_TRUE(DesignRuleFindings(Train(name)).empty()) << name;
  }
  const auto f = DesignRuleFindings(Train("emu3_d1_weak"));
  ASSERT_EQ(f.size(), 1U);
  EXPECT_NE(f[0].find("braking.emergency_pattern_mm_s2"), std::string::npos);
  EXPECT_NE(f[0].find("REQ-BR-010"), std::string::npos);
  TrainType t = Train("emu3_d1");
  t.service_pattern_mm_s2 = t.emergency_pattern_mm_s2 + 1;
  EXPECT_EQ(DesignRuleFindings(t).size(), 1U);
}

// @verifies REQ-SC-005 REQ-BR-007
TEST(Margins, SpeedAllowanceCoversTheD3Bound) {
  const SpeedErrorModel se = ReferenceSpeedErrorModel();
  for (const char* name : {"emu3_d1", "dmu2_d4", "emu10_d2"}) {
    EXPECT_EQ(SpeedAllowanceFinding(Train(name), se), "") << name;
  }
  TrainType t = Train("emu3_d1");
  t.speed_error_abs_mm_s = 10;
  t.speed_error_ppm = 0;
  EXPECT_NE(SpeedAllowanceFinding(t, se).find("REQ-SC-005"), std::string::npos);
  // the linear envelope of the NLP bounds dV everywhere
  for (std::int64_t v = 0; v <= 40000; v += 7) {
    EXPECT_LE(static_cast<double>(se.Bound(v)), se.c0_mm_s + se.c1 * static_cast<double>(v) + 1e-9);
  }
}

// A flat, straight running line of 20 km without binding restrictions.
offline::RunningLine FlatLine() {
  offline::RunningLine rl;
  rl.id = "flat";
  rl.length_mm = 20'000'000;
  rl.gradients.push_back({{0, rl.length_mm}, 0});
  rl.speed_limits.push_back({{0, rl.length_mm}, 250});
  rl.balises.push_back({"B1", 1'000'000});
  rl.blocks_mm = {0, rl.length_mm};
  return rl;
}

// @verifies REQ-BR-009 REQ-BR-014 REQ-BR-005
TEST(Margins, FlatLineClosedFormMatchesGridAndNlp) {
  const offline::RunningLine rl = FlatLine();
  const TrainType t = Train("emu3_d1");
  const MarginModel m(rl, t, ReferenceSpeedErrorModel());
  EXPECT_EQ(m.position_error_mm(), std::int64_t{1000} * 19'000'000 / 1'000'000 + t.readhesion_margin_mm);
  const Location loc{LocationClass::kEndOfTrack, "L", 10'010'000, 10'000, 10'000'000};
  // closed form on a level line with the worst data error (1 permille falling): run-up
  // a = accel_max + g ge, T = cycle + reaction + t_f max; braking beta_min - g ge
  const Adversary adv = m.WorstCorner();
  const double g = 9807.0 / 10000.0 * 10.0;  // gravity term of 1 permille (mm/s^2)
  const double a = 920.0 + g;
  const double b = 1100.0 - g;
  const double tt = (200.0 + 100.0 + 1500.0) / 1000.0;
  for (const double v0 : {0.0, 5000.0, 20000.0}) {
    const Trajectory tr = m.Simulate(9'000'000.0, v0, adv, false);
    const double vb = v0 + a * tt;
    const double closed = 9'000'000.0 + v0 * tt + 0.5 * a * tt * tt + vb * vb / (2.0 * b);
    EXPECT_NEAR(tr.stop_mm, closed, 1e-6 * closed) << v0;
  }
  const GridResult gr = GridWorstCase(m, loc, 1000);
  // the grid's worst state, in closed form
  const double v0 = gr.worst_moving.true_speed_mm_s;
  const double vb = v0 + a * tt;
  const double closed = gr.worst_moving.check_front_mm + v0 * tt + 0.5 * a * tt * tt + vb * vb / (2.0 * b);
  EXPECT_NEAR(gr.moving_margin_mm, 10'000'000.0 - closed, 1e-3);
  EXPECT_GE(gr.moving_margin_mm, 0.0);
  // NLP: never less conservative than the grid beyond 50 mm; close to it (relaxation) on a flat line
  const NlpResult nr = NlpWorstCase(m, loc, {{gr.worst_moving.check_front_mm, static_cast<double>(gr.worst_moving.measured_speed_mm_s)}});
  ASSERT_TRUE(nr.solved) << nr.status;
  EXPECT_LE(nr.margin_mm, gr.moving_margin_mm + 50.0);
  EXPECT_GE(nr.margin_mm, gr.moving_margin_mm - 1000.0);
  EXPECT_NEAR(nr.objective_m, -nr.margin_mm / 1000.0, 0.05);
}

// @verifies REQ-BR-009 REQ-BR-014
TEST(Margins, IpoptDerivativeCheckerReportsNoErrors) {
  const D1UpModel d1("emu3_d1");
  const MarginModel& m = d1.model;
  // a location whose approach crosses gradient and ceiling steps
  const Location loc{LocationClass::kPossession, "test", 3'250'000, 50'000, 3'200'000};
  const auto file = std::filesystem::temp_directory_path() / "railproof_margins_derivative_test.txt";
  std::filesystem::remove(file);
  NlpOptions opt;
  opt.derivative_test = true;
  opt.output_file = file.string();
  opt.smoothing_mm = 200.0;  // the production smoothing width
  for (const double xs : {3'000'000.0, 2'900'000.0}) {
    std::filesystem::remove(file);
    const NlpResult r = NlpWorstCase(m, loc, {{xs, 15000.0}}, opt);
    EXPECT_EQ(r.status, "derivative test");
    const std::string out = ReadAll(file);
    EXPECT_NE(out.find("Starting derivative checker for second derivatives."), std::string::npos);
    EXPECT_NE(out.find("No errors detected by derivative checker."), std::string::npos) << out.substr(0, 4000);
    EXPECT_EQ(out.find("Derivative checker detected"), std::string::npos);
  }
  std::filesystem::remove(file);
}

// @verifies REQ-BR-009 REQ-BR-011 REQ-BR-014
TEST(Margins, NlpNeverLessConservativeThanGridOnSampleLocations) {
  const offline::Line line = D1();
  const TrainType t = Train("emu3_d1");
  const MarginModel m(line.Running("down"), t, ReferenceSpeedErrorModel());
  const LocationSet ls = EnumerateLocations(line.Running("down"), t.length_mm, m.approach_mm());
  int solved = 0;
  for (std::size_t i = 0; i < ls.analysed.size(); i += 97) {
    const Location& loc = ls.analysed[i];
    const GridResult g = GridWorstCase(m, loc, 1000);
    std::vector<NlpSeed> seeds{{g.worst_moving.check_front_mm, static_cast<double>(g.worst_moving.measured_speed_mm_s)}};
    const NlpResult r = NlpWorstCase(m, loc, seeds);
    if (!r.solved) {
      continue;
    }
    ++solved;
    EXPECT_LE(r.margin_mm, g.moving_margin_mm + 50.0) << loc.id;
  }
  EXPECT_GE(solved, 5);
}

// @verifies REQ-BR-009 REQ-BR-011 REQ-BR-014
TEST(Margins, RealTrainTypesHaveNonNegativeMovingMarginsOnALineSection) {
  const offline::Line line = D1();
  const SpeedErrorModel se = ReferenceSpeedErrorModel();
  for (const char* name : {"emu3_d1", "dmu2_d4", "emu10_d2"}) {
    const TrainType t = Train(name);
    const MarginModel m(line.Running("up"), t, se);
    const LocationSet ls = EnumerateLocations(line.Running("up"), t.length_mm, m.approach_mm());
    EXPECT_FALSE(ls.skipped.empty());  // near the line start
    int n = 0;
    for (const auto& loc : ls.analysed) {
      if (loc.stop_limit_mm > 6'000'000 && loc.stop_limit_mm < 9'000'000) {  // section 6-9 km
        const GridResult g = GridWorstCase(m, loc, 1000);
        EXPECT_GE(g.moving_margin_mm, 0.0) << name << " " << loc.id;
        ++n;
      }
    }
    EXPECT_GT(n, 50) << name;
  }
}

// The restart from a standstill where the runtime's emergency pattern is 0 (design note §3:
// "0 if no v passes") is admitted by the supervision (v_s = 0 <= V_e = 0): the restart then
// runs for cycle + reaction + free running before braking. This documents the finding
// reported to the lead: the overrun beyond L is a few metres, inside every class margin
// except those of the platform stop and the level crossing (class margin 0).
// @verifies REQ-BR-009 REQ-BR-014
TEST(Margins, StandstillRestartWhereThePatternIsZeroIsReported) {
  const D1UpModel d1("emu3_d1");
  const MarginModel& m = d1.model;
  const Location& loc = kD1EndOfTrack;
  const GridResult g = GridWorstCase(m, loc, 1000);
  EXPECT_GE(g.moving_margin_mm, 0.0);
  if (m.patterns().EmergencyPatternSpeed(loc.stop_limit_mm, loc.stop_limit_mm, m.position_error_mm(),
                                         m.position_error_mm()) >= 0) {
    // the runtime admits a standing train at L: the restart overruns, within the class margin
    EXPECT_LT(g.standstill_margin_mm, 0.0);
    EXPECT_GT(g.standstill_margin_mm + static_cast<double>(loc.class_margin_mm), 0.0);
    EXPECT_TRUE(g.worst.standstill_start);
  }
}

// @verifies REQ-BR-009 REQ-BR-010
TEST(Margins, WeakenedTrainTypeGivesNegativeMargins) {
  const GridResult g = GridWorstCase(D1UpModel("emu3_d1_weak").model, kD1EndOfTrack, 1000);
  EXPECT_LT(g.moving_margin_mm, -10'000.0);
  EXPECT_LT(g.margin_mm, -10'000.0);
  // the worst case is a high-speed approach braking with the weakest real deceleration
  EXPECT_GT(g.worst_moving.true_speed_mm_s, 15'000.0);
  EXPECT_EQ(g.worst_moving.adversary.beta_mm_s2, 850.0);
}

// @verifies REQ-BR-009 REQ-BR-011
TEST(Margins, LocationsCoverEveryClassOfTheLine) {
  const offline::Line line = D1();
  const auto& rl = line.Running("up");
  const LocationSet ls = EnumerateLocations(rl, 60'000, 0);
  int count[kLocationClassCount] = {};
  for (const auto& l : ls.analysed) {
    ++count[static_cast<int>(l.cls)];
    EXPECT_EQ(l.stop_limit_mm, l.obstruction_mm - l.class_margin_mm);
  }
  for (int c = 0; c < kLocationClassCount; ++c) {
    EXPECT_GT(count[c], 0) << ToString(static_cast<LocationClass>(c));
  }
  EXPECT_TRUE(ls.skipped.empty());
  // possession start: margin_possession_mm before every block boundary
  bool found = false;
  for (const auto& l : ls.analysed) {
    found = found || (l.cls == LocationClass::kPossession && l.obstruction_mm == rl.blocks_mm[10] &&
                      l.class_margin_mm == 50'000);
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace railproof::br::analysis
