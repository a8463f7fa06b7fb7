#include "railproof/offline/json_reader.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

namespace railproof::offline {

nlohmann::json JsonNode::Parse(std::string_view text, const std::string& file) {
  try {
    return nlohmann::json::parse(text.begin(), text.end());
  } catch (const nlohmann::json::parse_error& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    throw InputError(file + ": invalid JSON: " + what);
  }
}

std::string JsonTypeName(const nlohmann::json& value) {
  if (value.is_number_integer()) {
    return "integer";
  }
  if (value.is_number_float()) {
    return "number";
  }
  return value.type_name();
}

void JsonNode::Fail(const std::string& reason) const {
  throw InputError(*file_ + ": " + (path_.empty() ? std::string("(top level)") : path_) + ": " + reason);
}

void JsonNode::RequireType(bool is_expected, std::string_view what) const {
  if (!is_expected) {
    Fail("expected " + std::string(what) + ", got " + JsonTypeName(*value_));
  }
}

void JsonNode::RequireObject() const { RequireType(value_->is_object(), "an object"); }

namespace {
std::string Join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}
}  // namespace

JsonNode JsonNode::Key(std::string_view key) const {
  RequireObject();
  const auto it = value_->find(key);
  if (it == value_->end()) {
    Fail("missing key '" + std::string(key) + "'");
  }
  return JsonNode(*it, Join(path_, key), *file_);
}

std::optional<JsonNode> JsonNode::OptKey(std::string_view key) const {
  RequireObject();
  const auto it = value_->find(key);
  if (it == value_->end() || it->is_null()) {
    return std::nullopt;
  }
  return JsonNode(*it, Join(path_, key), *file_);
}

bool JsonNode::Has(std::string_view key) const {
  RequireObject();
  return value_->contains(key);
}

void JsonNode::AllowOnly(std::initializer_list<std::string_view> allowed) const {
  RequireObject();
  for (const auto& item : value_->items()) {
    if (std::find(allowed.begin(), allowed.end(), std::string_view(item.key())) == allowed.end()) {
      Fail("unknown key '" + item.key() + "'");
    }
  }
}

std::int64_t JsonNode::Int() const {
  if (value_->is_number_unsigned()) {
    const auto u = value_->get<std::uint64_t>();
    if (u > static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max())) {
      Fail("integer out of range");
    }
    return static_cast<std::int64_t>(u);
  }
  RequireType(value_->is_number_integer(), "an integer");
  return value_->get<std::int64_t>();
}

double JsonNode::Number() const {
  RequireType(value_->is_number(), "a number");
  const double v = value_->get<double>();
  if (!std::isfinite(v)) {
    Fail("expected a finite number");
  }
  return v;
}

std::string JsonNode::String() const {
  RequireType(value_->is_string(), "a string");
  return value_->get<std::string>();
}

bool JsonNode::Bool() const {
  RequireType(value_->is_boolean(), "true or false");
  return value_->get<bool>();
}

std::vector<JsonNode> JsonNode::Array() const {
  RequireType(value_->is_array(), "an array");
  std::vector<JsonNode> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i) {
    out.emplace_back((*value_)[i], path_ + "[" + std::to_string(i) + "]", *file_);
  }
  return out;
}

std::vector<JsonNode> JsonNode::NonEmptyArray(const std::string& if_empty) const {
  std::vector<JsonNode> out = Array();
  if (out.empty()) {
    Fail(if_empty);
  }
  return out;
}

JsonNode JsonNode::Labelled(const std::string& label) const {
  return JsonNode(*value_, path_ + " (" + label + ")", *file_);
}

JsonDocument::JsonDocument(std::string_view text, const std::string& file)
    : ParsedJson{Parse(text, file)}, JsonNode(doc, "", file) {}

JsonDocument::JsonDocument(std::string_view text, const std::string& file, std::string_view schema,
                           std::string_view note)
    : JsonDocument(text, file) {
  const JsonNode s = Key("schema");
  if (s.String() != schema) {
    s.Fail("unsupported schema '" + s.String() + "', expected '" + std::string(schema) + "'" + std::string(note));
  }
}

std::string ReadInputFile(const std::filesystem::path& path, std::string_view what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw InputError(path.string() + ": cannot read" + (what.empty() ? "" : " " + std::string(what)));
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace railproof::offline
