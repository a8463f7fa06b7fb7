// libFuzzer target: the readers of the conformance vector files. An input is the text of
// one vector file; the model its header names chooses the reader, as the runners would:
// models/tg.pml the tg reader (cpp/runtime/tg/conformance/vector_reader.cpp, every telegram
// field), models/br.pml, ra.pml, mb.pml, lc.pml, lc_gnss.pml the shared reader
// (railproof/testing/vector_file.hpp) with the keys that capability's runner declares,
// anything else the shared reader with the keys every vector file has.
//
// Structure-aware: the custom mutator changes a vector line, the header line or the order of
// the lines (libFuzzer's byte mutator inside one line), then usually seals the header again
// (vector_count and vectors_sha256 of the new vector lines), so that the fuzzer gets past the
// header to the vectors instead of stopping at the digest; sometimes it leaves the seal
// stale, or mutates the bytes of the whole file.
//
// Oracles (a violation prints "railproof-fuzz: oracle violated: ..." and traps; ASan and
// UBSan watch for memory errors and undefined behaviour):
//  - a rejection is one line "fuzz.jsonl:<line>: <reason>" (at most kMaxReason bytes);
//  - an accepted file is whole: its first line is a JSON object of schema version
//    kVectorSchemaVersion whose vector_count is the number of vectors read and whose
//    vectors_sha256 is the SHA-256 of the text after the header line, which ends with a
//    newline (the reader's own checks, computed again here).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "br/conformance/vector_keys.hpp"
#include "lc/conformance/vector_keys.hpp"
#include "mb/conformance/vector_keys.hpp"
#include "ra/conformance/vector_keys.hpp"
#include "railproof/testing/vector_file.hpp"
#include "tg/conformance/vector_reader.hpp"

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace {

namespace rc = railproof::conformance;
using nlohmann::json;

constexpr std::size_t kMaxReason = 1000;  // the reader cuts a quoted parser message at 300
const std::string kFile = "fuzz.jsonl";

[[noreturn]] void OracleViolation(const std::string& what) {
  std::fprintf(stderr, "railproof-fuzz: oracle violated: %s\n", what.c_str());
  std::fflush(stderr);
  __builtin_trap();
}

// The reader of the model the header line names (the first of the models found in it).
enum class Reader { kTg, kBr, kRa, kMb, kLc, kAny };

Reader ReaderOf(std::string_view text) {
  const std::string_view head = text.substr(0, text.find('\n'));
  const std::pair<const char*, Reader> models[] = {
      {"\"models/tg.pml\"", Reader::kTg}, {"\"models/br.pml\"", Reader::kBr}, {"\"models/ra.pml\"", Reader::kRa},
      {"\"models/mb.pml\"", Reader::kMb}, {"\"models/lc.pml\"", Reader::kLc}, {"\"models/lc_gnss.pml\"", Reader::kLc}};
  for (const auto& [name, reader] : models) {
    if (head.find(name) != std::string_view::npos) {
      return reader;
    }
  }
  return Reader::kAny;
}

const rc::VectorKeys& KeysOf(Reader reader) {
  static const rc::VectorKeys br = rc::BrVectorKeys();
  static const rc::VectorKeys ra = rc::RaVectorKeys();
  static const rc::VectorKeys mb = rc::MbVectorKeys();
  static const rc::VectorKeys lc = rc::LcVectorKeys();
  static const rc::VectorKeys any;
  switch (reader) {
    case Reader::kBr: return br;
    case Reader::kRa: return ra;
    case Reader::kMb: return mb;
    case Reader::kLc: return lc;
    default: return any;
  }
}

void CheckReason(const std::string& error) {
  const std::string prefix = kFile + ":";
  std::size_t digits = prefix.size();
  while (digits < error.size() && error[digits] >= '0' && error[digits] <= '9') {
    ++digits;
  }
  if (error.rfind(prefix, 0) != 0 || digits == prefix.size() || error.compare(digits, 2, ": ") != 0 ||
      error.size() <= digits + 2) {
    OracleViolation("rejection not of the form \"fuzz.jsonl:<line>: <reason>\": " + error.substr(0, 200));
  }
  if (error.find('\n') != std::string::npos || error.find('\r') != std::string::npos) {
    OracleViolation("rejection of more than one line: " + error.substr(0, 200));
  }
  if (error.size() > kMaxReason) {
    OracleViolation("rejection longer than " + std::to_string(kMaxReason) + " bytes");
  }
}

void CheckAccepted(std::string_view text, std::size_t vectors) {
  const std::size_t eol = text.find('\n');
  if (eol == std::string_view::npos) {
    OracleViolation("accepted a file without a header line end");
  }
  const json header = json::parse(text.substr(0, eol), nullptr, /*allow_exceptions=*/false);
  const std::string_view body = text.substr(eol + 1);
  if (!header.is_object() || header.value("schema_version", json()) != rc::kVectorSchemaVersion) {
    OracleViolation("accepted a file whose header is not of schema version " +
                    std::to_string(rc::kVectorSchemaVersion));
  }
  if (header.value("vector_count", json()) != vectors) {
    OracleViolation("accepted " + std::to_string(vectors) + " vectors where the header states another count");
  }
  if (!body.empty() && body.back() != '\n') {
    OracleViolation("accepted a file whose last line has no line end");
  }
  if (header.value("vectors_sha256", json()) != rc::Sha256Hex(body)) {
    OracleViolation("accepted a file whose vector lines do not match its vectors_sha256");
  }
}

// ---- the structure-aware mutator ----------------------------------------------------------
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t Next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  std::size_t Below(std::size_t bound) { return bound == 0 ? 0 : static_cast<std::size_t>(Next() % bound); }
};

// The lines of text, each with its newline (the last one may have none).
std::vector<std::string> Lines(std::string_view text) {
  std::vector<std::string> lines;
  for (std::size_t begin = 0; begin < text.size();) {
    const std::size_t end = text.find('\n', begin);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
    lines.emplace_back(text.substr(begin, stop - begin));
    begin = stop;
  }
  return lines;
}

// libFuzzer's byte mutation of one line (its newline kept out of reach), within `budget` bytes.
void MutateLine(std::string& line, std::size_t budget) {
  const bool newline = !line.empty() && line.back() == '\n';
  std::string content = line.substr(0, line.size() - (newline ? 1 : 0));
  const std::size_t capacity = std::max(content.size(), budget) + 1;
  content.resize(capacity);
  const std::size_t n = LLVMFuzzerMutate(reinterpret_cast<std::uint8_t*>(content.data()),
                                         line.size() - (newline ? 1 : 0), capacity);
  content.resize(std::min(n, capacity));
  line = content + (newline ? "\n" : "");
}

// The header line with vector_count and vectors_sha256 of the lines after it (unchanged if
// the header is not a JSON object).
std::string Sealed(const std::vector<std::string>& lines) {
  std::string body;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    body += lines[i];
  }
  json header = json::parse(lines.empty() ? std::string() : lines[0], nullptr, /*allow_exceptions=*/false);
  if (!header.is_object()) {
    return (lines.empty() ? std::string() : lines[0]) + body;
  }
  header["vector_count"] = std::count(body.begin(), body.end(), '\n');
  header["vectors_sha256"] = rc::Sha256Hex(body);
  return header.dump(-1, ' ', false, json::error_handler_t::replace) + "\n" + body;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Reader reader = ReaderOf(text);
  if (reader == Reader::kTg) {
    rc::VectorSet set;
    std::string error;
    if (rc::ParseVectorFile(kFile, text, set, error)) {
      CheckAccepted(text, set.vectors.size());
    } else {
      CheckReason(error);
    }
    return 0;
  }
  rc::VectorFile file;
  if (const std::string error = rc::ReadVectorFile(kFile, text, KeysOf(reader), file); !error.empty()) {
    CheckReason(error);
  } else {
    CheckAccepted(text, file.vectors.size());
  }
  return 0;
}

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  SplitMix64 rng{seed};
  const std::size_t op = rng.Below(16);
  if (op == 0 || size == 0) {
    return LLVMFuzzerMutate(data, size, max_size);  // the bytes of the whole file, seal and all
  }
  std::vector<std::string> lines = Lines(std::string_view(reinterpret_cast<const char*>(data), size));
  const std::size_t budget = max_size > size ? max_size - size : 0;
  if (op <= 9 && lines.size() > 1) {  // one vector line
    MutateLine(lines[1 + rng.Below(lines.size() - 1)], budget);
  } else if (op <= 11) {  // the header line
    MutateLine(lines[0], budget);
  } else if (lines.size() > 1) {  // the lines: one dropped, repeated or two swapped
    const std::size_t a = 1 + rng.Below(lines.size() - 1);
    const std::size_t b = 1 + rng.Below(lines.size() - 1);
    switch (op) {
      case 12: lines.erase(lines.begin() + static_cast<std::ptrdiff_t>(a)); break;
      case 13: lines.insert(lines.begin() + static_cast<std::ptrdiff_t>(a), lines[b]); break;
      default: std::swap(lines[a], lines[b]); break;
    }
  }
  std::string out;
  if (rng.Below(8) != 0) {
    out = Sealed(lines);
  } else {
    for (const std::string& l : lines) {
      out += l;
    }
  }
  if (out.size() > max_size) {
    return LLVMFuzzerMutate(data, size, max_size);
  }
  std::copy(out.begin(), out.end(), data);
  return out.size();
}
