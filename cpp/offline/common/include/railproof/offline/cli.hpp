// Command-line parsing of the offline tools: a table of options (string value, repeated
// string, flag, bounded integer, bounded number, or a custom handler) bound to the tool's
// variables, parsed in order; the first error ends the parse. Parse() only reports (for
// tests); ParseOrExit() prints the tool's help on --help / -h and exits 0, or prints the
// error as "<tool>: <reason>[ (see --help)]" on stderr and exits with the tool's error code.
// Offline module. Registration mistakes (a name twice, --help / -h, a flag in a kPaired
// tool, Require of an option without a string target) throw std::logic_error.
#pragma once

#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace railproof::offline {

// How a tool words and handles its command-line errors.
struct CliStyle {
  enum class Unknown {
    kColon,   // "unknown option: X"
    kQuoted,  // "unknown option 'X'"
  };
  enum class Values {
    // The option's entry decides whether a value follows; a value option that is last:
    // "X needs a value".
    kNamed,
    // Every argument but --help / -h is an option followed by its value, checked before the
    // name is looked up: the last argument gives "unknown option or missing value: X".
    // No flags in this style.
    kPaired,
  };
  std::string tool{};              // prefix of every message: "<tool>: "
  Unknown unknown = Unknown::kColon;
  Values values = Values::kNamed;
  bool see_help = true;            // " (see --help)" after every reason
  int error_exit = 2;              // exit status of ParseOrExit / Fail
};

// A floating-point value (std::strtod: the whole text, finite). In `message` and
// `range_message`, "{opt}" is replaced by the option and "{value}" by the text given; an
// empty message means "{opt}: invalid value '{value}'".
struct NumberRule {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;             // lo < v instead of lo <= v
  bool reject_range_error = false;  // strtod's ERANGE (overflow or underflow) is malformed
  std::string message{};            // a malformed value, or out of [lo, hi] without range_message
  std::string range_message{};      // a well-formed value out of [lo, hi] (optional)
};

// A whole number (std::strtoll, base 10, the whole text) that must fit the target type
// (else `message`) and lie in [lo, hi] (else range_message, or message without one).
struct IntegerRule {
  long long lo = std::numeric_limits<long long>::min();
  long long hi = std::numeric_limits<long long>::max();
  bool digits_only = false;  // only 0-9 (no blanks, no sign), as std::from_chars of an unsigned
  std::string message{};
  std::string range_message{};
};

// The number of `text` as the value of `opt`, or the reason it is not accepted.
std::optional<std::string> ParseCliNumber(std::string_view opt, const std::string& text, const NumberRule& rule,
                                          double& out);
// As ParseCliNumber; type_lo / type_hi are the target type's range.
std::optional<std::string> ParseCliInteger(std::string_view opt, const std::string& text, const IntegerRule& rule,
                                           long long type_lo, long long type_hi, long long& out);

struct CliResult {
  enum class Status { kOk, kHelp, kError };
  Status status = Status::kOk;
  std::string error;  // the reason (kError), without the tool prefix and suffix
};

class CliParser {
 public:
  // A custom option: applies its value, or returns the reason it is not accepted.
  using Handler = std::function<std::optional<std::string>(const std::string& value)>;

  CliParser(CliStyle style, std::function<void()> print_help);

  // --name VALUE; the last one counts.
  CliParser& Value(std::string name, std::string& target);
  // --name VALUE, repeatable; appended in order.
  CliParser& List(std::string name, std::vector<std::string>& target);
  // --name: sets target to true.
  CliParser& Flag(std::string name, bool& target);
  CliParser& Number(std::string name, double& target, NumberRule rule);
  CliParser& Number(std::string name, std::vector<double>& target, NumberRule rule);  // repeatable
  CliParser& Number(std::string name, std::function<void(double)> set, NumberRule rule);
  template <typename T>
  CliParser& Integer(std::string name, T& target, IntegerRule rule);
  CliParser& Custom(std::string name, Handler handler);
  // After the arguments: "<name> is required" if the Value / List of `name` is empty
  // (checked in the order of the Require calls).
  CliParser& Require(const std::string& name);

  // Applies the arguments argv[1..argc) to the targets; stops at the first error or help.
  [[nodiscard]] CliResult Parse(int argc, const char* const* argv) const;
  // Parse; help: print it, exit 0; error: Fail.
  void ParseOrExit(int argc, const char* const* argv) const;
  // The line printed for an error: "<tool>: <reason>" plus " (see --help)" if the style says so.
  [[nodiscard]] std::string Message(const std::string& reason) const;
  // Prints Message(reason) on stderr and exits with the style's error code.
  [[noreturn]] void Fail(const std::string& reason) const;

 private:
  struct Option {
    std::string name;
    bool takes_value = true;
    Handler apply;                // value (empty for a flag) -> error
    std::function<bool()> empty;  // Value / List: is the target empty
  };
  CliParser& Add(Option option);
  CliParser& AddInteger(std::string name, std::function<void(long long)> set, IntegerRule rule, long long type_lo,
                        long long type_hi);
  [[nodiscard]] const Option* Find(std::string_view name) const;

  CliStyle style_;
  std::function<void()> print_help_;
  std::vector<Option> options_;
  std::vector<std::size_t> required_;  // indices into options_
};

template <typename T>
CliParser& CliParser::Integer(std::string name, T& target, IntegerRule rule) {
  static_assert(std::is_integral_v<T> && !std::is_same_v<T, bool>, "Integer needs an integer target");
  constexpr long long kLlMax = std::numeric_limits<long long>::max();
  constexpr long long type_lo = std::is_signed_v<T> ? static_cast<long long>(std::numeric_limits<T>::min()) : 0;
  constexpr long long type_hi = std::cmp_greater(std::numeric_limits<T>::max(), kLlMax)
                                    ? kLlMax
                                    : static_cast<long long>(std::numeric_limits<T>::max());
  return AddInteger(std::move(name), [&target](long long v) { target = static_cast<T>(v); }, std::move(rule), type_lo,
                    type_hi);
}

}  // namespace railproof::offline
