// Reader of the conformance vectors (spec/design/tg.md §7).
#include "vector_reader.hpp"

#include <algorithm>
#include <cctype>
#include <limits>
#include <set>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "railproof/testing/vector_file.hpp"

namespace railproof::conformance {
namespace {

using nlohmann::json;
namespace rr = railproof::tg;

// The keys of the tg vector files besides those every vector file has (vector_file.hpp), as
// spec/schemas/vectors_tg.schema.json defines them (the keys of both kinds of step
// together; ParseStep refuses those of the other kind): any other key is refused.
VectorKeys TgVectorKeys() {
  return VectorKeys{
      .header = KeyTree::parse(R"({"unit_scales": null, "parameters": null, "variant": null})"),
      .vector = KeyTree::parse(R"({"role": null})"),
      .step = KeyTree::parse(R"({
          "in": {"ev": null, "tg": {"src": null, "dst": null, "type": null, "seq": null, "echo": null,
          "auth": null, "integrity": null}},
          "out": {"tx": {"seq": null, "echo": null}, "link": null, "eb": null, "tracking": null,
          "verdict": null, "gap": null}
      })")};
}

// Thrown inside this file only; LoadVectorDirectory turns it into an error line.
struct FormatError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

const json& Field(const json& object, const char* key, const std::string& where) {
  if (!object.is_object()) {
    throw FormatError(where + " is not a JSON object");
  }
  const auto it = object.find(key);
  if (it == object.end()) {
    throw FormatError("missing field \"" + std::string(where.empty() ? "" : where + ".") + key + "\"");
  }
  return *it;
}

std::string Name(const std::string& where, const char* key) {
  return where.empty() ? std::string(key) : where + "." + key;
}

std::uint64_t Unsigned(const json& object, const char* key, const std::string& where, std::uint64_t max) {
  const json& v = Field(object, key, where);
  if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<std::int64_t>() >= 0)) {
    throw FormatError("field \"" + Name(where, key) + "\" is not a non-negative integer");
  }
  const auto value = v.get<std::uint64_t>();
  if (value > max) {
    throw FormatError("field \"" + Name(where, key) + "\" = " + std::to_string(value) + " exceeds " +
                      std::to_string(max));
  }
  return value;
}

std::uint32_t U32(const json& object, const char* key, const std::string& where) {
  return static_cast<std::uint32_t>(Unsigned(object, key, where, std::numeric_limits<std::uint32_t>::max()));
}

std::uint16_t U16(const json& object, const char* key, const std::string& where) {
  return static_cast<std::uint16_t>(Unsigned(object, key, where, std::numeric_limits<std::uint16_t>::max()));
}

std::string String(const json& object, const char* key, const std::string& where) {
  const json& v = Field(object, key, where);
  if (!v.is_string()) {
    throw FormatError("field \"" + Name(where, key) + "\" is not a string");
  }
  return v.get<std::string>();
}

bool Bool(const json& object, const char* key, const std::string& where) {
  const json& v = Field(object, key, where);
  if (!v.is_boolean()) {
    throw FormatError("field \"" + Name(where, key) + "\" is not a boolean");
  }
  return v.get<bool>();
}

std::optional<std::uint32_t> OptionalU32(const json& object, const char* key, const std::string& where) {
  const json& v = Field(object, key, where);
  if (v.is_null()) {
    return std::nullopt;
  }
  return U32(object, key, where);
}

template <typename T>
T OneOf(const json& object, const char* key, const std::string& where,
        std::initializer_list<std::pair<const char*, T>> choices) {
  const std::string value = String(object, key, where);
  for (const auto& [name, result] : choices) {
    if (value == name) {
      return result;
    }
  }
  throw FormatError("field \"" + Name(where, key) + "\" has unknown value " + Quoted(value));
}

void OnlyKeys(const json& object, const std::string& where, std::initializer_list<const char*> allowed) {
  for (auto it = object.begin(); it != object.end(); ++it) {
    const std::string& key = it.key();
    if (std::none_of(allowed.begin(), allowed.end(), [&key](const char* a) { return key == a; })) {
      throw FormatError("unknown field " + Quoted(Name(where, key.c_str())));
    }
  }
}

rr::LinkState ParseLink(const json& out, const std::string& where) {
  return OneOf<rr::LinkState>(out, "link", where,
                              {{"NONE", rr::LinkState::kNone}, {"UP", rr::LinkState::kUp}, {"LOST", rr::LinkState::kLost}});
}

void ParseRoleOutputs(const json& out, const std::string& where, rr::Role role, Expected& e) {
  if (out.contains("eb")) {
    e.eb = Bool(out, "eb", where);
  }
  if (out.contains("tracking")) {
    e.abnormal = OneOf<bool>(out, "tracking", where, {{"TRACKED", false}, {"ABNORMAL", true}});
  }
  if (role == rr::Role::kTrain && !e.eb) {
    throw FormatError("missing field \"" + Name(where, "eb") + "\" (train role)");
  }
  if (role == rr::Role::kGround && !e.abnormal) {
    throw FormatError("missing field \"" + Name(where, "tracking") + "\" (ground role)");
  }
}

Step ParseStep(const json& step, std::size_t index, rr::Role role) {
  const std::string where = "steps[" + std::to_string(index) + "]";
  const json& in = Field(step, "in", where);
  const json& out = Field(step, "out", where);
  const std::string win = where + ".in";
  const std::string wout = where + ".out";
  Step s;
  const std::string ev = String(in, "ev", win);
  if (ev == "tick") {
    OnlyKeys(in, win, {"ev"});
    OnlyKeys(out, wout, {"tx", "link", "eb", "tracking"});
    s.kind = Step::Kind::kTick;
    const json& tx = Field(out, "tx", wout);
    s.out.tx_seq = U32(tx, "seq", wout + ".tx");
    s.out.tx_echo = OptionalU32(tx, "echo", wout + ".tx");
  } else if (ev == "rx") {
    OnlyKeys(in, win, {"ev", "tg"});
    OnlyKeys(out, wout, {"verdict", "gap", "link", "eb", "tracking"});
    s.kind = Step::Kind::kRx;
    const json& tg = Field(in, "tg", win);
    const std::string wtg = win + ".tg";
    s.tg.src = U16(tg, "src", wtg);
    s.tg.dst = U16(tg, "dst", wtg);
    s.tg.type = OneOf<rr::TelegramType>(tg, "type", wtg,
                                        {{"CONTROL", rr::TelegramType::kControl},
                                         {"POSITION", rr::TelegramType::kPosition}});
    s.tg.seq = U32(tg, "seq", wtg);
    s.tg.echo = OptionalU32(tg, "echo", wtg);
    s.tg.with_link_key = OneOf<bool>(tg, "auth", wtg, {{"key", true}, {"nokey", false}});
    s.tg.corrupt = OneOf<bool>(tg, "integrity", wtg, {{"ok", false}, {"corrupt", true}});
    const std::string verdict = String(out, "verdict", wout);
    const auto parsed = ParseVerdict(verdict);
    if (!parsed) {
      throw FormatError("field \"" + wout + ".verdict\" has unknown value " + Quoted(verdict));
    }
    s.out.verdict = *parsed;
    s.out.gap = U32(out, "gap", wout);
  } else {
    throw FormatError("field \"" + win + ".ev\" has unknown value " + Quoted(ev));
  }
  s.out.link = ParseLink(out, wout);
  ParseRoleOutputs(out, wout, role, s.out);
  return s;
}

// (kind, schema version, count and digest: ReadVectorFile)
FileHeader ParseHeader(const json& h, const std::string& file) {
  FileHeader fh;
  fh.file = file;
  fh.model = String(h, "model", "");
  fh.model_sha256 = h.contains("model_sha256") && h["model_sha256"].is_string() ? h["model_sha256"].get<std::string>() : "";
  fh.generator = h.contains("generator") && h["generator"].is_string() ? h["generator"].get<std::string>() : "";
  const json& scales = Field(h, "unit_scales", "");
  fh.time_ms_per_tick = U32(scales, "time_ms_per_tick", "unit_scales");
  if (fh.time_ms_per_tick == 0) {
    throw FormatError("unit_scales.time_ms_per_tick must be positive");
  }
  const json& p = Field(h, "parameters", "");
  const std::string wp = "parameters";
  rr::EndpointConfig& e = fh.endpoint;
  e.seq_modulus = Unsigned(p, "seq_modulus", wp, rr::kSeqModulusMax);
  e.seq_window = U32(p, "seq_window", wp);
  e.history_depth = U32(p, "history_depth", wp);
  e.turnaround_ms = U32(p, "turnaround_ms", wp);
  e.link_timeout_ms = U32(p, "link_timeout_ms", wp);
  e.echo_validity_ms = U32(p, "echo_validity_ms", wp);
  e.initial_seq = U32(p, "init_own_seq", wp);
  fh.ground_id = U16(p, "ground_id", wp);
  fh.train_id = U16(p, "train_id", wp);
  return fh;
}

Vector ParseVector(const json& v, const std::string& file, std::size_t line, std::size_t header_index) {
  Vector vec;
  vec.file = file;
  vec.line = line;
  vec.header_index = header_index;
  vec.id = String(v, "id", "");
  if (vec.id.empty()) {
    throw FormatError("field \"id\" is empty");
  }
  vec.test_name = SanitizeTestName(vec.id);
  vec.role = OneOf<rr::Role>(v, "role", "", {{"ground", rr::Role::kGround}, {"train", rr::Role::kTrain}});
  const json& reqs = Field(v, "requirements", "");
  if (!reqs.is_array()) {
    throw FormatError("field \"requirements\" is not an array");
  }
  for (const json& r : reqs) {
    if (!r.is_string()) {
      throw FormatError("field \"requirements\" holds a non-string");
    }
    vec.requirements.push_back(r.get<std::string>());
  }
  vec.goal = v.contains("goal") && v["goal"].is_string() ? v["goal"].get<std::string>() : "";
  vec.kind = v.contains("kind") && v["kind"].is_string() ? v["kind"].get<std::string>() : "";
  const json& steps = Field(v, "steps", "");
  if (!steps.is_array() || steps.empty()) {
    throw FormatError("field \"steps\" is not a non-empty array");
  }
  for (std::size_t i = 0; i < steps.size(); ++i) {
    vec.steps.push_back(ParseStep(steps[i], i, vec.role));
  }
  return vec;
}

}  // namespace

const char* ToString(Verdict verdict) noexcept {
  switch (verdict) {
    case Verdict::kAccept: return "ACCEPT";
    case Verdict::kIntegrity: return "REJ_INTEGRITY";
    case Verdict::kAddress: return "REJ_ADDRESS";
    case Verdict::kAuth: return "REJ_AUTH";
    case Verdict::kRepeated: return "REJ_REPEATED";
    case Verdict::kSequence: return "REJ_SEQUENCE";
    case Verdict::kNoEcho: return "REJ_NO_ECHO";
    case Verdict::kUnknownEcho: return "REJ_UNKNOWN_ECHO";
    case Verdict::kStale: return "REJ_STALE";
  }
  return "INVALID";
}

std::optional<Verdict> ParseVerdict(const std::string& name) {
  for (const Verdict v : {Verdict::kAccept, Verdict::kIntegrity, Verdict::kAddress, Verdict::kAuth, Verdict::kRepeated,
                          Verdict::kSequence, Verdict::kNoEcho, Verdict::kUnknownEcho, Verdict::kStale}) {
    if (name == ToString(v)) {
      return v;
    }
  }
  return std::nullopt;
}

Verdict VerdictOf(rr::RejectReason reason) noexcept {
  switch (reason) {
    case rr::RejectReason::kNone: return Verdict::kAccept;
    case rr::RejectReason::kBadLength:
    case rr::RejectReason::kRsUncorrectable:
    case rr::RejectReason::kBadFormat:
    case rr::RejectReason::kCrcMismatch: return Verdict::kIntegrity;
    case rr::RejectReason::kWrongAddress: return Verdict::kAddress;
    case rr::RejectReason::kAuthFailed: return Verdict::kAuth;
    case rr::RejectReason::kRepeated: return Verdict::kRepeated;
    case rr::RejectReason::kOutOfSequence: return Verdict::kSequence;
    case rr::RejectReason::kNoEcho: return Verdict::kNoEcho;
    case rr::RejectReason::kUnknownEcho: return Verdict::kUnknownEcho;
    case rr::RejectReason::kStale: return Verdict::kStale;
  }
  return Verdict::kIntegrity;
}

std::string SanitizeTestName(const std::string& id) {
  std::string name = id;
  for (char& c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) == 0) {
      c = '_';
    }
  }
  return name;
}

bool ParseVectorFile(const std::string& file_name, const std::string& text, VectorSet& set, std::string& error) {
  VectorFile file;
  if (std::string e = ReadVectorFile(file_name, text, TgVectorKeys(), file); !e.empty()) {
    error = e;
    return false;
  }
  std::set<std::string> names;
  for (const Vector& v : set.vectors) {
    names.insert(v.test_name);
  }
  std::size_t line_no = 1;
  try {
    set.headers.push_back(ParseHeader(file.header, file_name));
    const std::size_t header_index = set.headers.size() - 1;
    for (const VectorLine& line : file.vectors) {
      line_no = line.line;
      Vector v = ParseVector(line.obj, file_name, line_no, header_index);
      if (!names.insert(v.test_name).second) {
        throw FormatError("duplicate vector id / test name \"" + v.test_name + "\"");
      }
      set.vectors.push_back(std::move(v));
    }
  } catch (const json::exception& e) {
    error = file_name + ":" + std::to_string(line_no) + ": malformed: " + e.what();
    return false;
  } catch (const FormatError& e) {
    error = file_name + ":" + std::to_string(line_no) + ": " + e.what();
    return false;
  }
  return true;
}

LoadResult LoadVectorDirectory(const std::filesystem::path& dir) {
  LoadResult result;
  // tg*.jsonl: the telegram-layer vectors (other models' files are replayed by their own
  // runners, e.g. railproof_conformance_mb for mb*.jsonl)
  std::vector<std::filesystem::path> files;
  if (std::string e = ListVectorFiles(dir, "tg", files); !e.empty()) {
    result.error = e;
    return result;
  }
  for (const auto& path : files) {
    std::string text;
    if (std::string e = ReadFileText(path, text); !e.empty()) {
      result.error = e;
      return result;
    }
    if (!ParseVectorFile(path.string(), text, result.set, result.error)) {
      return result;
    }
  }
  if (result.set.vectors.empty()) {
    result.error = "no vector in the " + std::to_string(files.size()) + " tg*.jsonl file(s) of " + dir.string();
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace railproof::conformance
