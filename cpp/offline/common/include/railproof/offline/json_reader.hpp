// Typed, path-aware access to a parsed JSON document for the offline tools' input files:
// every failure throws InputError "<file>: <entry path>: <reason>" (one line), so the
// message names the entry (REQ-MB-020), e.g. "d1.json: running_lines[0] (up).blocks_mm[3]:
// expected an integer, got string". JsonDocument and ReadInputFile are what every input
// loader shares: the file read (a regular file of at most kMaxInputBytes), the parse (UTF-8
// text, no duplicate key, at most kMaxJsonDepth levels) and the schema check; the typed
// reads below check a value's range before the loader converts or computes with it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/offline/line.hpp"

namespace railproof::offline {

// The largest input file a loader reads (16 MiB, some hundred times the largest generated
// line): checked before the file is read, so no input can make a tool allocate without bound.
inline constexpr std::uintmax_t kMaxInputBytes = std::uintmax_t{16} << 20U;
// The deepest nesting of arrays and objects a document may have (the data files use five).
inline constexpr int kMaxJsonDepth = 64;

// Closed ([lo, hi]) or, with lo_open, half-open ((lo, hi]) range of a number.
struct NumberRange {
  double lo = 0.0;
  double hi = 0.0;
  bool lo_open = false;
};

class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string path, const std::string& file)
      : value_(&value), path_(std::move(path)), file_(&file) {}

  // Parses `text`. It must be UTF-8 ("<file>: not UTF-8 text: invalid UTF-8 byte at index
  // <i>: 0x<byte>"), JSON ("<file>: invalid JSON: <parser message>"), with no key twice in
  // one object ("<file>: <object path>: duplicate key '<key>'") and no deeper than
  // kMaxJsonDepth ("<file>: <path>: nested deeper than 64 levels").
  static nlohmann::json Parse(std::string_view text, const std::string& file);

  [[nodiscard]] const std::string& Path() const { return path_; }
  [[nodiscard]] const nlohmann::json& Value() const { return *value_; }
  [[nodiscard]] bool IsNull() const { return value_->is_null(); }

  // Required member (object expected); "missing key 'k'" otherwise.
  [[nodiscard]] JsonNode Key(std::string_view key) const;
  // Member that may be absent or null.
  [[nodiscard]] std::optional<JsonNode> OptKey(std::string_view key) const;
  [[nodiscard]] bool Has(std::string_view key) const;
  // Rejects members not in `allowed` ("unknown key 'k'") — catches typos in hand-written files.
  void AllowOnly(std::initializer_list<std::string_view> allowed) const;

  [[nodiscard]] std::int64_t Int() const;
  [[nodiscard]] double Number() const;  // integer or float, finite
  [[nodiscard]] std::string String() const;
  [[nodiscard]] bool Bool() const;
  [[nodiscard]] std::vector<JsonNode> Array() const;
  // The elements of an array that must not be empty (`if_empty`: the reason if it is).
  [[nodiscard]] std::vector<JsonNode> NonEmptyArray(const std::string& if_empty) const;

  // Values within the range a loader computes with; outside it "value <v> <unit> is outside
  // [lo, hi]" ("(lo, hi]" for an open lower bound). `unit` may be empty.
  [[nodiscard]] std::int64_t IntIn(std::int64_t lo, std::int64_t hi, std::string_view unit = "") const;
  [[nodiscard]] double NumberIn(const NumberRange& range, std::string_view unit = "") const;
  // A number in `range` times `scale`, rounded to the nearest integer (metres to mm, seconds
  // to ms): the range is checked before the conversion, and must keep range * scale within
  // +-2^53 (a loader's mistake otherwise: std::logic_error).
  [[nodiscard]] std::int64_t ScaledIn(const NumberRange& range, double scale, std::string_view unit = "") const;
  // A pair [min, max] of integers in [lo, hi] with min <= max: "expected [min, max], got <n>
  // element(s)", "min <a> <unit> is greater than max <b> <unit>".
  [[nodiscard]] std::pair<std::int64_t, std::int64_t> IntPairIn(std::int64_t lo, std::int64_t hi,
                                                                std::string_view unit = "") const;

  // The same node with a label appended to its path (e.g. the id of an array element; a
  // label longer than 64 bytes is cut).
  [[nodiscard]] JsonNode Labelled(const std::string& label) const;

  [[noreturn]] void Fail(const std::string& reason) const;

 private:
  // Fails with "expected <what>, got <type>" unless `is_expected`.
  void RequireType(bool is_expected, std::string_view what) const;
  void RequireObject() const;

  const nlohmann::json* value_;
  std::string path_;
  const std::string* file_;
};

// "<what> (<type name>)" for messages.
std::string JsonTypeName(const nlohmann::json& value);

// Text of the input quoted for a message: 'text', cut to 64 bytes (at a character boundary)
// with "..." after it, so that no key or name of a file makes a message unbounded.
std::string Quoted(std::string_view text);

// A number for a message (6 significant digits: 1e+300, 0.5, 604800).
std::string FormatNumber(double v);

namespace json_detail {
// The parsed document, a base of JsonDocument so that it is built before the root node.
struct ParsedJson {
  nlohmann::json doc;
};
}  // namespace json_detail

// A parsed input document, which is its own root node (path ""): the text of `file` is
// parsed (JsonNode::Parse) and, given `schema`, its "schema" member must equal it ("<file>:
// schema: unsupported schema '<found>', expected '<schema>'<note>"). `file` must outlive the
// document and every node taken from it.
class JsonDocument : private json_detail::ParsedJson, public JsonNode {
 public:
  JsonDocument(std::string_view text, const std::string& file);
  JsonDocument(std::string_view text, const std::string& file, std::string_view schema, std::string_view note = "");
  JsonDocument(const JsonDocument&) = delete;
  JsonDocument& operator=(const JsonDocument&) = delete;
};

// The whole text of an input file. It must be a regular file of at most kMaxInputBytes;
// otherwise "<path>: cannot read <what>: <reason>" (reason: the system's, e.g. "No such file
// or directory", "Is a directory", or "not a regular file", "larger than the input limit of
// 16777216 bytes"). `what` names the kind of file ("line file"); empty: "file".
std::string ReadInputFile(const std::filesystem::path& path, std::string_view what);

// The input files of a directory: its *.json files in name order, or `path` itself when it is
// a file. Otherwise "<path>: <what>: no such file or directory", "<path>: cannot list <what>:
// <reason>" or "<path>: no <what> (*.json)". `what` names the content ("train types").
std::vector<std::filesystem::path> ListJsonFiles(const std::filesystem::path& path, std::string_view what);

}  // namespace railproof::offline
