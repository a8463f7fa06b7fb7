#include "railproof/offline/json_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace railproof::offline {

std::string OneLine(std::string_view text) {
  // UTF-8 first: a byte that is not (the parser's "last read" can end inside a character, a
  // file name need not be UTF-8) becomes U+FFFD, by the library's serialiser and parser
  const std::string utf8 =
      nlohmann::json::parse(nlohmann::json(std::string(text)).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace))
          .get<std::string>();
  std::string out;
  out.reserve(utf8.size());
  for (const char c : utf8) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20U && u != 0x7FU) {
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", u);
      out += buf;
    }
  }
  return out;
}

namespace {

constexpr std::size_t kQuoteBytes = 64;
constexpr std::size_t kParserMessageBytes = 200;

// The first `n` bytes of UTF-8 text, not cutting a character.
std::string_view Cut(std::string_view text, std::size_t n) {
  if (text.size() <= n) {
    return text;
  }
  while (n > 0 && (static_cast<unsigned char>(text[n]) & 0xC0U) == 0x80U) {
    --n;
  }
  return text.substr(0, n);
}

std::string CutWithDots(std::string_view text, std::size_t n) {
  const std::string_view head = Cut(text, n);
  return std::string(head) + (head.size() < text.size() ? "..." : "");
}

// The library's message without its "[json.exception.<kind>.<id>] " prefix, cut short.
std::string LibraryMessage(const nlohmann::json::exception& e) {
  std::string_view what = e.what();
  if (what.starts_with("[json.exception.")) {
    const auto end = what.find("] ");
    if (end != std::string_view::npos) {
      what.remove_prefix(end + 2);
    }
  }
  return CutWithDots(what, kParserMessageBytes);
}

std::string Join(const std::string& path, std::string_view key) {
  return path.empty() ? std::string(key) : path + "." + std::string(key);
}

std::string PathForMessage(const std::string& path) { return path.empty() ? std::string("(top level)") : path; }

// The parser callback that keeps what nlohmann's DOM parser does not: one key once per
// object (the parser keeps the last), and a bounded depth. It follows the path of the value
// being parsed, in the readers' notation (running_lines[0].blocks_mm[3]), for the message.
class StructureCheck {
 public:
  explicit StructureCheck(const std::string& file) : file_(&file) {}

  bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    switch (event) {
      case Event::object_start:
      case Event::array_start: {
        const std::string path = stack_.empty() ? std::string() : ChildPath();
        if (stack_.size() >= static_cast<std::size_t>(kMaxJsonDepth)) {
          throw InputError(*file_ + ": " + PathForMessage(path) + ": nested deeper than " +
                           std::to_string(kMaxJsonDepth) + " levels");
        }
        stack_.push_back(Level{event == Event::array_start, path, 0, {}, {}});
        break;
      }
      case Event::key: {
        Level& level = stack_.back();
        std::string key = parsed.get<std::string>();
        if (!level.keys.insert(key).second) {
          throw InputError(*file_ + ": " + PathForMessage(level.path) + ": duplicate key " + Quoted(key));
        }
        level.key = std::move(key);
        break;
      }
      case Event::object_end:
      case Event::array_end:
        stack_.pop_back();
        NextElement();
        break;
      case Event::value:
        NextElement();
        break;
    }
    return true;
  }

 private:
  struct Level {
    bool array = false;
    std::string path;
    std::size_t index = 0;  // of the element being parsed (arrays)
    std::string key;        // of the member being parsed (objects)
    std::set<std::string, std::less<>> keys;
  };

  [[nodiscard]] std::string ChildPath() const {
    const Level& parent = stack_.back();
    return parent.array ? parent.path + "[" + std::to_string(parent.index) + "]" : Join(parent.path, parent.key);
  }
  void NextElement() {
    if (!stack_.empty() && stack_.back().array) {
      ++stack_.back().index;
    }
  }

  const std::string* file_;
  std::vector<Level> stack_;
};

}  // namespace

// Appended rather than "'" + ... + "'": g++ 12 at -O3 reports a false -Wrestrict on
// operator+(const char*, std::string&&) (GCC bug 105651), which the Release build would fail on.
std::string Quoted(std::string_view text) {
  std::string out(1, '\'');
  out += CutWithDots(text, kQuoteBytes);
  out += '\'';
  return out;
}

std::string FormatNumber(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

nlohmann::json JsonNode::Parse(std::string_view text, const std::string& file) {
  // UTF-8 first, with the library's own check: serialising the text as a JSON string
  // (strict error handler) throws at the first byte that is not UTF-8.
  try {
    (void)nlohmann::json(std::string(text)).dump();
  } catch (const nlohmann::json::type_error& e) {
    throw InputError(file + ": not UTF-8 text: " + LibraryMessage(e));
  }
  try {
    StructureCheck check(file);
    return nlohmann::json::parse(text.begin(), text.end(), std::ref(check));
  } catch (const nlohmann::json::exception& e) {  // a syntax error, or a number beyond a double
    throw InputError(file + ": invalid JSON: " + LibraryMessage(e));
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

void JsonNode::Fail(const std::string& reason) const { throw InputError(*file_ + ": " + PathForMessage(path_) + ": " + reason); }

void JsonNode::RequireType(bool is_expected, std::string_view what) const {
  if (!is_expected) {
    Fail("expected " + std::string(what) + ", got " + JsonTypeName(*value_));
  }
}

void JsonNode::RequireObject() const { RequireType(value_->is_object(), "an object"); }

JsonNode JsonNode::Key(std::string_view key) const {
  RequireObject();
  const auto it = value_->find(key);
  if (it == value_->end()) {
    Fail("missing key " + Quoted(key));
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
      Fail("unknown key " + Quoted(item.key()));
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

namespace {
std::string WithUnit(const std::string& value, std::string_view unit) {
  return unit.empty() ? value : value + " " + std::string(unit);
}
}  // namespace

std::int64_t JsonNode::IntIn(std::int64_t lo, std::int64_t hi, std::string_view unit) const {
  const std::int64_t v = Int();
  if (v < lo || v > hi) {
    Fail("value " + WithUnit(std::to_string(v), unit) + " is outside [" + std::to_string(lo) + ", " +
         std::to_string(hi) + "]");
  }
  return v;
}

double JsonNode::NumberIn(const NumberRange& range, std::string_view unit) const {
  const double v = Number();
  if (v < range.lo || (range.lo_open && v == range.lo) || v > range.hi) {
    Fail("value " + WithUnit(FormatNumber(v), unit) + " is outside " + (range.lo_open ? "(" : "[") +
         FormatNumber(range.lo) + ", " + FormatNumber(range.hi) + "]");
  }
  return v;
}

std::int64_t JsonNode::ScaledIn(const NumberRange& range, double scale, std::string_view unit) const {
  constexpr double kExact = 9007199254740992.0;  // 2^53
  if (!(std::fabs(range.lo * scale) <= kExact && std::fabs(range.hi * scale) <= kExact)) {
    throw std::logic_error("JsonNode::ScaledIn: range times scale beyond 2^53");
  }
  return std::llround(NumberIn(range, unit) * scale);
}

std::pair<std::int64_t, std::int64_t> JsonNode::IntPairIn(std::int64_t lo, std::int64_t hi, std::string_view unit) const {
  const auto items = Array();
  if (items.size() != 2) {
    Fail("expected [min, max], got " + std::to_string(items.size()) + " element(s)");
  }
  const std::pair<std::int64_t, std::int64_t> r{items[0].IntIn(lo, hi, unit), items[1].IntIn(lo, hi, unit)};
  if (r.first > r.second) {
    Fail("min " + WithUnit(std::to_string(r.first), unit) + " is greater than max " +
         WithUnit(std::to_string(r.second), unit));
  }
  return r;
}

JsonNode JsonNode::Labelled(const std::string& label) const {
  return JsonNode(*value_, path_ + " (" + CutWithDots(label, kQuoteBytes) + ")", *file_);
}

JsonDocument::JsonDocument(std::string_view text, const std::string& file)
    : ParsedJson{Parse(text, file)}, JsonNode(doc, "", file) {}

JsonDocument::JsonDocument(std::string_view text, const std::string& file, std::string_view schema,
                           std::string_view note)
    : JsonDocument(text, file) {
  const JsonNode s = Key("schema");
  if (s.String() != schema) {
    s.Fail("unsupported schema " + Quoted(s.String()) + ", expected '" + std::string(schema) + "'" + std::string(note));
  }
}

std::vector<std::filesystem::path> ListJsonFiles(const std::filesystem::path& path, std::string_view what) {
  namespace fs = std::filesystem;
  const std::string name(what);
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) {
    return {path};
  }
  if (!fs::is_directory(path, ec)) {
    throw InputError(path.string() + ": " + name + ": no such file or directory");
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(path, ec)) {
    if (e.is_regular_file() && e.path().extension() == ".json") {
      files.push_back(e.path());
    }
  }
  if (ec) {
    throw InputError(path.string() + ": cannot list " + name + ": " + ec.message());
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    throw InputError(path.string() + ": no " + name + " (*.json)");
  }
  return files;
}

std::string ReadInputFile(const std::filesystem::path& path, std::string_view what) {
  namespace fs = std::filesystem;
  const std::string file = path.string();
  const auto fail = [&](const std::string& reason) -> void {
    throw InputError(file + ": cannot read " + (what.empty() ? std::string("file") : std::string(what)) + ": " + reason);
  };
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec) {
    fail(ec.message());
  }
  if (fs::is_directory(st)) {
    fail(std::error_code(EISDIR, std::generic_category()).message());
  }
  if (!fs::is_regular_file(st)) {
    fail("not a regular file");
  }
  const auto size = fs::file_size(path, ec);
  if (ec) {
    fail(ec.message());
  }
  const std::string too_large = "larger than the input limit of " + std::to_string(kMaxInputBytes) + " bytes";
  if (size > kMaxInputBytes) {
    fail(too_large);
  }
  errno = 0;
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> in(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!in) {
    fail(std::error_code(errno, std::generic_category()).message());
  }
  // read up to one byte past the limit: a file that grew since its size was taken is refused too
  std::string text(static_cast<std::size_t>(std::min<std::uintmax_t>(size, kMaxInputBytes)) + 1, '\0');
  std::size_t got = 0;
  for (;;) {
    if (got == text.size()) {
      if (got > kMaxInputBytes) {
        fail(too_large);
      }
      text.resize(std::min<std::size_t>(2 * text.size(), kMaxInputBytes + 1));
    }
    const std::size_t n = std::fread(text.data() + got, 1, text.size() - got, in.get());
    got += n;
    if (n == 0) {
      break;
    }
  }
  if (std::ferror(in.get()) != 0) {
    fail(std::error_code(errno, std::generic_category()).message());
  }
  if (got > kMaxInputBytes) {
    fail(too_large);
  }
  text.resize(got);
  return text;
}

}  // namespace railproof::offline
