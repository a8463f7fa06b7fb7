// libFuzzer target: arbitrary payload bytes -> messages::Decode (railproof/messages/codec.hpp).
// Besides the sanitizers, the oracles are:
//  - decoding is deterministic (a second decoding gives the same verdict and message);
//  - a decoded message is of the type its first byte names, and re-encodes to exactly the
//    input bytes (the layout is a bijection on valid payloads);
//  - a rejection is typed: a named DecodeError, no message left behind, and a field exactly
//    for the field checks (kTooManyEntries .. kUnsorted), a named one;
//  - the bundle decoder agrees with Decode on every payload that is not a BUNDLE (a bundle of
//    one); a decoded BUNDLE holds 2 .. kBundleMax messages and EncodeBundle gives back exactly
//    the input bytes; a rejected one holds nothing and names its reason.
// Any violation prints "railproof-fuzz: oracle violated: ..." and traps.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <span>
#include <variant>

#include "railproof/messages/codec.hpp"

namespace {

namespace rm = railproof::messages;

[[noreturn]] void OracleViolation(const char* what) noexcept {
  std::fprintf(stderr, "railproof-fuzz: oracle violated: %s\n", what);
  std::fflush(stderr);
  __builtin_trap();
}

bool SameBytes(const rm::Payload& p, std::span<const std::uint8_t> bytes) noexcept {
  const auto v = p.View();
  return v.size() == bytes.size() && std::equal(v.begin(), v.end(), bytes.begin());
}

void CheckAccepted(const rm::Decoded& d, std::span<const std::uint8_t> in) noexcept {
  if (std::holds_alternative<std::monostate>(d.message) || d.field != rm::Field::kNone) {
    OracleViolation("accepted without a message, or with a field");
  }
  if (static_cast<std::uint8_t>(rm::TypeOf(d.message)) != in[0]) {
    OracleViolation("decoded message is not of the type its first byte names");
  }
  const rm::Encoded e = rm::Encode(d.message);
  if (!e.Ok()) {
    OracleViolation("decoded message does not re-encode");
  }
  if (!SameBytes(e.payload, in)) {
    OracleViolation("re-encoded message differs from the input bytes");
  }
}

void CheckRejected(const rm::Decoded& d) noexcept {
  if (!std::holds_alternative<std::monostate>(d.message)) {
    OracleViolation("rejection holds a message");
  }
  if (std::strcmp(rm::ToString(d.error), "INVALID") == 0) {
    OracleViolation("rejection reason outside DecodeError");
  }
  const bool field_check = d.error >= rm::DecodeError::kTooManyEntries;
  if (field_check != (d.field != rm::Field::kNone) || std::strcmp(rm::ToString(d.field), "INVALID") == 0) {
    OracleViolation("rejection field missing, unexpected or unnamed");
  }
}

void CheckBundle(std::span<const std::uint8_t> in, const rm::Decoded& plain) noexcept {
  const rm::DecodedBundle b = rm::DecodeBundle(in);
  const bool is_bundle = !in.empty() && in[0] == rm::kBundleType;
  if (!is_bundle) {
    if (b.error != plain.error || b.field != plain.field || b.bundle.size != (plain.Ok() ? 1U : 0U)) {
      OracleViolation("the bundle decoder disagrees with Decode on a plain payload");
    }
    return;
  }
  if (!b.Ok()) {
    if (b.bundle.size != 0 || std::strcmp(rm::ToString(b.error), "INVALID") == 0 || b.entry >= rm::kBundleMax) {
      OracleViolation("bundle rejection holds messages, is unnamed or names no entry");
    }
    return;
  }
  if (b.bundle.size < 2 || b.bundle.size > rm::kBundleMax) {
    OracleViolation("decoded bundle outside 2 .. kBundleMax messages");
  }
  const rm::Encoded e = rm::EncodeBundle(b.bundle.View());
  if (!e.Ok() || !SameBytes(e.payload, in)) {
    OracleViolation("re-encoded bundle differs from the input bytes");
  }
}

}  // namespace

// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-003 REQ-LC-010
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  const rm::Decoded d = rm::Decode(in);
  const rm::Decoded again = rm::Decode(in);
  if (again.error != d.error || again.field != d.field || again.message.index() != d.message.index()) {
    OracleViolation("decoding is not deterministic");
  }
  if (d.Ok()) {
    CheckAccepted(d, in);
    if (!SameBytes(rm::Encode(again.message).payload, in)) {
      OracleViolation("a second decoding re-encodes differently");
    }
  } else {
    CheckRejected(d);
  }
  CheckBundle(in, d);
  return 0;
}
