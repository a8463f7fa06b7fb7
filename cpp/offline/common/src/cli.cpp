// Command line of the offline tools (see cli.hpp).
#include "railproof/offline/cli.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstdlib>
#include <exception>
#include <limits>
#include <optional>
#include <utility>

#include "railproof/offline/line.hpp"

namespace railproof::offline {
namespace {

// The number of the whole text (std::strtod), if it is one and finite.
std::optional<double> FiniteNumber(const std::string& text) {
  if (text.empty()) {
    return std::nullopt;
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(v)) {
    return std::nullopt;
  }
  return v;
}

std::string Bound(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

namespace cli_detail {

CLI::Validator FloatText() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        return FiniteNumber(text) ? "" : "not a finite number: '" + text + "'";
      },
      "");
}

CLI::Validator IntegerText(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        const std::size_t digits = text.starts_with('+') || text.starts_with('-') ? 1 : 0;
        if (text.size() == digits ||
            !std::all_of(text.begin() + static_cast<std::ptrdiff_t>(digits), text.end(),
                         [](char c) { return c >= '0' && c <= '9'; })) {
          return "not an integer: '" + text + "'";
        }
        errno = 0;
        const long long v = std::strtoll(text.c_str(), nullptr, 10);
        if (errno == ERANGE || v < lo || v > hi) {
          return "not an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]: '" + text + "'";
        }
        text = std::to_string(v);
        return "";
      },
      "");
}

CLI::Option* Repeatable(CLI::Option* option, bool empty) {
  if (empty) {
    option->default_str("");
  }
  return option->expected(1)->allow_extra_args(false)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

}  // namespace cli_detail

CLI::Validator InRange(double lo, double hi, bool lo_open) {
  const std::string range = (lo_open ? "(" : "[") + Bound(lo) + ", " + Bound(hi) + "]";
  return CLI::Validator(
      [lo, hi, lo_open, range](std::string& text) -> std::string {
        const std::optional<double> v = FiniteNumber(text);
        if (!v || *v < lo || (lo_open && *v == lo) || *v > hi) {
          return "not a number in " + range + ": '" + text + "'";
        }
        return "";
      },
      "");
}

CLI::Validator Above(double lo) { return InRange(lo, std::numeric_limits<double>::max(), true); }

Cli::Cli(std::string tool, const std::string& description, const std::string& exit_statuses)
    : tool_(std::move(tool)), app_(description, tool_) {
  // unknown arguments are collected and reported by Parse (before a missing required option)
  app_.allow_extras();
  app_.option_defaults()->always_capture_default();  // --help shows every option's default
  app_.footer("Exit status: " + exit_statuses + ";\n" + kBadUsageStatus);
  app_.get_formatter()->column_width(34);
}

CliResult Cli::Parse(int argc, const char* const* argv) {
  const auto unexpected = [this]() -> std::optional<std::string> {
    const std::vector<std::string> rest = app_.remaining();
    if (rest.empty()) {
      return std::nullopt;
    }
    return (rest.front().starts_with("-") ? "unknown option '" : "unexpected argument '") + rest.front() + "'";
  };
  try {
    app_.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    return {CliResult::Status::kHelp, {}};
  } catch (const CLI::ParseError& e) {
    return {CliResult::Status::kError, unexpected().value_or(e.what())};
  }
  if (auto error = unexpected()) {
    return {CliResult::Status::kError, std::move(*error)};
  }
  return {};
}

void Cli::ParseOrExit(int argc, const char* const* argv) {
  const CliResult r = Parse(argc, argv);
  if (r.status == CliResult::Status::kHelp) {
    std::fputs(Help().c_str(), stdout);
    std::exit(0);
  }
  if (r.status == CliResult::Status::kError) {
    Fail(r.error);
  }
}

std::string Cli::Help() const { return app_.help(); }

std::string Cli::Message(const std::string& reason) const { return tool_ + ": " + reason + " (see --help)"; }

void Cli::Fail(const std::string& reason) const {
  std::fprintf(stderr, "%s\n", Message(reason).c_str());
  std::exit(kUsageExit);
}

void Progress::operator()(const std::string& text) const {
  if (!quiet_) {
    const std::lock_guard<std::mutex> lock(mu_);
    std::fprintf(stderr, "%s: %s\n", tool_.c_str(), text.c_str());
  }
}

int RunTool(const std::string& tool, const std::function<int()>& body) {
  try {
    return body();
  } catch (const InputError& e) {
    std::fprintf(stderr, "%s: %s\n", tool.c_str(), e.what());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", tool.c_str(), e.what());
  }
  return kUsageExit;
}

}  // namespace railproof::offline
