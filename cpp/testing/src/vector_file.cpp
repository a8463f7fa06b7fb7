// One vector file read whole or not at all (see vector_file.hpp).
#include "railproof/testing/vector_file.hpp"

#include <sodium.h>

#include <algorithm>
#include <array>
#include <fstream>
#include <iterator>
#include <set>
#include <system_error>
#include <utility>

namespace railproof::conformance {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// A reason longer than this is cut (the parser quotes what it read, which may be a whole line).
constexpr std::size_t kMaxReason = 300;

std::string Cut(std::string s) {
  if (s.size() > kMaxReason) {
    s.resize(kMaxReason);
    s += " ...";
  }
  return s;
}

// Ends the parse at the first duplicate key or too deep nesting (what() is the reason).
struct StopParse {
  std::string reason;
};

// Where the parser is: one frame per open object or array, with the key or index of the
// value being read in it.
class ParsePosition {
 public:
  void BeginValue() {
    if (!frames_.empty() && !frames_.back().object) {
      Frame& f = frames_.back();
      f.index = f.started ? f.index + 1 : 0;
      f.started = true;
    }
  }
  void Open(bool object) {
    BeginValue();
    if (frames_.size() >= kMaxJsonDepth) {
      throw StopParse{"nesting deeper than " + std::to_string(kMaxJsonDepth) + " levels at " + Quoted(Path())};
    }
    frames_.push_back(Frame{object, {}, {}, 0, false});
  }
  void Close() { frames_.pop_back(); }
  void Key(const std::string& key) {
    Frame& f = frames_.back();
    f.key = key;
    if (!f.keys.insert(key).second) {
      throw StopParse{"duplicate key " + Quoted(Path())};
    }
  }

 private:
  struct Frame {
    bool object;
    std::set<std::string> keys;  // of an object, so far
    std::string key;             // of an object, the current one
    std::size_t index;           // of an array, the current element
    bool started;
  };
  // "steps[2].in.v_s": the keys and indices down to the value being read
  std::string Path() const {
    std::string p;
    for (const Frame& f : frames_) {
      p += f.object ? (p.empty() ? "" : ".") + f.key : "[" + std::to_string(f.index) + "]";
    }
    return p.empty() ? "(top level)" : p;
  }
  std::vector<Frame> frames_;
};

// The keys every vector file has (spec/schemas/vector_header.schema.json, the vector
// fields every capability's schema has), with a runner's own.
KeyTree WithCommonHeaderKeys(const KeyTree& own) {
  KeyTree t = own.is_object() ? own : KeyTree::object();
  for (const char* k : {"kind", "schema_version", "model", "model_sha256", "generator", "spin_version", "vector_count",
                        "vectors_sha256"}) {
    t[k] = nullptr;
  }
  return t;
}

KeyTree WithCommonVectorKeys(const VectorKeys& keys) {
  KeyTree t = keys.vector.is_object() ? keys.vector : KeyTree::object();
  for (const char* k : {"id", "requirements", "goal", "kind", "seed"}) {
    t[k] = nullptr;
  }
  t["steps"] = KeyTree::array({keys.step});
  return t;
}

bool IsLowerHex(const json& v, std::size_t digits) {
  if (!v.is_string()) {
    return false;
  }
  const auto& s = v.get_ref<const std::string&>();
  return s.size() == digits &&
         std::all_of(s.begin(), s.end(), [](char c) { return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'); });
}

}  // namespace

std::string Quoted(std::string_view s) {
  const bool cut = s.size() > kMaxQuoted;
  const json text = std::string(s.substr(0, kMaxQuoted));
  return text.dump(-1, ' ', false, json::error_handler_t::replace) + (cut ? " (cut)" : "");
}

std::string Sha256Hex(std::string_view bytes) {
  std::array<unsigned char, crypto_hash_sha256_BYTES> digest{};
  crypto_hash_sha256(digest.data(), reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(2 * digest.size());
  for (const unsigned char b : digest) {
    out += kHex[b >> 4U];
    out += kHex[b & 0xFU];
  }
  return out;
}

std::string ParseJsonLine(std::string_view text, json& out) {
  ParsePosition at;
  const json::parser_callback_t callback = [&at](int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start: at.Open(true); break;
      case json::parse_event_t::array_start: at.Open(false); break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end: at.Close(); break;
      case json::parse_event_t::key: at.Key(parsed.get_ref<const std::string&>()); break;
      case json::parse_event_t::value: at.BeginValue(); break;
    }
    return true;
  };
  try {
    out = json::parse(text.begin(), text.end(), callback, /*allow_exceptions=*/true);
  } catch (const StopParse& stop) {
    out = json();
    return Cut(stop.reason);
  } catch (const json::exception& e) {
    out = json();
    std::string what = e.what();
    if (const std::size_t b = what.find("] "); what.rfind("[json.exception.", 0) == 0 && b != std::string::npos) {
      what.erase(0, b + 2);  // "[json.exception.parse_error.101] " adds nothing for a reader
    }
    return Cut("malformed JSON: " + what);
  }
  return "";
}

std::string UnknownKey(const json& value, const KeyTree& keys, const std::string& path) {
  if (keys.is_object() && value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it) {
      const std::string here = path.empty() ? it.key() : path + "." + it.key();
      const auto allowed = keys.find(it.key());
      if (allowed == keys.end()) {
        return here;
      }
      if (std::string k = UnknownKey(it.value(), *allowed, here); !k.empty()) {
        return k;
      }
    }
  } else if (keys.is_array() && keys.size() == 1 && value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      if (std::string k = UnknownKey(value[i], keys[0], path + "[" + std::to_string(i) + "]"); !k.empty()) {
        return k;
      }
    }
  }
  return "";
}

std::string ReadVectorFile(const std::string& file, std::string_view text, const VectorKeys& keys, VectorFile& out) {
  out = VectorFile{};
  const auto at = [&file](std::size_t line, const std::string& reason) {
    return file + ":" + std::to_string(line) + ": " + reason;
  };
  if (text.empty()) {
    return at(1, "empty file (no header line)");
  }
  const std::size_t eol = text.find('\n');
  if (eol == std::string_view::npos) {
    return at(1, "the header line has no line end (file cut short?)");
  }
  // the header: what the file is, how many vector lines follow and their digest
  json& header = out.header;
  if (std::string e = ParseJsonLine(text.substr(0, eol), header); !e.empty()) {
    return at(1, e);
  }
  if (!header.is_object() || !header.contains("kind") || header["kind"] != "header") {
    return at(1, "first line is not a vector header (\"kind\":\"header\")");
  }
  if (!header.contains("schema_version") || !header["schema_version"].is_number_integer()) {
    return at(1, "the header has no integer schema_version");
  }
  if (header["schema_version"] != kVectorSchemaVersion) {
    return at(1, "schema_version " + header["schema_version"].dump() + " is not supported (expected " +
                     std::to_string(kVectorSchemaVersion) + ")");
  }
  if (const std::string k = UnknownKey(header, WithCommonHeaderKeys(keys.header)); !k.empty()) {
    return at(1, "unknown header key " + Quoted(k));
  }
  const json* count = header.contains("vector_count") ? &header["vector_count"] : nullptr;
  if (count == nullptr || !count->is_number_integer() || *count < 0) {
    return at(1, "the header has no vector_count (a non-negative integer)");
  }
  if (!header.contains("vectors_sha256") || !IsLowerHex(header["vectors_sha256"], 2 * crypto_hash_sha256_BYTES)) {
    return at(1, "the header has no vectors_sha256 (64 lowercase hex digits)");
  }
  // the vector lines as written: their number and digest first, then each line
  const std::string_view body = text.substr(eol + 1);
  const auto lines = static_cast<std::size_t>(std::count(body.begin(), body.end(), '\n'));
  if (!body.empty() && body.back() != '\n') {
    return at(lines + 2, "the last line has no line end (file cut short?)");
  }
  if (*count != lines) {
    return at(1, "the header states " + count->dump() + " vectors, the file has " + std::to_string(lines));
  }
#ifndef RAILPROOF_VECTOR_FILE_NO_DIGEST_CHECK  // defined only for the fuzz oracle's negative test
  if (Sha256Hex(body) != header["vectors_sha256"].get_ref<const std::string&>()) {
    return at(1, "the vector lines do not match the header's vectors_sha256 (a vector was changed)");
  }
#endif
  const KeyTree vector_keys = WithCommonVectorKeys(keys);
  std::size_t n = 1;
  for (std::size_t begin = 0; begin < body.size();) {
    const std::size_t end = body.find('\n', begin);  // every line ends with one (checked above)
    const std::string_view line = body.substr(begin, end - begin);
    begin = end + 1;
    ++n;
    if (line.empty()) {
      return at(n, "empty line");
    }
    VectorLine v{n, json()};
    if (std::string e = ParseJsonLine(line, v.obj); !e.empty()) {
      return at(n, e);
    }
    if (!v.obj.is_object()) {
      return at(n, "the line is not a JSON object");
    }
    if (const std::string k = UnknownKey(v.obj, vector_keys); !k.empty()) {
      return at(n, "unknown key " + Quoted(k));
    }
    out.vectors.push_back(std::move(v));
  }
  return "";
}

std::string ListVectorFiles(const fs::path& dir, const std::string& prefix, std::vector<fs::path>& files) {
  files.clear();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    return "vector directory " + dir.string() + " does not exist or is not a directory";
  }
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::error_code type_ec;
    if (it->path().extension() == ".jsonl" && name.rfind(prefix, 0) == 0 && it->is_regular_file(type_ec)) {
      files.push_back(it->path());
    }
  }
  if (ec) {
    return "cannot list vector directory " + dir.string() + ": " + ec.message();
  }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    return "no *.jsonl vector file (" + prefix + "*.jsonl) in " + dir.string();
  }
  return "";
}

std::string ReadFileText(const fs::path& path, std::string& text) {
  text.clear();
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    return path.string() + ": cannot be read (" + ec.message() + ")";
  }
  if (size > kMaxVectorFileBytes) {
    return path.string() + ": " + std::to_string(size) + " bytes, more than a vector file may have (" +
           std::to_string(kMaxVectorFileBytes) + ")";
  }
  std::ifstream in(path, std::ios::binary);
  text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    return path.string() + ": cannot be read";
  }
  if (text.size() > kMaxVectorFileBytes) {  // grew while it was read
    return path.string() + ": more than " + std::to_string(kMaxVectorFileBytes) + " bytes";
  }
  return "";
}

}  // namespace railproof::conformance
