// Frame coding of the radio telegram safety layer (spec/design/tg.md §2-§4):
// header || AEAD ciphertext || tag || CRC-16, cut into 50-byte blocks, each RS(66,50)
// encoded. The receiver side runs checks 1-3 of design §4 as named functions, in order;
// check 5 (authenticity) is OpenPayload. Runtime module: no heap, no exceptions.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "railproof/tg/aead.hpp"
#include "railproof/tg/telegram.hpp"

namespace railproof::tg {

// Bytes on the air: size = number of blocks * 66.
struct EncodedFrame {
  std::array<std::uint8_t, kRxMax> bytes;
  std::size_t size;

  [[nodiscard]] std::span<const std::uint8_t> View() const noexcept {
    return std::span<const std::uint8_t>(bytes).first(size <= bytes.size() ? size : 0);
  }
};

enum class EncodeStatus : std::uint8_t {
  kOk,
  kPayloadTooLong,  // payload longer than kPayloadMax
  kCryptoError,     // libsodium unavailable
  kBadHeader,       // version != kVersion or type not CONTROL/POSITION
};

// The 21 header bytes (associated data) of a header; flags from echo_valid, length from
// header.payload_len.
// @implements REQ-TG-007
std::array<std::uint8_t, kHeaderBytes> SerializeHeader(const TelegramHeader& header) noexcept;

// Builds a frame: header (payload_len := payload.size()), payload encrypted with the
// header as associated data, tag, CRC-16 over everything before it, then RS(66,50) per
// 50-byte block (last block zero-padded). Deterministic: same inputs, same bytes. On any
// status other than kOk, out.size is 0.
// @implements REQ-TG-005
// @implements REQ-TG-007
// @implements REQ-TG-010
// @implements REQ-TG-011
EncodeStatus EncodeFrame(const TelegramHeader& header, std::span<const std::uint8_t> payload,
                         const LinkKey& key, EncodedFrame& out) noexcept;

// Link FEC only: cuts `frame` (1 .. kInnerMax bytes) into 50-byte blocks, zero-pads the
// last one and RS(66,50)-encodes each into out. Returns false (out.size = 0) if the
// length is out of range. EncodeFrame uses it; tests and fuzzers use it to re-encode a
// tampered inner frame.
// @implements REQ-TG-010
bool EncodeBlocks(std::span<const std::uint8_t> frame, EncodedFrame& out) noexcept;

// Result of RS-decoding the received blocks: frame bytes and zero padding.
struct InnerFrame {
  std::array<std::uint8_t, kInnerMax> bytes;
  std::size_t blocks;                 // number of RS blocks received
  std::uint8_t corrected_symbols;     // sum over all blocks

  [[nodiscard]] std::span<const std::uint8_t> Data() const noexcept {
    return std::span<const std::uint8_t>(bytes).first(blocks <= kMaxBlocks ? blocks * kBlockData : 0);
  }
};

// A frame that passed checks 1-3 (design §4). Its content must not be used before
// OpenPayload has authenticated it (REQ-TG-007).
struct DecodedFrame {
  TelegramHeader header;
  std::array<std::uint8_t, kPayloadMax> ciphertext;  // first header.payload_len bytes valid
  std::array<std::uint8_t, kTagBytes> tag;
  std::array<std::uint8_t, kHeaderBytes> header_bytes;
  std::uint8_t corrected_symbols;
};

// Design §4 check 1: length is a positive multiple of 66 and at most kMaxBlocks * 66
// (else kBadLength); every block RS-decodes within 8 corrections (else kRsUncorrectable).
// @implements REQ-TG-005
// @implements REQ-TG-010
// @implements REQ-TG-018
RejectReason CheckBlockDecoding(std::span<const std::uint8_t> rx, InnerFrame& inner) noexcept;

// Design §4 check 2: version, type, flags, payload length, block count = ceil((39+L)/50),
// zero padding after the frame; else kBadFormat. Fills header on success.
// @implements REQ-TG-005
// @implements REQ-TG-018
RejectReason CheckFrameFormat(const InnerFrame& inner, TelegramHeader& header) noexcept;

// Design §4 check 3: CRC-16/IBM-3740 over bytes 0 .. 36+L equals bytes 37+L, 38+L
// (big-endian); else kCrcMismatch. Requires a header that passed CheckFrameFormat.
// @implements REQ-TG-005
// @implements REQ-TG-010
RejectReason CheckFrameCrc(const InnerFrame& inner, const TelegramHeader& header) noexcept;

// Checks 1-3 in order; kNone and out filled on success, otherwise the first failing
// check's reason and out zeroed.
// @implements REQ-TG-005
// @implements REQ-TG-018
RejectReason DecodeFrame(std::span<const std::uint8_t> rx, DecodedFrame& out) noexcept;

// Design §4 check 5: AEAD-opens the payload with the link key; the associated data is the
// serialisation of frame.header, so any field changed after decoding fails too. Writes
// frame.header.payload_len bytes of plaintext. kAuthFailed if the tag does not verify (or
// libsodium is unavailable: fail-safe), kBadLength if plaintext_out is too short,
// kBadFormat if payload_len > kPayloadMax (both before anything is written). On
// kAuthFailed the first payload_len bytes of plaintext_out are zero.
// @implements REQ-TG-007
// @implements REQ-TG-011
RejectReason OpenPayload(const DecodedFrame& frame, const LinkKey& key,
                         std::span<std::uint8_t> plaintext_out) noexcept;

}  // namespace railproof::tg
