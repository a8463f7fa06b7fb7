// Shared pieces of the radio fuzz targets and of the corpus generator:
//  - the fixed link key every fuzz target uses (and a second, "attacker" key);
//  - the catalogue of corpus telegrams: the only authentic telegrams that may ever be
//    accepted under the fuzz key, because nothing else was ever sealed with it;
//  - a structure-aware mutator that RS-decodes a frame, mutates the inner frame
//    (header, ciphertext, tag, CRC, padding), optionally repairs CRC and block count,
//    re-applies the RS(66,50) code and injects symbol errors, so that the fuzzer reaches
//    checks 2, 3 and 5 of spec/design/tg.md §4 instead of stopping at check 1.
// Header-only and free of libFuzzer symbols, so that plain executables (the corpus
// generator) and further fuzz targets (e.g. one for the receiver state machine) can use it.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

#include "railproof/tg/aead.hpp"
#include "railproof/tg/crc16.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"

namespace railproof::fuzz {

namespace rr = railproof::tg;

// Public test keys: never used outside the fuzz targets and their corpus.
inline constexpr std::array<std::uint8_t, rr::kKeyBytes> kFuzzKeyBytes = {
    0x72, 0x61, 0x69, 0x6c, 0x70, 0x72, 0x6f, 0x6f, 0x66, 0x2d, 0x66, 0x75, 0x7a, 0x7a, 0x2d, 0x6b,
    0x65, 0x79, 0x2d, 0x30, 0x31, 0xa5, 0x5a, 0xc3, 0x3c, 0x96, 0x69, 0x0f, 0xf0, 0x12, 0x34, 0x56};
inline constexpr std::array<std::uint8_t, rr::kKeyBytes> kAttackerKeyBytes = {
    0x61, 0x74, 0x74, 0x61, 0x63, 0x6b, 0x65, 0x72, 0x2d, 0x6b, 0x65, 0x79, 0x2d, 0x30, 0x31, 0x00,
    0xde, 0xad, 0xbe, 0xef, 0x01, 0x23, 0x45, 0x67, 0x89, 0xab, 0xcd, 0xef, 0xfe, 0xdc, 0xba, 0x98};

inline const rr::LinkKey& FuzzKey() noexcept {
  static const rr::LinkKey key(kFuzzKeyBytes);
  return key;
}

// ---- catalogue of corpus telegrams ------------------------------------------------------
// Entry i: type CONTROL (even i, ground -> train) or POSITION (odd i), payload length
// kCorpusLengths[i / 2] (block boundaries), sequence number kCorpusSeqBase + i, and a
// payload that is a fixed function of i.
inline constexpr std::uint32_t kCorpusSeqBase = 0x5EED0000U;
inline constexpr std::array<std::uint16_t, 10> kCorpusLengths = {0, 1, 11, 12, 61, 62, 111, 112, 127, 128};
inline constexpr std::size_t kCorpusTelegrams = 2 * kCorpusLengths.size();
inline constexpr std::uint16_t kGroundId = static_cast<std::uint16_t>(params::tg::ground_id);
inline constexpr std::size_t kRsRadius = static_cast<std::size_t>(params::tg::rs_t);
inline constexpr std::uint16_t kTrainId = static_cast<std::uint16_t>(params::tg::model::model_train_id);

struct CorpusTelegram {
  rr::TelegramHeader header;
  std::array<std::uint8_t, rr::kPayloadMax> payload;  // first header.payload_len bytes
  [[nodiscard]] std::span<const std::uint8_t> Payload() const noexcept {
    return std::span<const std::uint8_t>(payload).first(header.payload_len);
  }
};

// index must be < kCorpusTelegrams; other indices give entry 0.
constexpr CorpusTelegram CorpusEntry(std::size_t index) noexcept {
  if (index >= kCorpusTelegrams) {
    index = 0;
  }
  CorpusTelegram t{};
  const bool control = index % 2 == 0;
  t.header.version = rr::kVersion;
  t.header.type = control ? rr::TelegramType::kControl : rr::TelegramType::kPosition;
  t.header.src = control ? kGroundId : kTrainId;
  t.header.dst = control ? kTrainId : kGroundId;
  t.header.seq = kCorpusSeqBase + static_cast<std::uint32_t>(index);
  t.header.echo = static_cast<std::uint32_t>(0x0BADF00DU + 3U * index);
  t.header.echo_valid = index % 3 != 0;
  t.header.timestamp_ms = static_cast<std::uint32_t>(1000U * index + 250U);
  t.header.payload_len = kCorpusLengths[index / 2];
  for (std::size_t i = 0; i < t.header.payload_len; ++i) {
    t.payload[i] = static_cast<std::uint8_t>(131U * i + 17U * index + 5U);
  }
  return t;
}

// True iff (header, plaintext) is exactly one of the catalogue telegrams.
inline bool IsCorpusTelegram(const rr::TelegramHeader& header, std::span<const std::uint8_t> plaintext) noexcept {
  const std::uint32_t index = header.seq - kCorpusSeqBase;  // wraps for seq < base
  if (index >= kCorpusTelegrams) {
    return false;
  }
  const CorpusTelegram expected = CorpusEntry(index);
  const auto want = expected.Payload();
  return header == expected.header && plaintext.size() == want.size() &&
         std::equal(want.begin(), want.end(), plaintext.begin());
}

// Reports a violated fuzz oracle in a greppable line, then stops the process so that
// libFuzzer records the input as a crash.
[[noreturn]] inline void OracleViolation(const char* what) noexcept {
  std::fprintf(stderr, "railproof-fuzz: oracle violated: %s\n", what);
  std::fflush(stderr);
  __builtin_trap();
}

// ---- frame surgery -----------------------------------------------------------------------

// Writes the CRC-16 of inner frame bytes [0, 37+L) at 37+L if that fits; returns false if not.
inline bool FixCrc(rr::InnerFrame& inner, std::size_t payload_len) noexcept {
  const std::size_t at = rr::layout::CrcOffset(payload_len);
  if (at + rr::kCrcBytes > inner.bytes.size()) {
    return false;
  }
  const std::uint16_t crc = rr::Crc16(std::span<const std::uint8_t>(inner.bytes).first(at));
  inner.bytes[at] = static_cast<std::uint8_t>(crc >> 8U);
  inner.bytes[at + 1] = static_cast<std::uint8_t>(crc);
  return true;
}

inline std::size_t PayloadLenField(const rr::InnerFrame& inner) noexcept {
  return (static_cast<std::size_t>(inner.bytes[rr::layout::kPayloadLen]) << 8U) |
         inner.bytes[rr::layout::kPayloadLen + 1];
}

// Deterministic pseudo-random numbers for the mutator (SplitMix64).
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t Next() noexcept {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31U);
  }
  std::size_t Below(std::size_t bound) noexcept { return bound == 0 ? 0 : static_cast<std::size_t>(Next() % bound); }
  bool Chance(std::size_t one_in) noexcept { return Below(one_in) == 0; }
};

// XORs `errors` distinct symbols of block `block` of an encoded frame with non-zero values.
inline void InjectSymbolErrors(rr::EncodedFrame& frame, std::size_t block, std::size_t errors,
                               SplitMix64& rng) noexcept {
  std::array<bool, rr::kBlockBytes> hit{};
  errors = std::min(errors, rr::kBlockBytes);
  for (std::size_t e = 0; e < errors; ++e) {
    std::size_t pos = rng.Below(rr::kBlockBytes);
    while (hit[pos]) {  // bounded: fewer than kBlockBytes positions are taken
      pos = (pos + 1) % rr::kBlockBytes;
    }
    hit[pos] = true;
    frame.bytes[block * rr::kBlockBytes + pos] ^= static_cast<std::uint8_t>(1U + rng.Below(255));
  }
}

// The byte-level mutator of the fuzzing engine (LLVMFuzzerMutate for libFuzzer).
using RawMutator = std::size_t (*)(std::uint8_t* data, std::size_t size, std::size_t max_size);

// Structure-aware mutation of one frame in data[0, size) (capacity max_size); returns the
// new size. Deterministic in (data, size, max_size, seed) and the raw mutator.
inline std::size_t MutateFrame(std::uint8_t* data, std::size_t size, std::size_t max_size, unsigned seed,
                               RawMutator raw) noexcept {
  SplitMix64 rng{seed};
  if (rng.Chance(8) || max_size < rr::kBlockBytes) {
    return raw(data, size, max_size);  // plain bytes: lengths, RS failures
  }
  // 1. Inner frame: RS-decode the input, or start from a catalogue telegram.
  rr::InnerFrame inner{};
  if (rr::CheckBlockDecoding(std::span<const std::uint8_t>(data, size), inner) != rr::RejectReason::kNone ||
      rng.Chance(16)) {
    const CorpusTelegram seed_telegram = CorpusEntry(rng.Below(kCorpusTelegrams));
    rr::EncodedFrame fresh{};
    if (rr::EncodeFrame(seed_telegram.header, seed_telegram.Payload(), FuzzKey(), fresh) != rr::EncodeStatus::kOk ||
        rr::CheckBlockDecoding(fresh.View(), inner) != rr::RejectReason::kNone) {
      return raw(data, size, max_size);  // unreachable with a working encoder
    }
  }
  std::size_t inner_len = inner.blocks * rr::kBlockData;

  // 2. Mutate the inner frame.
  switch (rng.Below(4)) {
    case 0:
    case 1: {  // generic byte mutation, may change the length
      inner_len = raw(inner.bytes.data(), inner_len, inner.bytes.size());
      inner_len = std::clamp<std::size_t>(inner_len, 1, inner.bytes.size());
      break;
    }
    case 2: {  // one header field to a boundary or random value
      static constexpr std::array<std::size_t, 6> kFields = {rr::layout::kVersion, rr::layout::kType,
                                                             rr::layout::kFlags,   rr::layout::kPayloadLen,
                                                             rr::layout::kPayloadLen + 1, rr::layout::kSeq + 3};
      static constexpr std::array<std::uint8_t, 8> kValues = {0, 1, 2, 3, 0x7F, 0x80, 0xFE, 0xFF};
      const std::size_t at = kFields[rng.Below(kFields.size())];
      inner.bytes[at] = rng.Chance(2) ? kValues[rng.Below(kValues.size())] : static_cast<std::uint8_t>(rng.Next());
      break;
    }
    default: {  // flip one bit anywhere in the frame, padding included
      const std::size_t bit = rng.Below(inner_len * 8);
      inner.bytes[bit / 8] ^= static_cast<std::uint8_t>(1U << (bit % 8));
      break;
    }
  }
  for (std::size_t i = inner_len; i < inner.bytes.size(); ++i) {
    inner.bytes[i] = 0;
  }

  // 3. Repairs, so that later checks are reached: block count and padding from the
  //    length field (usually), then the CRC (usually).
  const std::size_t len = PayloadLenField(inner);
  if (len <= rr::kPayloadMax && !rng.Chance(4)) {
    inner_len = rr::BlockCount(len) * rr::kBlockData;
    for (std::size_t i = rr::FrameBytes(len); i < inner.bytes.size(); ++i) {
      inner.bytes[i] = 0;
    }
  }
  if (len <= rr::kPayloadMax && !rng.Chance(4)) {
    (void)FixCrc(inner, len);
  }

  // 4. Link FEC, then channel noise: mostly within the correction radius, sometimes beyond.
  rr::EncodedFrame out{};
  if (!rr::EncodeBlocks(std::span<const std::uint8_t>(inner.bytes).first(inner_len), out) || out.size > max_size) {
    return raw(data, size, max_size);
  }
  const std::size_t blocks = out.size / rr::kBlockBytes;
  if (rng.Chance(2)) {
    for (std::size_t b = 0; b < blocks; ++b) {
      InjectSymbolErrors(out, b, rng.Below(kRsRadius + 1), rng);  // 0 .. t
    }
    if (rng.Chance(8)) {
      InjectSymbolErrors(out, rng.Below(blocks), kRsRadius + 1 + rng.Below(4), rng);  // beyond t
    }
  }
  std::copy(out.bytes.begin(), out.bytes.begin() + static_cast<std::ptrdiff_t>(out.size), data);
  return out.size;
}

}  // namespace railproof::fuzz
