// Unit tests of the offline tools' command-line parser (railproof/offline/cli.hpp): values,
// lists, flags, bounded numbers, custom handlers, required options, help, the error
// wording of both styles and the first-error-wins order. Only the non-exiting Parse and
// Message are exercised.
#include <gtest/gtest.h>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "railproof/offline/cli.hpp"

namespace railproof::offline {
namespace {

// argv of `args` with a program name in front.
CliResult ParseWith(const CliParser& cli, std::vector<std::string> args) {
  args.insert(args.begin(), "tool");
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

void ExpectOk(const CliResult& r) {
  EXPECT_EQ(r.status, CliResult::Status::kOk) << r.error;
}

struct Targets {
  std::string name;
  std::string out;
  std::vector<std::string> items;
  bool quiet = false;
  int threads = 1;
  double budget = 0.3;
  std::vector<double> rates;
};

// A parser in the style of the tools that say "(see --help)".
CliParser NamedParser(Targets& t, CliStyle::Unknown unknown = CliStyle::Unknown::kQuoted) {
  CliParser cli({.tool = "demo", .unknown = unknown}, nullptr);
  cli.Value("--name", t.name)
      .Value("--out", t.out)
      .List("--item", t.items)
      .Flag("--quiet", t.quiet)
      .Integer("--threads", t.threads, {.lo = 1, .hi = 64, .message = "{opt}: expected 1..64, got '{value}'"})
      .Number("--budget", t.budget, {.lo = 0.0, .hi = 10.0, .message = "{opt}: not a number in [0, 10]: '{value}'"})
      .Number("--rate", t.rates,
              {.lo = 0.0,
               .hi = 1.0,
               .reject_range_error = true,
               .message = "{opt}: not a finite number: '{value}'",
               .range_message = "{opt} must be in [0, 1], got {value}"})
      .Require("--name");
  return cli;
}

TEST(CliParser, ValuesListsAndFlagsReachTheirTargets) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "a", "--item", "x", "--quiet", "--item", "y", "--name", "b", "--out", ""}));
  EXPECT_EQ(t.name, "b");  // the last one counts
  EXPECT_EQ(t.out, "");
  EXPECT_EQ(t.items, (std::vector<std::string>{"x", "y"}));
  EXPECT_TRUE(t.quiet);
}

TEST(CliParser, UntouchedTargetsKeepTheirDefaults) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "a"}));
  EXPECT_EQ(t.threads, 1);
  EXPECT_DOUBLE_EQ(t.budget, 0.3);
  EXPECT_FALSE(t.quiet);
  EXPECT_TRUE(t.items.empty());
}

TEST(CliParser, AValueMayLookLikeAnOption) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "--help", "--out", "--quiet"}));
  EXPECT_EQ(t.name, "--help");
  EXPECT_EQ(t.out, "--quiet");
  EXPECT_FALSE(t.quiet);
}

TEST(CliParser, MissingValueIsNamed) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectError(ParseWith(cli, {"--name", "a", "--out"}), "--out needs a value");
  ExpectError(ParseWith(cli, {"--threads"}), "--threads needs a value");
}

TEST(CliParser, UnknownOptionInBothWordings) {
  Targets t;
  ExpectError(ParseWith(NamedParser(t), {"--name", "a", "--bogus"}), "unknown option '--bogus'");
  ExpectError(ParseWith(NamedParser(t, CliStyle::Unknown::kColon), {"x"}), "unknown option: x");
  ExpectError(ParseWith(NamedParser(t), {""}), "unknown option ''");
}

TEST(CliParser, RequiredOptionsInOrderAfterTheArguments) {
  Targets t;
  CliParser cli({.tool = "demo"}, nullptr);
  cli.Value("--name", t.name).List("--item", t.items).Require("--item").Require("--name");
  ExpectError(ParseWith(cli, {}), "--item is required");
  ExpectError(ParseWith(cli, {"--item", "x"}), "--name is required");
  ExpectError(ParseWith(cli, {"--item", "x", "--name", ""}), "--name is required");  // empty counts as missing
  ExpectOk(ParseWith(cli, {"--item", "x", "--name", "n"}));
  // An argument error comes before a missing required option.
  ExpectError(ParseWith(cli, {"--bogus"}), "unknown option: --bogus");
}

TEST(CliParser, HelpWinsUnlessAnEarlierArgumentFailed) {
  Targets t;
  const CliParser cli = NamedParser(t);
  EXPECT_EQ(ParseWith(cli, {"--help"}).status, CliResult::Status::kHelp);
  EXPECT_EQ(ParseWith(cli, {"-h", "--bogus"}).status, CliResult::Status::kHelp);
  EXPECT_EQ(ParseWith(cli, {"--threads", "3", "-h"}).status, CliResult::Status::kHelp);  // no required check
  ExpectError(ParseWith(cli, {"--bogus", "--help"}), "unknown option '--bogus'");
  ExpectError(ParseWith(cli, {"--threads", "0", "--help"}), "--threads: expected 1..64, got '0'");
}

TEST(CliInteger, InRangeAndOutOfRange) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "a", "--threads", "64"}));
  EXPECT_EQ(t.threads, 64);
  ExpectOk(ParseWith(cli, {"--name", "a", "--threads", "1"}));
  EXPECT_EQ(t.threads, 1);
  ExpectOk(ParseWith(cli, {"--name", "a", "--threads", "+7"}));  // strtoll syntax
  EXPECT_EQ(t.threads, 7);
  for (const char* bad : {"0", "65", "-1", "abc", "3x", "", "1.0", "99999999999999999999999"}) {
    ExpectError(ParseWith(cli, {"--threads", bad}), std::string("--threads: expected 1..64, got '") + bad + "'");
  }
}

TEST(CliInteger, DigitsOnlyTypeRangeAndRangeMessage) {
  const IntegerRule rule{.lo = 1,
                         .digits_only = true,
                         .message = "{opt}: not a non-negative integer: '{value}'",
                         .range_message = "{opt} must be >= 1"};
  unsigned blocks = 9;
  CliParser cli({.tool = "demo", .values = CliStyle::Values::kPaired, .see_help = false}, nullptr);
  cli.Integer("--blocks", blocks, rule);
  ExpectOk(ParseWith(cli, {"--blocks", "007"}));
  EXPECT_EQ(blocks, 7U);
  ExpectOk(ParseWith(cli, {"--blocks", "4294967295"}));
  EXPECT_EQ(blocks, 4294967295U);
  ExpectError(ParseWith(cli, {"--blocks", "0"}), "--blocks must be >= 1");
  for (const char* bad : {"4294967296", "-1", "+1", " 1", "1.5", "", "0x10"}) {
    ExpectError(ParseWith(cli, {"--blocks", bad}), std::string("--blocks: not a non-negative integer: '") + bad + "'");
  }
}

TEST(CliInteger, SignedTargetTypeRange) {
  std::int8_t small = 0;
  CliParser cli({.tool = "demo"}, nullptr);
  cli.Integer("--small", small, {.message = "bad {value}"});
  ExpectOk(ParseWith(cli, {"--small", "-128"}));
  EXPECT_EQ(small, -128);
  ExpectError(ParseWith(cli, {"--small", "128"}), "bad 128");
}

TEST(CliNumber, InRangeAndOutOfRange) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "a", "--budget", "10"}));
  EXPECT_DOUBLE_EQ(t.budget, 10.0);
  ExpectOk(ParseWith(cli, {"--name", "a", "--budget", " 2.5e0"}));  // strtod syntax
  EXPECT_DOUBLE_EQ(t.budget, 2.5);
  ExpectOk(ParseWith(cli, {"--name", "a", "--budget", "1e-400"}));  // underflow accepted unless rejected
  EXPECT_DOUBLE_EQ(t.budget, 0.0);
  for (const char* bad : {"-0.1", "10.5", "abc", "", "nan", "inf", "1e400", "5x"}) {
    ExpectError(ParseWith(cli, {"--budget", bad}), std::string("--budget: not a number in [0, 10]: '") + bad + "'");
  }
}

TEST(CliNumber, RepeatableWithSeparateRangeMessage) {
  Targets t;
  const CliParser cli = NamedParser(t);
  ExpectOk(ParseWith(cli, {"--name", "a", "--rate", "0", "--rate", "1", "--rate", "0.5"}));
  EXPECT_EQ(t.rates, (std::vector<double>{0.0, 1.0, 0.5}));
  ExpectError(ParseWith(cli, {"--rate", "1.5"}), "--rate must be in [0, 1], got 1.5");
  ExpectError(ParseWith(cli, {"--rate", "1e-400"}), "--rate: not a finite number: '1e-400'");
  ExpectError(ParseWith(cli, {"--rate", "nan"}), "--rate: not a finite number: 'nan'");
}

TEST(CliNumber, OpenLowerBoundAndSetter) {
  std::optional<double> cap;
  CliParser cli({.tool = "demo"}, nullptr);
  cli.Number("--cap", [&](double v) { cap = v; }, {.lo = 0.0, .hi = 400.0, .lo_open = true, .message = "{opt} '{value}'"});
  ExpectOk(ParseWith(cli, {"--cap", "400"}));
  EXPECT_EQ(cap, 400.0);
  ExpectError(ParseWith(cli, {"--cap", "0"}), "--cap '0'");
  ExpectError(ParseWith(cli, {"--cap", "400.1"}), "--cap '400.1'");
}

TEST(CliNumber, FreeFunctionAndDefaultMessage) {
  double v = -1.0;
  EXPECT_EQ(ParseCliNumber("--x", "2", {.lo = 1.0}, v), std::nullopt);
  EXPECT_DOUBLE_EQ(v, 2.0);
  EXPECT_EQ(ParseCliNumber("--x", "0", {.lo = 1.0}, v), "--x: invalid value '0'");
  EXPECT_DOUBLE_EQ(v, 2.0);  // unchanged on error
  // The placeholders are filled once: a value containing "{opt}" stays as given.
  EXPECT_EQ(ParseCliNumber("--x", "{opt}", {.message = "{opt}={value}"}, v), "--x={opt}");
}

TEST(CliParser, CustomHandlerErrorsAndValues) {
  std::vector<std::string> seen;
  CliParser cli({.tool = "demo"}, nullptr);
  cli.Custom("--mode", [&](const std::string& v) -> std::optional<std::string> {
    if (v != "a" && v != "b") {
      return "--mode: expected a or b, got '" + v + "'";
    }
    seen.push_back(v);
    return std::nullopt;
  });
  ExpectOk(ParseWith(cli, {"--mode", "a", "--mode", "b"}));
  EXPECT_EQ(seen, (std::vector<std::string>{"a", "b"}));
  ExpectError(ParseWith(cli, {"--mode", "c", "--mode", "a"}), "--mode: expected a or b, got 'c'");
  EXPECT_EQ(seen.size(), 2U);  // the parse stopped at the first error
  ExpectError(ParseWith(cli, {"--mode"}), "--mode needs a value");
}

TEST(CliParser, PairedStyleChecksTheValueBeforeTheName) {
  std::string json;
  CliParser cli({.tool = "demo", .values = CliStyle::Values::kPaired, .see_help = false}, nullptr);
  cli.Value("--json", json);
  ExpectError(ParseWith(cli, {"--json"}), "unknown option or missing value: --json");
  ExpectError(ParseWith(cli, {"--bogus"}), "unknown option or missing value: --bogus");
  ExpectError(ParseWith(cli, {"--bogus", "--help"}), "unknown option: --bogus");
  EXPECT_EQ(ParseWith(cli, {"--help"}).status, CliResult::Status::kHelp);
  ExpectOk(ParseWith(cli, {"--json", "--help"}));
  EXPECT_EQ(json, "--help");
}

TEST(CliParser, MessageFormats) {
  const CliParser named({.tool = "margins"}, nullptr);
  EXPECT_EQ(named.Message("--line is required"), "margins: --line is required (see --help)");
  const CliParser paired({.tool = "residual_error", .values = CliStyle::Values::kPaired, .see_help = false}, nullptr);
  EXPECT_EQ(paired.Message("unknown option: --x"), "residual_error: unknown option: --x");
}

TEST(CliParser, RegistrationMistakesThrow) {
  std::string s;
  bool b = false;
  CliParser cli({.tool = "demo"}, nullptr);
  cli.Value("--a", s).Flag("--f", b);
  EXPECT_THROW(cli.Value("--a", s), std::logic_error);
  EXPECT_THROW(cli.Flag("--help", b), std::logic_error);
  EXPECT_THROW(cli.Require("--f"), std::logic_error);
  EXPECT_THROW(cli.Require("--none"), std::logic_error);
  CliParser paired({.tool = "demo", .values = CliStyle::Values::kPaired}, nullptr);
  EXPECT_THROW(paired.Flag("--f", b), std::logic_error);
}

}  // namespace
}  // namespace railproof::offline
