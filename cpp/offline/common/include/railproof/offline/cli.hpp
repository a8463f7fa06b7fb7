// Command line of the offline tools: CLI11 (Debian libcli11-dev, header-only) with the
// project's conventions, so that every tool behaves alike:
//   - --help / -h prints the generated help (usage, the tool's description, every option
//     with its text, the footer) on stdout and exits 0;
//   - bad usage prints one line "<tool>: <reason> (see --help)" on stderr and exits 2; an
//     unknown or unexpected argument is reported before a missing required option;
//   - a repeatable option (std::vector target) takes one value per occurrence, kept in
//     order; a number must be the whole text and, if floating-point, finite;
//   - RunTool() is the tool's main(): bad input (InputError: an input file, or an output that
//     cannot be written, output_file.hpp) prints "<tool>: <reason>", any other exception
//     "<tool>: error: <reason>", both exit 2;
//   - the footer of --help states the exit statuses in one form: the tool's own, then the
//     2 of bad usage and bad input that every tool shares.
// The conformance runners use CLI11 the same way (railproof/testing/runner_cli.hpp).
// Why a library: one well-kept parser for every tool and runner instead of three hand-written
// ones, and the help is generated from the same table that parses, so a usage text cannot
// drift from the options; what is the project's own is only these conventions.
// Offline module (may allocate and throw).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <limits>
#include <mutex>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace railproof::offline {

struct CliResult {
  enum class Status { kOk, kHelp, kError };
  Status status = Status::kOk;
  std::string error;  // the reason (kError), without the tool prefix and suffix
};

// Exit status of bad usage and bad input of every tool.
inline constexpr int kUsageExit = 2;
// What the footer of every tool's --help says of it.
inline constexpr const char* kBadUsageStatus =
    "2 bad usage or bad input: an input file, or an output that cannot be written\n"
    "(one line \"<tool>: <file>: <reason>\" on stderr; no result file is changed).";

namespace cli_detail {
// The checks Cli::Add attaches to a number option: the whole text is a finite number, or a
// decimal integer in [lo, hi] (the target type's range; rewritten as plain decimal digits,
// so that a leading zero is never read as octal).
CLI::Validator FloatText();
CLI::Validator IntegerText(long long lo, long long hi);
template <typename T>
CLI::Validator NumberText() {
  if constexpr (std::is_floating_point_v<T>) {
    return FloatText();
  } else {
    constexpr long long kMax = std::numeric_limits<long long>::max();
    return IntegerText(static_cast<long long>(std::numeric_limits<T>::min()),
                       std::cmp_greater(std::numeric_limits<T>::max(), kMax) ? kMax
                                                                             : static_cast<long long>(std::numeric_limits<T>::max()));
  }
}
// One value per occurrence, every occurrence kept in order; `empty`: no default to show.
CLI::Option* Repeatable(CLI::Option* option, bool empty);
}  // namespace cli_detail

class Cli {
 public:
  // `tool` is the program name in the usage line and the prefix of every message;
  // `description` opens --help; `exit_statuses`, the tool's own exit statuses ("0 pass, 1 a
  // check failed (named on stderr)"), begin the footer, which ends with the status 2 shared by
  // every tool (kBadUsageStatus).
  Cli(std::string tool, const std::string& description, const std::string& exit_statuses = "0 done");
  Cli(const Cli&) = delete;
  Cli& operator=(const Cli&) = delete;

  // --name bound to `target`: std::string (one value), bool (a flag), an integer or a
  // floating-point number (one value), or a std::vector of strings or numbers (repeatable).
  // Returns the CLI11 option for ->required(), ->check(...), ->delimiter(','), ...
  template <typename T>
  CLI::Option* Add(const std::string& name, T& target, const std::string& help);

  CLI::App& app() { return app_; }

  // Applies the arguments argv[1..argc) (for tests: never exits).
  [[nodiscard]] CliResult Parse(int argc, const char* const* argv);
  // Parse; help: print it, exit 0; error: Fail.
  void ParseOrExit(int argc, const char* const* argv);
  [[nodiscard]] std::string Help() const;
  // The line printed for bad usage: "<tool>: <reason> (see --help)".
  [[nodiscard]] std::string Message(const std::string& reason) const;
  // Prints Message(reason) on stderr and exits with kUsageExit.
  [[noreturn]] void Fail(const std::string& reason) const;

 private:
  std::string tool_;
  CLI::App app_;
};

template <typename T>
CLI::Option* Cli::Add(const std::string& name, T& target, const std::string& help) {
  if constexpr (std::is_same_v<T, bool>) {
    return app_.add_flag(name, target, help);
  } else if constexpr (std::is_arithmetic_v<T>) {
    return app_.add_option(name, target, help)->transform(cli_detail::NumberText<T>());
  } else if constexpr (std::is_same_v<T, std::vector<double>>) {
    return cli_detail::Repeatable(app_.add_option(name, target, help)->transform(cli_detail::NumberText<double>()),
                                  target.empty());
  } else if constexpr (std::is_same_v<T, std::vector<std::string>>) {
    return cli_detail::Repeatable(app_.add_option(name, target, help), target.empty());
  } else {
    static_assert(std::is_same_v<T, std::string>, "Cli::Add: string, bool, number or a vector of them");
    return app_.add_option(name, target, help);
  }
}

// A number in [lo, hi] (`lo_open`: lo < value); message "not a number in [lo, hi]: 'text'".
CLI::Validator InRange(double lo, double hi, bool lo_open = false);
// A number above `lo` (lo < value); message "not a number above lo: 'text'".
CLI::Validator Above(double lo);

// The progress lines of a tool on stderr, "<tool>: <text>", none if `quiet` (--quiet); one
// line at a time when called from several threads.
class Progress {
 public:
  Progress(std::string tool, bool quiet) : tool_(std::move(tool)), quiet_(quiet) {}
  void operator()(const std::string& text) const;

 private:
  std::string tool_;
  bool quiet_;
  mutable std::mutex mu_;
};

// The main() of a tool: runs `body` and returns its exit status; an InputError prints
// "<tool>: <what>", any other std::exception "<tool>: error: <what>" on stderr, exit 2.
int RunTool(const std::string& tool, const std::function<int()>& body);

}  // namespace railproof::offline
