// Reader of the conformance vectors (JSON Lines, spec/design/tg.md §7): one
// header line per file, then one vector per line. Each file is read whole or not at all by
// ReadVectorFile (railproof/testing/vector_file.hpp: schema version, count, digest,
// duplicate and unknown keys), then the telegram fields are checked here. Test-only code
// (may allocate); it never throws: every problem is reported as a LoadResult error naming
// the file and line.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/telegram.hpp"

namespace railproof::conformance {

// Model verdicts (design §4 / §7).
enum class Verdict : std::uint8_t {
  kAccept,
  kIntegrity,
  kAddress,
  kAuth,
  kRepeated,
  kSequence,
  kNoEcho,
  kUnknownEcho,
  kStale,
};

const char* ToString(Verdict verdict) noexcept;
std::optional<Verdict> ParseVerdict(const std::string& name);
// The C++ rejection reason's verdict (design §7 mapping).
Verdict VerdictOf(tg::RejectReason reason) noexcept;

// Header parameters of one vector file.
struct FileHeader {
  std::string file;
  std::string model;
  std::string model_sha256;
  std::string generator;
  std::uint32_t time_ms_per_tick = 0;
  // the endpoint parameters (init_own_seq as initial_seq); role and ids are the vector's
  tg::EndpointConfig endpoint{};
  std::uint16_t ground_id = 0;
  std::uint16_t train_id = 0;
};

// A telegram delivered to the endpoint under test ("ev":"rx").
struct RxTelegram {
  std::uint16_t src = 0;
  std::uint16_t dst = 0;
  tg::TelegramType type = tg::TelegramType::kControl;
  std::uint32_t seq = 0;
  std::optional<std::uint32_t> echo;  // nullopt: echo flag clear
  bool with_link_key = true;          // "auth":"key" (else the attacker's key)
  bool corrupt = false;               // "integrity":"corrupt"
};

// Expected outputs; eb / abnormal are present as the vector states them (at least the
// role's own one).
struct Expected {
  // tick
  std::uint32_t tx_seq = 0;
  std::optional<std::uint32_t> tx_echo;
  // rx
  Verdict verdict = Verdict::kAccept;
  std::uint32_t gap = 0;
  // both
  tg::LinkState link = tg::LinkState::kNone;
  std::optional<bool> eb;        // "eb"
  std::optional<bool> abnormal;  // "tracking": true for "ABNORMAL"
};

struct Step {
  enum class Kind : std::uint8_t { kTick, kRx };
  Kind kind = Kind::kTick;
  RxTelegram tg;
  Expected out;
};

struct Vector {
  std::string id;
  std::string test_name;  // id with every non-alphanumeric character replaced by '_'
  tg::Role role = tg::Role::kTrain;
  std::vector<std::string> requirements;
  std::string goal;
  std::string kind;
  std::size_t header_index = 0;  // into VectorSet::headers
  std::string file;
  std::size_t line = 0;
  std::vector<Step> steps;
};

struct VectorSet {
  std::vector<FileHeader> headers;
  std::vector<Vector> vectors;
};

struct LoadResult {
  bool ok = false;
  std::string error;  // one line, names the file (and line) at fault
  VectorSet set;
};

std::string SanitizeTestName(const std::string& id);

// Reads every tg*.jsonl file of dir (sorted by name). Fails if dir is missing or not a
// directory, has no *.jsonl file, or holds no vector at all; fails on the first malformed
// line (naming file and line) and on duplicate test names.
LoadResult LoadVectorDirectory(const std::filesystem::path& dir);

// Parses one file's text, appending its header and vectors to set; false and a one-line
// error "<file>:<line>: <reason>" if the file is not whole or not well formed (exposed for
// the reader's fuzz target, cpp/testing/fuzz).
bool ParseVectorFile(const std::string& file_name, const std::string& text, VectorSet& set, std::string& error);

}  // namespace railproof::conformance
