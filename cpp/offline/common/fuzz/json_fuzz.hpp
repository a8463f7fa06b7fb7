// Shared pieces of the fuzz targets of the offline tools' input loaders (line, train type,
// line scenario, wheel-rail scenario, timetable; cpp/offline/*/fuzz):
//  - the oracle: a loader given any bytes either accepts them or throws offline::InputError
//    whose message is one line "<file>: <entry>: <reason>" (valid UTF-8, no control
//    character, every part non-empty); any other exception, a message of another form, a
//    crash or undefined behaviour (ASan+UBSan) is a violation. Each violation prints
//    "railproof-fuzz: oracle violated: ..." and traps. The targets add what an accepted file
//    must satisfy (Require);
//  - a structure-aware mutator: the input, or half of the time a text the loader accepted
//    shortly before, is parsed as JSON and mutated as a document (numbers set to boundary
//    and extreme values or to another number of the document, values replaced by another
//    type or by another value of the document, members and elements removed, duplicated,
//    swapped, keys renamed, strings emptied, lengthened, cut or set to a path, deep nesting,
//    a key written twice), so that the fuzzer gets past the parser to the loaders' range and
//    consistency checks, one at a time; one mutation in eight, and any input that is not
//    JSON, is left to libFuzzer's byte mutator (syntax, UTF-8, truncation).
// Header-only; a target defines libFuzzer's entry points with RAILPROOF_FUZZ_JSON_MUTATOR()
// and its own LLVMFuzzerTestOneInput.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <typeinfo>
#include <vector>

#include <nlohmann/json.hpp>

#include "railproof/offline/line.hpp"

namespace railproof::fuzz {

[[noreturn]] inline void OracleViolation(std::string_view what, std::string_view detail = "") {
  std::fprintf(stderr, "railproof-fuzz: oracle violated: %.*s%s%.*s\n", static_cast<int>(what.size()), what.data(),
               detail.empty() ? "" : ": ", static_cast<int>(detail.size()), detail.data());
  std::fflush(stderr);
  __builtin_trap();
}

// A property an accepted input must have.
inline void Require(bool holds, std::string_view what) {
  if (!holds) {
    OracleViolation("accepted input breaks a rule of the loader", what);
  }
}

// The form of a rejection: "<file>: <entry>: <reason>", one line of UTF-8 text.
inline void CheckMessage(const std::string& file, const std::string& msg) {
  try {
    (void)nlohmann::json(msg).dump();  // throws on a byte that is not UTF-8
  } catch (const nlohmann::json::exception&) {
    OracleViolation("message is not UTF-8 text",
                    nlohmann::json(msg).dump(-1, ' ', true, nlohmann::json::error_handler_t::replace));
  }
  if (std::any_of(msg.begin(), msg.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20U || c == 0x7F; })) {
    OracleViolation("message is not one line of text", msg);
  }
  const std::string prefix = file + ": ";
  if (msg.rfind(prefix, 0) != 0) {
    OracleViolation("message does not begin with the file", msg);
  }
  const std::string_view rest = std::string_view(msg).substr(prefix.size());
  const auto sep = rest.find(": ");
  if (sep == std::string_view::npos || sep == 0 || sep + 2 >= rest.size()) {
    OracleViolation("message is not '<file>: <entry>: <reason>'", msg);
  }
}

// The texts the loader accepted most recently (at most 256): the mutator starts from one of
// them half of the time. The corpus fills with rejected variants (every check's error path
// is new coverage) and a mutation of a rejected text is rejected again, mostly by the same
// check; a mutation of an accepted text reaches every check, one at a time.
inline std::vector<std::string>& Accepted() {
  static std::vector<std::string> pool;
  return pool;
}

inline void NoteAccepted(const std::string& text) {
  static std::size_t count = 0;
  std::vector<std::string>& pool = Accepted();
  if (pool.size() < 256) {
    pool.push_back(text);
  } else {
    pool[count % pool.size()] = text;
  }
  ++count;
}

// Runs `load` on `text` (the text of `file`): it returns, or rejects with the project's input
// error in the one form.
template <typename Load>
void CheckLoad(const std::string& file, const std::string& text, Load&& load) {
  try {
    load();
    NoteAccepted(text);
  } catch (const offline::InputError& e) {
    CheckMessage(file, e.what());
  } catch (const std::exception& e) {
    OracleViolation(std::string("rejection is not the project's input error (") + typeid(e).name() + ")", e.what());
  } catch (...) {
    OracleViolation("rejection by an exception of unknown type");
  }
}

// ---- structure-aware mutation ----------------------------------------------------------------

using ByteMutator = std::size_t (*)(std::uint8_t* data, std::size_t size, std::size_t max_size);

namespace detail {

using Json = nlohmann::json;
using Rng = std::minstd_rand;

inline std::size_t Pick(Rng& rng, std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>(rng()) % n; }

// Deepest nesting of brackets outside strings (the parser is iterative, but dump() recurses).
inline std::size_t Nesting(const std::uint8_t* data, std::size_t size) {
  std::size_t depth = 0;
  std::size_t deepest = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (in_string) {
      if (c == '\\') {
        ++i;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
    } else if ((c == ']' || c == '}') && depth > 0) {
      --depth;
    }
  }
  return deepest;
}

// Every value of the document (pre-order), and what it holds: the pools the mutations draw
// from, so that a mutated value is often one that means something elsewhere in the file (an
// id, a station, a boundary).
struct Pools {
  std::vector<Json*> nodes;
  std::vector<Json> numbers;
  std::vector<std::string> strings;
  std::vector<std::string> keys;
};

inline Pools Collect(Json& root) {
  Pools p;
  std::vector<Json*> todo{&root};
  while (!todo.empty()) {
    Json* n = todo.back();
    todo.pop_back();
    p.nodes.push_back(n);
    if (n->is_number()) {
      p.numbers.push_back(*n);
    } else if (n->is_string()) {
      p.strings.push_back(n->get<std::string>());
    } else if (n->is_object()) {
      for (auto it = n->begin(); it != n->end(); ++it) {
        p.keys.push_back(it.key());
        todo.push_back(&it.value());
      }
    } else if (n->is_array()) {
      for (auto& e : *n) {
        todo.push_back(&e);
      }
    }
  }
  return p;
}

inline Json InterestingNumber(Rng& rng) {
  constexpr std::int64_t kI64Max = std::numeric_limits<std::int64_t>::max();
  constexpr std::int64_t kI64Min = std::numeric_limits<std::int64_t>::min();
  switch (Pick(rng, 24)) {
    case 0: return 0;
    case 1: return -1;
    case 2: return 1;
    case 3: return 0.5;
    case 4: return -0.0;
    case 5: return std::int64_t{2147483647};
    case 6: return std::int64_t{2147483648};
    case 7: return std::int64_t{9007199254740993};
    case 8: return kI64Max;
    case 9: return kI64Min;
    case 10: return std::numeric_limits<std::uint64_t>::max();
    case 11: return std::uint64_t{9223372036854775808U};
    case 12: return 1e300;
    case 13: return -1e300;
    case 14: return std::numeric_limits<double>::max();
    case 15: return std::numeric_limits<double>::denorm_min();
    case 16: return 1e-300;
    case 17: return std::int64_t{10'000'000'000};
    case 18: return std::int64_t{10'000'000'001};
    case 19: return 65535;
    case 20: return 65536;
    case 21: return 604800;
    case 22: return 3600000;
    default: return 1e7;
  }
}

// A number derived from `v`: a neighbour, a multiple, the negation.
inline Json NearNumber(const Json& v, Rng& rng) {
  if (v.is_number_integer() || v.is_number_unsigned()) {
    const auto i = v.is_number_unsigned() ? static_cast<std::int64_t>(v.get<std::uint64_t>() >> 1U) : v.get<std::int64_t>();
    const std::int64_t small = std::clamp<std::int64_t>(i, -1'000'000'000'000, 1'000'000'000'000);
    switch (Pick(rng, 6)) {
      case 0: return small + 1;
      case 1: return small - 1;
      case 2: return small * 1000;
      case 3: return -small;
      case 4: return static_cast<double>(small) + 0.5;
      default: return small / 2;
    }
  }
  const double d = v.get<double>();
  switch (Pick(rng, 5)) {
    case 0: return d * 1e6;
    case 1: return -d;
    case 2: return d + 1.0;
    case 3: return d / 1e6;
    default: return std::nextafter(d, 1e308);
  }
}

inline Json AnyValue(const Pools& p, Rng& rng) {
  switch (Pick(rng, 10)) {
    case 0: return nullptr;
    case 1: return true;
    case 2: return "";
    case 3: return Json::array();
    case 4: return Json::object();
    case 5: return InterestingNumber(rng);
    case 6: return p.strings.empty() ? Json("x") : Json(p.strings[Pick(rng, p.strings.size())]);
    case 7: return p.numbers.empty() ? Json(0) : p.numbers[Pick(rng, p.numbers.size())];
    default: return *p.nodes[Pick(rng, p.nodes.size())];  // a copy of another part of the document
  }
}

inline std::string MutatedString(const std::string& s, const Pools& p, Rng& rng) {
  switch (Pick(rng, 8)) {
    case 0: return "";
    case 1: return std::string(4096, 'x');
    case 2: return "../" + s;
    case 3: return s + "\n" + s;
    case 4: return s + "\xc3\xa9";
    case 5: return s.empty() ? s : s.substr(0, s.size() - 1);
    default: return p.strings.empty() ? s : p.strings[Pick(rng, p.strings.size())];
  }
}

// A member to be written twice is copied under its key with this character in front; the
// dump shows it as the escape "\u0001", which WriteTwice removes.
inline constexpr char kTwice = '\x01';

inline void MutateOnce(Json& root, Rng& rng) {
  Pools p = Collect(root);
  // two in three mutations change a number or a string: the values the checks are about
  std::vector<Json*> leaves;
  for (Json* node : p.nodes) {
    if (node->is_number() || node->is_string()) {
      leaves.push_back(node);
    }
  }
  Json& n = !leaves.empty() && Pick(rng, 3) != 0 ? *leaves[Pick(rng, leaves.size())] : *p.nodes[Pick(rng, p.nodes.size())];
  switch (Pick(rng, 8)) {
    case 0:  // a number: boundary, extreme, neighbour or another of the document
      if (n.is_number()) {
        n = Pick(rng, 3) == 0 ? InterestingNumber(rng)
            : Pick(rng, 2) == 0 && !p.numbers.empty() ? p.numbers[Pick(rng, p.numbers.size())]
                                                     : NearNumber(n, rng);
        return;
      }
      break;
    case 1:  // a string
      if (n.is_string()) {
        n = MutatedString(n.get<std::string>(), p, rng);
        return;
      }
      break;
    case 2:  // a member: removed, added with a key of the document, renamed, written twice
      if (n.is_object()) {
        if (!n.empty() && Pick(rng, 3) == 0) {
          auto it = n.begin();
          std::advance(it, static_cast<std::ptrdiff_t>(Pick(rng, n.size())));
          if (Pick(rng, 2) == 0) {
            n.erase(it);
          } else {
            n[kTwice + it.key()] = it.value();  // the same key twice (WriteTwice)
          }
        } else if (!p.keys.empty()) {
          const std::string& key = p.keys[Pick(rng, p.keys.size())];
          n[Pick(rng, 4) == 0 ? key + "_" : key] = AnyValue(p, rng);
        }
        return;
      }
      break;
    case 3:  // an element: removed, duplicated, swapped, or the array emptied
      if (n.is_array() && !n.empty()) {
        const std::size_t i = Pick(rng, n.size());
        switch (Pick(rng, 4)) {
          case 0: n.erase(i); break;
          case 1: n.insert(n.begin() + static_cast<std::ptrdiff_t>(i), n[i]); break;
          case 2: std::swap(n[i], n[Pick(rng, n.size())]); break;
          default: n = Json::array(); break;
        }
        return;
      }
      break;
    case 4: {  // deep nesting around a value
      Json v = n;
      const std::size_t levels = 60 + Pick(rng, 10);
      for (std::size_t i = 0; i < levels; ++i) {
        v = Json::array({std::move(v)});
      }
      n = std::move(v);
      return;
    }
    default:
      break;
  }
  n = AnyValue(p, rng);  // a value of another type or another part of the document
}

// `text` with every member marked kTwice under the key it copies: the same key twice in one
// object, which a JSON value cannot hold.
inline std::string WriteTwice(std::string text) {
  constexpr std::string_view kMark = "\\u0001";
  for (auto at = text.find(kMark); at != std::string::npos; at = text.find(kMark, at)) {
    text.erase(at, kMark.size());
  }
  return text;
}

}  // namespace detail

// The mutator of a loader's fuzz target (LLVMFuzzerCustomMutator).
inline std::size_t MutateJson(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed,
                              ByteMutator bytes) {
  detail::Rng rng(seed == 0 ? 1U : seed);
  if (detail::Pick(rng, 8) == 0 || detail::Nesting(data, size) > 100) {
    return bytes(data, size, max_size);
  }
  const std::vector<std::string>& accepted = Accepted();
  if (!accepted.empty() && detail::Pick(rng, 2) == 0) {
    const std::string& base = accepted[detail::Pick(rng, accepted.size())];
    if (base.size() <= max_size) {
      std::memcpy(data, base.data(), base.size());
      size = base.size();
    }
  }
  detail::Json doc = detail::Json::parse(data, data + size, nullptr, false);
  if (doc.is_discarded()) {
    return bytes(data, size, max_size);
  }
  const std::size_t rounds = detail::Pick(rng, 3) == 0 ? 2 : 1;
  for (std::size_t i = 0; i < rounds; ++i) {
    detail::MutateOnce(doc, rng);
  }
  // a string cut inside a character is written with U+FFFD (the byte mutator makes bad UTF-8)
  const int indent = detail::Pick(rng, 2) == 0 ? -1 : 1;
  const std::string text = detail::WriteTwice(doc.dump(indent, ' ', false, detail::Json::error_handler_t::replace));
  if (text.size() > max_size) {
    return bytes(data, size, max_size);
  }
  std::memcpy(data, text.data(), text.size());
  return text.size();
}

// One input of a loader's target (its LLVMFuzzerTestOneInput): `load(text)` reads the input
// as the text of `file` and checks what it accepted, under the oracle of CheckLoad.
template <typename Load>
int TestOneInput(const std::string& file, const std::uint8_t* data, std::size_t size, Load&& load) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  CheckLoad(file, text, [&] { load(text); });
  return 0;
}

}  // namespace railproof::fuzz

// libFuzzer's custom mutator of a loader's target: MutateJson over libFuzzer's byte mutator.
#define RAILPROOF_FUZZ_JSON_MUTATOR()                                                                          \
  extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);          \
  extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,    \
                                                 unsigned int seed) {                                          \
    return railproof::fuzz::MutateJson(data, size, max_size, seed, &LLVMFuzzerMutate);                         \
  }
