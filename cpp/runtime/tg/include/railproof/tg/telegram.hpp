// Telegram types, fixed capacities and typed rejection reasons of the radio telegram
// safety layer. Frame layout: spec/design/tg.md §2; receiver checks: §4.
// Runtime module: no heap, no exceptions, every size fixed at compile time.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "railproof/core/enum_names.hpp"
#include "railproof/generated/tg_params.hpp"

namespace railproof::tg {

// @implements REQ-TG-008
enum class TelegramType : std::uint8_t {
  kControl = 1,   // ground -> train
  kPosition = 2,  // train -> ground
};

// Application-level header (design §2, bytes 0-20 on the air; flags and payload length
// are represented by echo_valid and payload_len).
// @implements REQ-TG-008
struct TelegramHeader {
  std::uint8_t version;
  TelegramType type;
  std::uint16_t src;
  std::uint16_t dst;
  std::uint32_t seq;
  std::uint32_t echo;
  bool echo_valid;
  std::uint32_t timestamp_ms;
  std::uint16_t payload_len;

  friend constexpr bool operator==(const TelegramHeader&, const TelegramHeader&) = default;
};

inline constexpr std::uint8_t kVersion = 1;
inline constexpr std::uint8_t kFlagEchoValid = 0x01;

inline constexpr std::size_t kHeaderBytes = 21;
inline constexpr std::size_t kTagBytes = 16;
inline constexpr std::size_t kCrcBytes = 2;
inline constexpr std::size_t kFrameOverhead = kHeaderBytes + kTagBytes + kCrcBytes;  // 39
inline constexpr std::size_t kPayloadMax =
    static_cast<std::size_t>(params::tg::payload_max_bytes);
inline constexpr std::size_t kFrameMax = kFrameOverhead + kPayloadMax;
inline constexpr std::size_t kBlockData = static_cast<std::size_t>(params::tg::rs_k);
inline constexpr std::size_t kBlockBytes = static_cast<std::size_t>(params::tg::rs_n);
inline constexpr std::size_t kMaxBlocks = (kFrameMax + kBlockData - 1) / kBlockData;
inline constexpr std::size_t kInnerMax = kMaxBlocks * kBlockData;  // frame + padding
inline constexpr std::size_t kRxMax = kMaxBlocks * kBlockBytes;    // largest valid input

static_assert(kFrameOverhead == 39, "design §2: F = 39 + L");
static_assert(kBlockBytes == 66 && kBlockData == 50, "design §1: RS(66,50)");
static_assert(kPayloadMax <= 0xFFFF, "payload length is a 16-bit field");
static_assert(kHeaderBytes <= kBlockData, "the header must lie in block 0");

// Byte offsets of the frame fields (design §2, all integers big-endian).
namespace layout {
inline constexpr std::size_t kVersion = 0;
inline constexpr std::size_t kType = 1;
inline constexpr std::size_t kSrc = 2;
inline constexpr std::size_t kDst = 4;
inline constexpr std::size_t kSeq = 6;
inline constexpr std::size_t kEcho = 10;
inline constexpr std::size_t kTimestamp = 14;
inline constexpr std::size_t kFlags = 18;
inline constexpr std::size_t kPayloadLen = 19;
inline constexpr std::size_t kPayload = 21;
constexpr std::size_t TagOffset(std::size_t payload_len) noexcept { return kPayload + payload_len; }
constexpr std::size_t CrcOffset(std::size_t payload_len) noexcept {
  return kPayload + payload_len + kTagBytes;
}
}  // namespace layout

// Frame length F = 39 + L and its number of RS blocks ceil(F / 50) (design §2).
constexpr std::size_t FrameBytes(std::size_t payload_len) noexcept {
  return kFrameOverhead + payload_len;
}
constexpr std::size_t BlockCount(std::size_t payload_len) noexcept {
  return (FrameBytes(payload_len) + kBlockData - 1) / kBlockData;
}
static_assert(BlockCount(kPayloadMax) == kMaxBlocks);

struct Telegram {
  TelegramHeader header;
  std::array<std::uint8_t, kPayloadMax> payload;
};

// Typed rejection reasons (design §4). kBadLength ... kCrcMismatch come from the frame
// decoder, kAuthFailed from OpenPayload, the others from the receiver state machine.
// @implements REQ-TG-018
enum class RejectReason : std::uint8_t {
  kNone,
  kBadLength,
  kRsUncorrectable,
  kBadFormat,
  kCrcMismatch,
  kWrongAddress,
  kAuthFailed,
  kRepeated,
  kOutOfSequence,
  kNoEcho,
  kUnknownEcho,
  kStale,
};

// Stable names (the rejection column of design §4); "Invalid" for out-of-range values.
// @implements REQ-TG-018
constexpr const char* ToString(RejectReason reason) noexcept {
  return core::EnumName(reason, std::array<const char*, 12>{"None", "BadLength", "RsUncorrectable", "BadFormat", "CrcMismatch", "WrongAddress", "AuthFailed", "Repeated", "OutOfSequence", "NoEcho", "UnknownEcho", "Stale"}, "Invalid");
}

}  // namespace railproof::tg
