// Typed, path-aware access to a parsed JSON document for the offline tools' input files:
// every failure throws InputError "<file>: <entry path>: <reason>" (one line), so the
// message names the entry (REQ-MB-020), e.g. "d1.json: running_lines[0] (up).blocks_mm[3]:
// expected an integer, got string". JsonDocument and ReadInputFile are what every input
// loader shares: the file read, the parse and the schema check.
#pragma once

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

class JsonNode {
 public:
  JsonNode(const nlohmann::json& value, std::string path, const std::string& file)
      : value_(&value), path_(std::move(path)), file_(&file) {}

  // Parses `text`; a syntax error gives "<file>: invalid JSON: <parser message>".
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

  // The same node with a label appended to its path (e.g. the id of an array element).
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

namespace json_detail {
// The parsed document, a base of JsonDocument so that it is built before the root node.
struct ParsedJson {
  nlohmann::json doc;
};
}  // namespace json_detail

// A parsed input document, which is its own root node (path ""): the text of `file` is
// parsed ("<file>: invalid JSON: <parser message>" on a syntax error) and, given `schema`,
// its "schema" member must equal it ("<file>: schema: unsupported schema '<found>', expected
// '<schema>'<note>"). `file` must outlive the document and every node taken from it.
class JsonDocument : private json_detail::ParsedJson, public JsonNode {
 public:
  JsonDocument(std::string_view text, const std::string& file);
  JsonDocument(std::string_view text, const std::string& file, std::string_view schema, std::string_view note = "");
  JsonDocument(const JsonDocument&) = delete;
  JsonDocument& operator=(const JsonDocument&) = delete;
};

// The whole text of an input file; "<path>: cannot read <what>" ("<path>: cannot read" if
// `what` is empty) when it cannot be opened.
std::string ReadInputFile(const std::filesystem::path& path, std::string_view what);

}  // namespace railproof::offline
