// Unit tests of the offline tools' command line (railproof/offline/cli.hpp, CLI11 with the
// project's conventions): values, repeatable options, flags, numbers, ranges, required
// options, help, the order of the errors and the message format. Only the non-exiting Parse
// and Message are exercised; RunTool's exit statuses are checked with throwing bodies.
#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "railproof/offline/cli.hpp"
#include "railproof/offline/line.hpp"

namespace railproof::offline {
namespace {

// argv of `args` with a program name in front.
CliResult ParseWith(Cli& cli, std::vector<std::string> args) {
  args.insert(args.begin(), "demo");
  std::vector<const char*> argv;
  for (const auto& a : args) {
    argv.push_back(a.c_str());
  }
  return cli.Parse(static_cast<int>(argv.size()), argv.data());
}

void ExpectError(const CliResult& r, const std::string& error) {
  EXPECT_EQ(r.status, CliResult::Status::kError);
  EXPECT_EQ(r.error, error);
}

void ExpectOk(const CliResult& r) { EXPECT_EQ(r.status, CliResult::Status::kOk) << r.error; }

struct Targets {
  std::string name;
  std::string out;
  std::vector<std::string> items;
  bool quiet = false;
  int threads = 1;
  unsigned blocks = 9;
  double budget = 0.3;
  std::vector<double> rates;
  std::vector<double> leads;
};

// A parser with one option of every kind, each with a target in `t`.
struct Demo {
  Targets t;
  Cli cli{"demo", "A demonstration.", "0 done, 1 failed"};
  Demo() {
    cli.Add("--name", t.name, "a name")->required();
    cli.Add("--out", t.out, "an output");
    cli.Add("--item", t.items, "an item; repeatable");
    cli.Add("--quiet", t.quiet, "no progress");
    cli.Add("--threads", t.threads, "threads")->check(InRange(1, 64));
    cli.Add("--blocks", t.blocks, "blocks")->check(InRange(1, 1e12));
    cli.Add("--budget", t.budget, "seconds")->check(InRange(0.0, 10.0));
    cli.Add("--rate", t.rates, "a rate; repeatable")->check(InRange(0.0, 1.0));
    cli.Add("--lead", t.leads, "leads, comma-separated")->delimiter(',')->check(InRange(0.0, 600.0));
  }
};

TEST(Cli, ValuesListsAndFlagsReachTheirTargets) {
  Demo d;
  ExpectOk(ParseWith(d.cli, {"--name", "a", "--item", "x", "--quiet", "--item", "y", "--out=o", "--threads", "7"}));
  EXPECT_EQ(d.t.name, "a");
  EXPECT_EQ(d.t.out, "o");
  EXPECT_EQ(d.t.items, (std::vector<std::string>{"x", "y"}));
  EXPECT_TRUE(d.t.quiet);
  EXPECT_EQ(d.t.threads, 7);
}

TEST(Cli, UntouchedTargetsKeepTheirDefaults) {
  Demo d;
  ExpectOk(ParseWith(d.cli, {"--name", "a"}));
  EXPECT_EQ(d.t.threads, 1);
  EXPECT_EQ(d.t.blocks, 9U);
  EXPECT_DOUBLE_EQ(d.t.budget, 0.3);
  EXPECT_FALSE(d.t.quiet);
  EXPECT_TRUE(d.t.items.empty());
}

TEST(Cli, ARepeatableOptionTakesOneValuePerOccurrence) {
  Demo d;
  ExpectError(ParseWith(d.cli, {"--name", "a", "--item", "x", "y"}), "unexpected argument 'y'");
  Demo e;
  ExpectOk(ParseWith(e.cli, {"--name", "a", "--rate", "0", "--rate", "1", "--rate", "0.5"}));
  EXPECT_EQ(e.t.rates, (std::vector<double>{0.0, 1.0, 0.5}));
}

TEST(Cli, ACommaSeparatedListIsCheckedElementByElement) {
  Demo d;
  ExpectOk(ParseWith(d.cli, {"--name", "a", "--lead", "6,8,10.5"}));
  EXPECT_EQ(d.t.leads, (std::vector<double>{6.0, 8.0, 10.5}));
  Demo e;
  ExpectError(ParseWith(e.cli, {"--name", "a", "--lead", "6,x,10"}), "--lead: not a finite number: 'x'");
  Demo f;
  ExpectError(ParseWith(f.cli, {"--name", "a", "--lead", "6,601"}), "--lead: not a number in [0, 600]: '601'");
}

TEST(Cli, UnknownArgumentsComeBeforeAMissingRequiredOption) {
  Demo d;
  ExpectError(ParseWith(d.cli, {"--bogus"}), "unknown option '--bogus'");
  Demo e;
  ExpectError(ParseWith(e.cli, {"--name", "a", "stray"}), "unexpected argument 'stray'");
  Demo f;
  ExpectError(ParseWith(f.cli, {}), "--name is required");
}

TEST(Cli, MissingValueIsNamed) {
  Demo d;
  const CliResult r = ParseWith(d.cli, {"--name", "a", "--out"});
  EXPECT_EQ(r.status, CliResult::Status::kError);
  EXPECT_NE(r.error.find("--out"), std::string::npos) << r.error;
}

TEST(Cli, HelpIsGeneratedFromTheOptions) {
  Demo d;
  EXPECT_EQ(ParseWith(d.cli, {"--help"}).status, CliResult::Status::kHelp);
  Demo e;
  EXPECT_EQ(ParseWith(e.cli, {"-h"}).status, CliResult::Status::kHelp);  // no required check
  const std::string help = d.cli.Help();
  for (const char* part : {"A demonstration.", "Usage: demo", "--name", "a name", "--lead",
                           "Exit status: 0 done, 1 failed;\n2 bad usage or bad input"}) {
    EXPECT_NE(help.find(part), std::string::npos) << part << " not in\n" << help;
  }
}

TEST(Cli, IntegersAreTheWholeTextInTheTargetTypeAndRange) {
  for (const char* good : {"1", "64", "+7"}) {
    Demo d;
    ExpectOk(ParseWith(d.cli, {"--name", "a", "--threads", good}));
  }
  for (const char* bad : {"abc", "3x", "1.5", "0x10", " 1", "", "-"}) {
    Demo d;
    ExpectError(ParseWith(d.cli, {"--name", "a", "--threads", bad}), std::string("--threads: not an integer: '") + bad + "'");
  }
  for (const char* bad : {"0", "65", "-1"}) {
    Demo d;
    ExpectError(ParseWith(d.cli, {"--name", "a", "--threads", bad}), std::string("--threads: not a number in [1, 64]: '") + bad + "'");
  }
  Demo big;
  ExpectError(ParseWith(big.cli, {"--name", "a", "--threads", "99999999999999999999999"}),
              "--threads: not an integer in [-2147483648, 2147483647]: '99999999999999999999999'");
  Demo d;
  ExpectOk(ParseWith(d.cli, {"--name", "a", "--blocks", "4294967295"}));
  EXPECT_EQ(d.t.blocks, 4294967295U);
  Demo e;  // in range of the check, not of the target type
  ExpectError(ParseWith(e.cli, {"--name", "a", "--blocks", "4294967296"}),
              "--blocks: not an integer in [0, 4294967295]: '4294967296'");
  Demo f;  // decimal, never octal
  ExpectOk(ParseWith(f.cli, {"--name", "a", "--threads", "010"}));
  EXPECT_EQ(f.t.threads, 10);
}

TEST(Cli, FloatingPointNumbersAreFiniteAndInRange) {
  Demo d;
  ExpectOk(ParseWith(d.cli, {"--name", "a", "--budget", "2.5e0"}));
  EXPECT_DOUBLE_EQ(d.t.budget, 2.5);
  for (const char* bad : {"nan", "inf", "1e400", "5x", "abc", ""}) {
    Demo e;
    ExpectError(ParseWith(e.cli, {"--name", "a", "--budget", bad}), std::string("--budget: not a finite number: '") + bad + "'");
  }
  for (const char* bad : {"-0.1", "10.5"}) {
    Demo e;
    ExpectError(ParseWith(e.cli, {"--name", "a", "--budget", bad}), std::string("--budget: not a number in [0, 10]: '") + bad + "'");
  }
}

TEST(Cli, OpenLowerBound) {
  double cap = 1.0;
  Cli cli("demo", "");
  cli.Add("--cap", cap, "")->check(InRange(0.0, 400.0, true));
  ExpectOk(ParseWith(cli, {"--cap", "400"}));
  EXPECT_DOUBLE_EQ(cap, 400.0);
  ExpectError(ParseWith(cli, {"--cap", "0"}), "--cap: not a number in (0, 400]: '0'");
  double rate = 1.0;
  Cli above("demo", "");
  above.Add("--rate", rate, "")->check(Above(0.0));
  ExpectOk(ParseWith(above, {"--rate", "1e300"}));
  EXPECT_EQ(ParseWith(above, {"--rate", "0"}).status, CliResult::Status::kError);
}

TEST(Cli, MessageFormat) {
  const Cli cli("margins", "");
  EXPECT_EQ(cli.Message("--line is required"), "margins: --line is required (see --help)");
}

TEST(RunTool, ReturnsTheBodysStatusOrTwoOnAnException) {
  EXPECT_EQ(RunTool("demo", [] { return 1; }), 1);
  testing::internal::CaptureStderr();
  EXPECT_EQ(RunTool("demo", []() -> int { throw InputError("in.json: entry: bad"); }), kUsageExit);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "demo: in.json: entry: bad\n");
  testing::internal::CaptureStderr();
  EXPECT_EQ(RunTool("demo", []() -> int { throw std::runtime_error("boom"); }), kUsageExit);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "demo: error: boom\n");
}

}  // namespace
}  // namespace railproof::offline
