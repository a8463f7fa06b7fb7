// Command-line parsing of the offline tools (see cli.hpp).
#include "railproof/offline/cli.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace railproof::offline {
namespace {

// `pattern` with every "{opt}" and "{value}" replaced (one pass: the replacements are not
// scanned again).
std::string Fill(const std::string& pattern, std::string_view opt, const std::string& value) {
  constexpr std::string_view kOpt = "{opt}";
  constexpr std::string_view kValue = "{value}";
  std::string out;
  for (std::size_t i = 0; i < pattern.size();) {
    const std::string_view rest = std::string_view(pattern).substr(i);
    if (rest.starts_with(kOpt)) {
      out += opt;
      i += kOpt.size();
    } else if (rest.starts_with(kValue)) {
      out += value;
      i += kValue.size();
    } else {
      out += pattern[i];
      ++i;
    }
  }
  return out;
}

// The rule's message, or a plain one if the rule gives none.
const std::string& Pattern(const std::string& message) {
  static const std::string kDefault = "{opt}: invalid value '{value}'";
  return message.empty() ? kDefault : message;
}

}  // namespace

std::optional<std::string> ParseCliNumber(std::string_view opt, const std::string& text, const NumberRule& rule,
                                          double& out) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const bool range_error = errno == ERANGE;
  if (end == text.c_str() || *end != '\0' || (rule.reject_range_error && range_error) || !std::isfinite(v)) {
    return Fill(Pattern(rule.message), opt, text);
  }
  if (v < rule.lo || (rule.lo_open && v == rule.lo) || v > rule.hi) {
    return Fill(Pattern(rule.range_message.empty() ? rule.message : rule.range_message), opt, text);
  }
  out = v;
  return std::nullopt;
}

std::optional<std::string> ParseCliInteger(std::string_view opt, const std::string& text, const IntegerRule& rule,
                                           long long type_lo, long long type_hi, long long& out) {
  if (rule.digits_only &&
      (text.empty() || !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))) {
    return Fill(Pattern(rule.message), opt, text);
  }
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || errno == ERANGE || v < type_lo || v > type_hi) {
    return Fill(Pattern(rule.message), opt, text);
  }
  if (v < rule.lo || v > rule.hi) {
    return Fill(Pattern(rule.range_message.empty() ? rule.message : rule.range_message), opt, text);
  }
  out = v;
  return std::nullopt;
}

CliParser::CliParser(CliStyle style, std::function<void()> print_help)
    : style_(std::move(style)), print_help_(std::move(print_help)) {}

CliParser& CliParser::Add(Option option) {
  if (option.name == "--help" || option.name == "-h" || Find(option.name) != nullptr) {
    throw std::logic_error(style_.tool + ": option " + option.name + " registered twice");
  }
  options_.push_back(std::move(option));
  return *this;
}

CliParser& CliParser::Value(std::string name, std::string& target) {
  return Add({std::move(name), true,
              [&target](const std::string& v) -> std::optional<std::string> {
                target = v;
                return std::nullopt;
              },
              [&target] { return target.empty(); }});
}

CliParser& CliParser::List(std::string name, std::vector<std::string>& target) {
  return Add({std::move(name), true,
              [&target](const std::string& v) -> std::optional<std::string> {
                target.push_back(v);
                return std::nullopt;
              },
              [&target] { return target.empty(); }});
}

CliParser& CliParser::Flag(std::string name, bool& target) {
  if (style_.values == CliStyle::Values::kPaired) {
    throw std::logic_error(style_.tool + ": flag " + name + " in a tool whose options all take a value");
  }
  return Add({std::move(name), false,
              [&target](const std::string&) -> std::optional<std::string> {
                target = true;
                return std::nullopt;
              },
              nullptr});
}

CliParser& CliParser::Number(std::string name, double& target, NumberRule rule) {
  return Number(std::move(name), [&target](double v) { target = v; }, std::move(rule));
}

CliParser& CliParser::Number(std::string name, std::vector<double>& target, NumberRule rule) {
  return Number(std::move(name), [&target](double v) { target.push_back(v); }, std::move(rule));
}

CliParser& CliParser::Number(std::string name, std::function<void(double)> set, NumberRule rule) {
  std::string opt = name;
  return Add({std::move(name), true,
              [opt = std::move(opt), set = std::move(set), rule = std::move(rule)](
                  const std::string& text) -> std::optional<std::string> {
                double v = 0.0;
                if (auto error = ParseCliNumber(opt, text, rule, v)) {
                  return error;
                }
                set(v);
                return std::nullopt;
              },
              nullptr});
}

CliParser& CliParser::AddInteger(std::string name, std::function<void(long long)> set, IntegerRule rule,
                                 long long type_lo, long long type_hi) {
  std::string opt = name;
  return Add({std::move(name), true,
              [opt = std::move(opt), set = std::move(set), rule = std::move(rule), type_lo, type_hi](
                  const std::string& text) -> std::optional<std::string> {
                long long v = 0;
                if (auto error = ParseCliInteger(opt, text, rule, type_lo, type_hi, v)) {
                  return error;
                }
                set(v);
                return std::nullopt;
              },
              nullptr});
}

CliParser& CliParser::Custom(std::string name, Handler handler) {
  return Add({std::move(name), true, std::move(handler), nullptr});
}

CliParser& CliParser::Require(const std::string& name) {
  const Option* o = Find(name);
  if (o == nullptr || !o->empty) {
    throw std::logic_error(style_.tool + ": Require(" + name + "): no Value or List option of that name");
  }
  required_.push_back(static_cast<std::size_t>(o - options_.data()));
  return *this;
}

const CliParser::Option* CliParser::Find(std::string_view name) const {
  const auto it = std::find_if(options_.begin(), options_.end(), [&](const Option& o) { return o.name == name; });
  return it == options_.end() ? nullptr : &*it;
}

CliResult CliParser::Parse(int argc, const char* const* argv) const {
  const bool paired = style_.values == CliStyle::Values::kPaired;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      return {CliResult::Status::kHelp, {}};
    }
    const bool has_next = i + 1 < argc;
    if (paired && !has_next) {
      return {CliResult::Status::kError, "unknown option or missing value: " + arg};
    }
    const Option* o = Find(arg);
    if (o == nullptr) {
      return {CliResult::Status::kError, style_.unknown == CliStyle::Unknown::kQuoted
                                             ? "unknown option '" + arg + "'"
                                             : "unknown option: " + arg};
    }
    std::string value;
    if (o->takes_value) {
      if (!has_next) {
        return {CliResult::Status::kError, arg + " needs a value"};
      }
      value = argv[++i];
    }
    if (auto error = o->apply(value)) {
      return {CliResult::Status::kError, std::move(*error)};
    }
  }
  for (const std::size_t r : required_) {
    if (options_[r].empty()) {
      return {CliResult::Status::kError, options_[r].name + " is required"};
    }
  }
  return {};
}

void CliParser::ParseOrExit(int argc, const char* const* argv) const {
  const CliResult r = Parse(argc, argv);
  if (r.status == CliResult::Status::kHelp) {
    if (print_help_) {
      print_help_();
    }
    std::exit(0);
  }
  if (r.status == CliResult::Status::kError) {
    Fail(r.error);
  }
}

std::string CliParser::Message(const std::string& reason) const {
  return style_.tool + ": " + reason + (style_.see_help ? " (see --help)" : "");
}

void CliParser::Fail(const std::string& reason) const {
  std::fprintf(stderr, "%s\n", Message(reason).c_str());
  std::exit(style_.error_exit);
}

}  // namespace railproof::offline
