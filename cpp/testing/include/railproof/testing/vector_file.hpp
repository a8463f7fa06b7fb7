// One vector file read whole or not at all, for every conformance runner (the JSON Lines
// runners of br, ra, lc and mb through jsonl_vectors.hpp, the tg reader
// cpp/runtime/tg/conformance/vector_reader.cpp). A vector file is a header line, then one
// vector per line (spec/schemas/vector_header.schema.json, spec/design/tg.md §7):
//  - the header is a JSON object with "kind":"header", schema_version exactly
//    kVectorSchemaVersion, and vector_count and vectors_sha256 that match the text after the
//    header line (the number of lines and the SHA-256 of their bytes as written), checked
//    before any vector is read: a file cut at a line boundary, a line dropped, duplicated or
//    edited is refused;
//  - every line is one JSON object whose objects name no key twice (nlohmann keeps the last
//    one; its parser callback refuses the second) and nest at most kMaxJsonDepth deep;
//  - no key the format does not know, in the header, in a vector or in a step: the runner
//    declares its keys (VectorKeys), the keys every file has are added here.
// Every error is one line "<file>:<line>: <reason>" (the whole file: "<file>: <reason>").
// Test-only code: allocates, never throws.
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace railproof::conformance {

// The vector file format the runners read (header "schema_version"; vectors.py SCHEMA_VERSION).
inline constexpr std::int64_t kVectorSchemaVersion = 2;
// Deepest nesting of objects and arrays in one line (the formats need 8).
inline constexpr std::size_t kMaxJsonDepth = 32;
// Largest vector file read (the largest generated one has about 2 MB).
inline constexpr std::uintmax_t kMaxVectorFileBytes = std::uintmax_t{256} << 20U;

// The keys a JSON value may have: an object gives each allowed key the keys of its value; an
// array of one element gives the keys of every element of an array; anything else (null)
// allows any value there.
using KeyTree = nlohmann::json;

// What a runner declares: the keys its files have besides those every vector file has
// (header: kind, schema_version, model, model_sha256, generator, spin_version,
// vector_count, vectors_sha256; vector: id, requirements, goal, kind, seed, steps).
struct VectorKeys {
  KeyTree header = KeyTree::object();
  KeyTree vector = KeyTree::object();
  KeyTree step = KeyTree::object();  // the keys of one step (the elements of "steps")
};

// One vector line: its number in the file and its object.
struct VectorLine {
  std::size_t line = 0;
  nlohmann::json obj;
};

struct VectorFile {
  nlohmann::json header;
  std::vector<VectorLine> vectors;
};

// s as a JSON string (quoted, control characters escaped: a message stays one line), at most
// kMaxQuoted of its bytes.
inline constexpr std::size_t kMaxQuoted = 120;
std::string Quoted(std::string_view s);

// SHA-256 of bytes in lowercase hex (libsodium).
std::string Sha256Hex(std::string_view bytes);

// Parses one JSON text into out; "" or the one-line reason: malformed JSON, a key named twice
// in one object (`duplicate key "steps[2].in.v_s"`), nesting deeper than kMaxJsonDepth.
std::string ParseJsonLine(std::string_view text, nlohmann::json& out);

// "" or the path of the first key of value that keys does not allow ("steps[3].in.speed";
// path names value itself).
std::string UnknownKey(const nlohmann::json& value, const KeyTree& keys, const std::string& path = "");

// Reads the text of one vector file (file: its name in messages); "" or the first error.
std::string ReadVectorFile(const std::string& file, std::string_view text, const VectorKeys& keys, VectorFile& out);

// The <prefix>*.jsonl regular files of dir, sorted by name; "" or the reason (no directory,
// not listable, no such file).
std::string ListVectorFiles(const std::filesystem::path& dir, const std::string& prefix,
                            std::vector<std::filesystem::path>& files);

// The bytes of a vector file; "" or "<file>: <reason>" (unreadable, over kMaxVectorFileBytes).
std::string ReadFileText(const std::filesystem::path& path, std::string& text);

}  // namespace railproof::conformance
