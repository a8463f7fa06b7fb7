// Unit tests of the telegram frame coding and receiver checks 1-3 and 5
// (spec/design/tg.md §2-§4).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "railproof/tg/aead.hpp"
#include "railproof/tg/crc16.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/tg/reed_solomon.hpp"
#include "railproof/tg/telegram.hpp"
#include "test_keys.hpp"

namespace railproof::tg {
namespace {

constexpr std::array<std::uint8_t, kKeyBytes> kKeyBytesA = {
    0x1f, 0x3a, 0x55, 0x70, 0x8b, 0xa6, 0xc1, 0xdc, 0xf7, 0x12, 0x2d, 0x48, 0x63, 0x7e, 0x99, 0xb4,
    0xcf, 0xea, 0x05, 0x20, 0x3b, 0x56, 0x71, 0x8c, 0xa7, 0xc2, 0xdd, 0xf8, 0x13, 0x2e, 0x49, 0x64};
constexpr std::array<std::uint8_t, kKeyBytes> kKeyBytesB = test::OneBitApart(kKeyBytesA);

// Payload lengths at the block boundaries: F = 39 + L is 39, 40, 50 (one full block), 51,
// 100, 101, 150, 151 and 167 (= kFrameMax).
constexpr std::array<std::size_t, 9> kBoundaryLengths = {0, 1, 11, 12, 61, 62, 111, 112, 128};

TelegramHeader MakeHeader(TelegramType type = TelegramType::kControl, std::uint32_t seq = 0x01020304U,
                          bool echo_valid = true) {
  TelegramHeader h{};
  h.version = kVersion;
  h.type = type;
  h.src = type == TelegramType::kControl ? 1 : 42;
  h.dst = type == TelegramType::kControl ? 42 : 1;
  h.seq = seq;
  h.echo = 0xA0B0C0D0U;
  h.echo_valid = echo_valid;
  h.timestamp_ms = 0x00ABCDEFU;
  h.payload_len = 0;
  return h;
}

std::vector<std::uint8_t> MakePayload(std::size_t len) {
  std::vector<std::uint8_t> p(len);
  for (std::size_t i = 0; i < len; ++i) {
    p[i] = static_cast<std::uint8_t>(i * 37U + 11U);
  }
  return p;
}

EncodedFrame Encode(const TelegramHeader& h, std::span<const std::uint8_t> payload,
                    const std::array<std::uint8_t, kKeyBytes>& key_bytes = kKeyBytesA) {
  EncodedFrame frame{};
  const LinkKey key(key_bytes);
  EXPECT_EQ(EncodeFrame(h, payload, key, frame), EncodeStatus::kOk);
  return frame;
}

// RS-decodes the frame to its 50-byte-per-block inner form (frame + padding).
InnerFrame Inner(const EncodedFrame& frame) {
  InnerFrame inner{};
  EXPECT_EQ(CheckBlockDecoding(frame.View(), inner), RejectReason::kNone);
  return inner;
}

// Rewrites the CRC of an inner frame for payload length len.
void FixCrc(InnerFrame& inner, std::size_t len) {
  const std::size_t at = layout::CrcOffset(len);
  const std::uint16_t crc = Crc16(std::span<const std::uint8_t>(inner.bytes).first(at));
  inner.bytes[at] = static_cast<std::uint8_t>(crc >> 8U);
  inner.bytes[at + 1] = static_cast<std::uint8_t>(crc);
}

// Re-applies the link FEC to a (tampered) inner frame, keeping its block count.
EncodedFrame Reencode(const InnerFrame& inner) {
  EncodedFrame frame{};
  EXPECT_TRUE(EncodeBlocks(inner.Data(), frame));
  return frame;
}

RejectReason Decode(const EncodedFrame& frame) {
  DecodedFrame out{};
  return DecodeFrame(frame.View(), out);
}

RejectReason DecodeAndOpen(const EncodedFrame& frame, std::vector<std::uint8_t>& plaintext,
                           const std::array<std::uint8_t, kKeyBytes>& key_bytes = kKeyBytesA) {
  DecodedFrame out{};
  const RejectReason decoded = DecodeFrame(frame.View(), out);
  if (decoded != RejectReason::kNone) {
    return decoded;
  }
  plaintext.assign(out.header.payload_len, 0xEE);
  return OpenPayload(out, LinkKey(key_bytes), plaintext);
}

// Corrupts `errors` distinct symbols of block `block` (distinct positions, non-zero error
// values); `salt` varies the pattern.
void CorruptBlock(EncodedFrame& frame, std::size_t block, std::size_t errors, std::size_t salt) {
  for (std::size_t j = 0; j < errors; ++j) {
    const std::size_t pos = (7U * j + salt) % kBlockBytes;  // 7 is coprime to 66: distinct
    frame.bytes[block * kBlockBytes + pos] ^= static_cast<std::uint8_t>(0x11U * (j + 1U) + salt % 3U);
  }
}

// ---------------------------------------------------------------------------------------
// Round trips and layout

// @verifies REQ-TG-005
// @verifies REQ-TG-007
// @verifies REQ-TG-010
TEST(Frame, RoundTripAtBlockBoundaries) {
  for (const std::size_t len : kBoundaryLengths) {
    SCOPED_TRACE(len);
    const auto payload = MakePayload(len);
    const TelegramHeader h = MakeHeader();
    const EncodedFrame frame = Encode(h, payload);
    EXPECT_EQ(frame.size, BlockCount(len) * kBlockBytes);
    DecodedFrame out{};
    ASSERT_EQ(DecodeFrame(frame.View(), out), RejectReason::kNone);
    EXPECT_EQ(out.header.payload_len, len);
    EXPECT_EQ(out.corrected_symbols, 0);
    std::vector<std::uint8_t> plain(len + 3, 0xEE);
    ASSERT_EQ(OpenPayload(out, LinkKey(kKeyBytesA), plain), RejectReason::kNone);
    EXPECT_TRUE(std::equal(payload.begin(), payload.end(), plain.begin()));
    EXPECT_EQ(plain[len], 0xEE) << "OpenPayload wrote past payload_len";
  }
  EXPECT_EQ(BlockCount(0), 1U);
  EXPECT_EQ(BlockCount(11), 1U);
  EXPECT_EQ(BlockCount(12), 2U);
  EXPECT_EQ(BlockCount(61), 2U);
  EXPECT_EQ(BlockCount(62), 3U);
  EXPECT_EQ(BlockCount(128), 4U);
  EXPECT_EQ(kMaxBlocks, 4U);
  EXPECT_EQ(kFrameMax, 167U);
}

// @verifies REQ-TG-005
// @verifies REQ-TG-008
TEST(Frame, HeaderFieldsRoundTripIncludingEchoFlag) {
  std::vector<TelegramHeader> headers;
  headers.push_back(MakeHeader(TelegramType::kControl, 0, false));
  headers.push_back(MakeHeader(TelegramType::kPosition, 0xFFFFFFFFU, true));
  TelegramHeader extreme = MakeHeader(TelegramType::kPosition, 0x80000001U, true);
  extreme.src = 0xFFFF;
  extreme.dst = 0;
  extreme.echo = 0xFFFFFFFFU;
  extreme.timestamp_ms = 0xFFFFFFFFU;
  headers.push_back(extreme);
  TelegramHeader no_echo = MakeHeader(TelegramType::kControl, 7, false);
  no_echo.echo = 0;  // flag clear; the echo field is carried as given
  headers.push_back(no_echo);
  for (TelegramHeader h : headers) {
    const auto payload = MakePayload(20);
    h.payload_len = 999;  // ignored: EncodeFrame takes the length from the payload
    const EncodedFrame frame = Encode(h, payload);
    DecodedFrame out{};
    ASSERT_EQ(DecodeFrame(frame.View(), out), RejectReason::kNone);
    h.payload_len = 20;
    EXPECT_EQ(out.header, h);
    EXPECT_EQ(out.header_bytes, SerializeHeader(h));
  }
}

// @verifies REQ-TG-005
// @verifies REQ-TG-007
// @verifies REQ-TG-010
TEST(Frame, LayoutMatchesDesign) {
  const std::size_t len = 61;
  const auto payload = MakePayload(len);
  const TelegramHeader h = MakeHeader(TelegramType::kPosition, 0x11223344U, true);
  const EncodedFrame frame = Encode(h, payload);
  const InnerFrame inner = Inner(frame);
  ASSERT_EQ(inner.blocks, 2U);
  const std::array<std::uint8_t, kHeaderBytes> expected_header = {
      0x01, 0x02, 0x00, 0x2A, 0x00, 0x01, 0x11, 0x22, 0x33, 0x44, 0xA0,
      0xB0, 0xC0, 0xD0, 0x00, 0xAB, 0xCD, 0xEF, 0x01, 0x00, 0x3D};
  EXPECT_TRUE(std::equal(expected_header.begin(), expected_header.end(), inner.bytes.begin()));
  // Ciphertext and tag are exactly libsodium's, with the header as associated data.
  std::array<std::uint8_t, kPayloadMax> ct{};
  std::array<std::uint8_t, kTagBytes> tag{};
  ASSERT_EQ(Seal(LinkKey(kKeyBytesA), DeriveNonce(h), expected_header, payload,
                 std::span<std::uint8_t>(ct).first(len), tag),
            AeadStatus::kOk);
  EXPECT_TRUE(std::equal(ct.begin(), ct.begin() + len, inner.bytes.begin() + layout::kPayload));
  EXPECT_TRUE(std::equal(tag.begin(), tag.end(), inner.bytes.begin() + static_cast<std::ptrdiff_t>(layout::TagOffset(len))));
  // CRC-16 big-endian over bytes 0 .. 36+L, then zero padding up to 2 * 50.
  const std::uint16_t crc = Crc16(std::span<const std::uint8_t>(inner.bytes).first(37 + len));
  EXPECT_EQ(inner.bytes[37 + len], crc >> 8U);
  EXPECT_EQ(inner.bytes[38 + len], crc & 0xFFU);
  for (std::size_t i = FrameBytes(len); i < 2 * kBlockData; ++i) {
    EXPECT_EQ(inner.bytes[i], 0) << i;
  }
  // Every 66-byte block is the systematic RS(66,50) codeword of its 50 data bytes.
  for (std::size_t b = 0; b < 2; ++b) {
    std::array<std::uint8_t, kBlockBytes> cw{};
    ASSERT_EQ(Rs6650().Encode(std::span<const std::uint8_t>(inner.bytes).subspan(b * kBlockData, kBlockData), cw),
              RsStatus::kOk);
    EXPECT_TRUE(std::equal(cw.begin(), cw.end(), frame.bytes.begin() + static_cast<std::ptrdiff_t>(b * kBlockBytes)));
  }
}

// @verifies REQ-TG-011
// @verifies REQ-TG-018
TEST(Frame, EncodingIsDeterministic) {
  for (const std::size_t len : kBoundaryLengths) {
    const auto payload = MakePayload(len);
    const EncodedFrame a = Encode(MakeHeader(), payload);
    const EncodedFrame b = Encode(MakeHeader(), payload);
    ASSERT_EQ(a.size, b.size);
    EXPECT_TRUE(std::equal(a.bytes.begin(), a.bytes.begin() + static_cast<std::ptrdiff_t>(a.size), b.bytes.begin()));
  }
  // Same payload, next sequence number: a different nonce gives a different ciphertext.
  const auto payload = MakePayload(32);
  const InnerFrame first = Inner(Encode(MakeHeader(TelegramType::kControl, 10), payload));
  const InnerFrame second = Inner(Encode(MakeHeader(TelegramType::kControl, 11), payload));
  EXPECT_FALSE(std::equal(first.bytes.begin() + layout::kPayload, first.bytes.begin() + layout::kPayload + 32,
                          second.bytes.begin() + layout::kPayload));
}

// @verifies REQ-TG-018
TEST(Frame, EncoderRejectsInvalidInput) {
  const LinkKey key(kKeyBytesA);
  EncodedFrame out{};
  out.size = 7;
  const auto too_long = MakePayload(kPayloadMax + 1);
  EXPECT_EQ(EncodeFrame(MakeHeader(), too_long, key, out), EncodeStatus::kPayloadTooLong);
  EXPECT_EQ(out.size, 0U);
  const auto payload = MakePayload(4);
  for (const std::uint8_t version : std::array<std::uint8_t, 3>{0, 2, 255}) {
    TelegramHeader h = MakeHeader();
    h.version = version;
    EXPECT_EQ(EncodeFrame(h, payload, key, out), EncodeStatus::kBadHeader);
  }
  for (const std::uint8_t type : std::array<std::uint8_t, 3>{0, 3, 255}) {
    TelegramHeader h = MakeHeader();
    h.type = static_cast<TelegramType>(type);
    EXPECT_EQ(EncodeFrame(h, payload, key, out), EncodeStatus::kBadHeader);
  }
  EXPECT_FALSE(EncodeBlocks({}, out));
  std::array<std::uint8_t, kInnerMax + 1> big{};
  EXPECT_FALSE(EncodeBlocks(big, out));
  EXPECT_EQ(out.size, 0U);
  EXPECT_TRUE(EncodeBlocks(std::span<const std::uint8_t>(big).first(kInnerMax), out));
  EXPECT_EQ(out.size, kRxMax);
}

// ---------------------------------------------------------------------------------------
// Check 1: CheckBlockDecoding

// @verifies REQ-TG-005
// @verifies REQ-TG-010
TEST(Frame, CorrectsUpToEightSymbolsInEveryBlock) {
  for (const std::size_t len : {std::size_t{0}, std::size_t{61}, std::size_t{128}}) {
    const auto payload = MakePayload(len);
    const EncodedFrame clean = Encode(MakeHeader(), payload);
    const std::size_t blocks = clean.size / kBlockBytes;
    for (std::size_t errors = 1; errors <= 8; ++errors) {
      for (std::size_t salt = 0; salt < 66; salt += 13) {
        SCOPED_TRACE(testing::Message() << "len " << len << " errors " << errors << " salt " << salt);
        EncodedFrame noisy = clean;
        for (std::size_t b = 0; b < blocks; ++b) {
          CorruptBlock(noisy, b, errors, salt + b);
        }
        DecodedFrame out{};
        ASSERT_EQ(DecodeFrame(noisy.View(), out), RejectReason::kNone);
        EXPECT_EQ(out.corrected_symbols, errors * blocks);
        std::vector<std::uint8_t> plain(len);
        ASSERT_EQ(OpenPayload(out, LinkKey(kKeyBytesA), plain), RejectReason::kNone);
        EXPECT_EQ(plain, payload);
      }
    }
  }
}

// @verifies REQ-TG-005
// @verifies REQ-TG-010
TEST(Frame, NineSymbolsInOneBlockAreUncorrectable) {
  const auto payload = MakePayload(128);
  const EncodedFrame clean = Encode(MakeHeader(), payload);
  ASSERT_EQ(clean.size, 4 * kBlockBytes);
  for (std::size_t b = 0; b < 4; ++b) {
    for (std::size_t salt = 0; salt < 66; salt += 5) {
      EncodedFrame noisy = clean;
      CorruptBlock(noisy, b, 9, salt);
      DecodedFrame out{};
      out.corrected_symbols = 99;
      EXPECT_EQ(DecodeFrame(noisy.View(), out), RejectReason::kRsUncorrectable) << b << " " << salt;
      EXPECT_EQ(out.corrected_symbols, 0) << "rejected output must be wiped";
      EXPECT_EQ(out.header, TelegramHeader{});
    }
  }
  // The other blocks being correctable does not matter: one bad block rejects the frame.
  EncodedFrame mixed = clean;
  CorruptBlock(mixed, 0, 8, 1);
  CorruptBlock(mixed, 2, 9, 4);
  EXPECT_EQ(Decode(mixed), RejectReason::kRsUncorrectable);
}

// @verifies REQ-TG-018
TEST(Frame, BadLengthsAreRejected) {
  const EncodedFrame full = Encode(MakeHeader(), MakePayload(128));
  ASSERT_EQ(full.size, kRxMax);
  std::array<std::uint8_t, 7 * kBlockBytes> big{};
  std::copy(full.bytes.begin(), full.bytes.end(), big.begin());
  for (const std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{65}, std::size_t{67},
                                 std::size_t{131}, kRxMax - 1, kRxMax + 1, kRxMax + kBlockBytes,
                                 7 * kBlockBytes}) {
    DecodedFrame out{};
    EXPECT_EQ(DecodeFrame(std::span<const std::uint8_t>(big).first(size), out), RejectReason::kBadLength) << size;
  }
  // Truncated by one byte and oversized by one all-zero (valid) RS block.
  DecodedFrame scratch{};
  EXPECT_EQ(DecodeFrame(std::span<const std::uint8_t>(full.bytes).first(full.size - 1), scratch),
            RejectReason::kBadLength);
  EXPECT_EQ(DecodeFrame(std::span<const std::uint8_t>(big).first(kRxMax + kBlockBytes), scratch),
            RejectReason::kBadLength);
  EXPECT_EQ(DecodeFrame(std::span<const std::uint8_t>(full.bytes).first(full.size), scratch),
            RejectReason::kNone);
}

// ---------------------------------------------------------------------------------------
// Check 2: CheckFrameFormat (CRC and RS recomputed, so only the format is wrong)

RejectReason DecodeWithHeaderByte(std::size_t len, std::size_t offset, std::uint8_t value) {
  InnerFrame inner = Inner(Encode(MakeHeader(), MakePayload(len)));
  inner.bytes[offset] = value;
  FixCrc(inner, len);
  return Decode(Reencode(inner));
}

// @verifies REQ-TG-005
// @verifies REQ-TG-018
TEST(Frame, WrongVersionTypeOrFlagsIsBadFormat) {
  for (const std::uint8_t v : std::array<std::uint8_t, 4>{0, 2, 0x81, 0xFF}) {
    EXPECT_EQ(DecodeWithHeaderByte(5, layout::kVersion, v), RejectReason::kBadFormat) << int{v};
  }
  for (const std::uint8_t t : std::array<std::uint8_t, 4>{0, 3, 4, 0xFF}) {
    EXPECT_EQ(DecodeWithHeaderByte(5, layout::kType, t), RejectReason::kBadFormat) << int{t};
  }
  for (const std::uint8_t f : std::array<std::uint8_t, 4>{0x02, 0x03, 0x80, 0xFF}) {
    EXPECT_EQ(DecodeWithHeaderByte(5, layout::kFlags, f), RejectReason::kBadFormat) << int{f};
  }
  // Control: the same edits that keep the fields valid pass the format check.
  EXPECT_EQ(DecodeWithHeaderByte(5, layout::kFlags, 0x00), RejectReason::kNone);
  EXPECT_EQ(DecodeWithHeaderByte(5, layout::kType, 0x02), RejectReason::kNone);
}

// @verifies REQ-TG-005
// @verifies REQ-TG-018
TEST(Frame, WrongPayloadLengthOrBlockCountIsBadFormat) {
  // Longer than kPayloadMax.
  for (const std::uint16_t l : {std::uint16_t{129}, std::uint16_t{0x0100}, std::uint16_t{0xFFFF}}) {
    InnerFrame inner = Inner(Encode(MakeHeader(), MakePayload(128)));
    inner.bytes[layout::kPayloadLen] = static_cast<std::uint8_t>(l >> 8U);
    inner.bytes[layout::kPayloadLen + 1] = static_cast<std::uint8_t>(l);
    EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kBadFormat) << l;
  }
  // L = 11 fits one block; claiming L = 12 needs two.
  {
    InnerFrame inner = Inner(Encode(MakeHeader(), MakePayload(11)));
    ASSERT_EQ(inner.blocks, 1U);
    inner.bytes[layout::kPayloadLen + 1] = 12;
    EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kBadFormat);
  }
  // L = 61 needs two blocks: the first block alone, and the frame plus one zero block.
  {
    const EncodedFrame two = Encode(MakeHeader(), MakePayload(61));
    ASSERT_EQ(two.size, 2 * kBlockBytes);
    DecodedFrame out{};
    EXPECT_EQ(DecodeFrame(std::span<const std::uint8_t>(two.bytes).first(kBlockBytes), out), RejectReason::kBadFormat);
    EncodedFrame three = two;  // the all-zero word is an RS codeword with zero data
    std::fill(three.bytes.begin() + 2 * kBlockBytes, three.bytes.begin() + 3 * kBlockBytes, std::uint8_t{0});
    three.size = 3 * kBlockBytes;
    EXPECT_EQ(Decode(three), RejectReason::kBadFormat);
  }
  // Shorter L in the same block count: the old tag/CRC bytes become non-zero padding.
  {
    InnerFrame inner = Inner(Encode(MakeHeader(), MakePayload(5)));
    inner.bytes[layout::kPayloadLen + 1] = 4;
    FixCrc(inner, 4);
    EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kBadFormat);
  }
}

// @verifies REQ-TG-005
// @verifies REQ-TG-018
TEST(Frame, NonZeroPaddingIsBadFormat) {
  for (const std::size_t len : {std::size_t{0}, std::size_t{12}, std::size_t{100}}) {
    const InnerFrame clean = Inner(Encode(MakeHeader(), MakePayload(len)));
    for (std::size_t i = FrameBytes(len); i < clean.blocks * kBlockData; ++i) {
      InnerFrame inner = clean;
      inner.bytes[i] = 0x01;
      EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kBadFormat) << len << " " << i;
    }
  }
}

// @verifies REQ-TG-018
TEST(Frame, CheckFunctionsRejectInconsistentInputs) {
  InnerFrame empty{};
  TelegramHeader h{};
  EXPECT_EQ(CheckFrameFormat(empty, h), RejectReason::kBadFormat);
  InnerFrame too_many{};
  too_many.blocks = kMaxBlocks + 1;
  EXPECT_EQ(CheckFrameFormat(too_many, h), RejectReason::kBadFormat);
  const InnerFrame inner = Inner(Encode(MakeHeader(), MakePayload(3)));
  TelegramHeader lying = MakeHeader();
  lying.payload_len = 100;  // CRC position beyond the received blocks
  EXPECT_EQ(CheckFrameCrc(inner, lying), RejectReason::kBadFormat);
  lying.payload_len = 3;
  EXPECT_EQ(CheckFrameCrc(inner, lying), RejectReason::kNone);
  const InnerFrame four = Inner(Encode(MakeHeader(), MakePayload(kPayloadMax)));
  TelegramHeader over = MakeHeader();
  over.payload_len = kPayloadMax + 1;  // its CRC would still lie inside the four blocks
  EXPECT_EQ(CheckFrameCrc(four, over), RejectReason::kBadFormat);
}

// ---------------------------------------------------------------------------------------
// Check 3: CheckFrameCrc

// @verifies REQ-TG-005
// @verifies REQ-TG-010
TEST(Frame, CrcBitFlipsAreCrcMismatch) {
  for (const std::size_t len : {std::size_t{0}, std::size_t{11}, std::size_t{128}}) {
    const InnerFrame clean = Inner(Encode(MakeHeader(), MakePayload(len)));
    const std::size_t crc_at = layout::CrcOffset(len);
    for (std::size_t bit = 0; bit < 16; ++bit) {
      InnerFrame inner = clean;
      inner.bytes[crc_at + bit / 8] ^= static_cast<std::uint8_t>(1U << (bit % 8));
      EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kCrcMismatch) << len << " " << bit;
    }
    // Flips in the header, ciphertext and tag that keep the format valid, CRC unchanged.
    for (const std::size_t at : {layout::kSrc, layout::kSeq + 3, layout::kTimestamp, layout::kPayload,
                                 layout::TagOffset(len) + 15}) {
      InnerFrame inner = clean;
      inner.bytes[at] ^= 0x40;
      EXPECT_EQ(Decode(Reencode(inner)), RejectReason::kCrcMismatch) << len << " at " << at;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Check 5: OpenPayload

// @verifies REQ-TG-007
TEST(Frame, WrongKeyIsAuthFailed) {
  for (const std::size_t len : {std::size_t{0}, std::size_t{1}, std::size_t{128}}) {
    const EncodedFrame frame = Encode(MakeHeader(), MakePayload(len), kKeyBytesB);
    std::vector<std::uint8_t> plain;
    EXPECT_EQ(DecodeAndOpen(frame, plain, kKeyBytesA), RejectReason::kAuthFailed);
    EXPECT_TRUE(std::all_of(plain.begin(), plain.end(), [](std::uint8_t b) { return b == 0; }))
        << "a rejected payload must not be readable";
    EXPECT_EQ(DecodeAndOpen(frame, plain, kKeyBytesB), RejectReason::kNone);
    EXPECT_EQ(plain, MakePayload(len));
  }
}

// @verifies REQ-TG-007
TEST(Frame, TamperedCiphertextOrTagIsAuthFailed) {
  const std::size_t len = 61;
  const InnerFrame clean = Inner(Encode(MakeHeader(), MakePayload(len)));
  std::vector<std::uint8_t> plain;
  for (std::size_t i = layout::kPayload; i < layout::CrcOffset(len); ++i) {
    for (const std::uint8_t mask : std::array<std::uint8_t, 2>{0x01, 0x80}) {
      InnerFrame inner = clean;
      inner.bytes[i] ^= mask;
      FixCrc(inner, len);
      EXPECT_EQ(DecodeAndOpen(Reencode(inner), plain), RejectReason::kAuthFailed) << i;
    }
  }
}

// @verifies REQ-TG-007
// @verifies REQ-TG-011
TEST(Frame, TamperedHeaderIsAuthFailed) {
  for (const std::size_t len : {std::size_t{0}, std::size_t{40}}) {
    const InnerFrame clean = Inner(Encode(MakeHeader(), MakePayload(len)));
    std::vector<std::uint8_t> plain;
    // Every header bit whose flip keeps the format valid (type 1<->2 needs two bits).
    for (std::size_t i = layout::kSrc; i < layout::kFlags; ++i) {
      for (std::size_t bit = 0; bit < 8; ++bit) {
        InnerFrame inner = clean;
        inner.bytes[i] ^= static_cast<std::uint8_t>(1U << bit);
        FixCrc(inner, len);
        EXPECT_EQ(DecodeAndOpen(Reencode(inner), plain), RejectReason::kAuthFailed) << i << " " << bit;
      }
    }
    InnerFrame flag = clean;
    flag.bytes[layout::kFlags] ^= kFlagEchoValid;
    FixCrc(flag, len);
    EXPECT_EQ(DecodeAndOpen(Reencode(flag), plain), RejectReason::kAuthFailed);
    InnerFrame type = clean;
    type.bytes[layout::kType] = static_cast<std::uint8_t>(TelegramType::kPosition);
    FixCrc(type, len);
    EXPECT_EQ(DecodeAndOpen(Reencode(type), plain), RejectReason::kAuthFailed);
  }
}

// @verifies REQ-TG-007
TEST(Frame, HeaderChangedAfterDecodingIsAuthFailed) {
  const EncodedFrame frame = Encode(MakeHeader(), MakePayload(10));
  DecodedFrame clean{};
  ASSERT_EQ(DecodeFrame(frame.View(), clean), RejectReason::kNone);
  std::array<std::uint8_t, kPayloadMax> plain{};
  ASSERT_EQ(OpenPayload(clean, LinkKey(kKeyBytesA), plain), RejectReason::kNone);
  DecodedFrame echo = clean;
  echo.header.echo += 1;
  EXPECT_EQ(OpenPayload(echo, LinkKey(kKeyBytesA), plain), RejectReason::kAuthFailed);
  DecodedFrame stamp = clean;
  stamp.header.timestamp_ms -= 1;
  EXPECT_EQ(OpenPayload(stamp, LinkKey(kKeyBytesA), plain), RejectReason::kAuthFailed);
  DecodedFrame flag = clean;
  flag.header.echo_valid = false;
  EXPECT_EQ(OpenPayload(flag, LinkKey(kKeyBytesA), plain), RejectReason::kAuthFailed);
  DecodedFrame shorter = clean;
  shorter.header.payload_len = 9;
  EXPECT_EQ(OpenPayload(shorter, LinkKey(kKeyBytesA), plain), RejectReason::kAuthFailed);
}

// @verifies REQ-TG-018
TEST(Frame, OpenPayloadRejectsUnusableBuffers) {
  const EncodedFrame frame = Encode(MakeHeader(), MakePayload(10));
  DecodedFrame decoded{};
  ASSERT_EQ(DecodeFrame(frame.View(), decoded), RejectReason::kNone);
  std::array<std::uint8_t, 9> small{};
  EXPECT_EQ(OpenPayload(decoded, LinkKey(kKeyBytesA), small), RejectReason::kBadLength);
  DecodedFrame bogus = decoded;
  bogus.header.payload_len = kPayloadMax + 1;
  std::array<std::uint8_t, kPayloadMax + 1> large{};
  EXPECT_EQ(OpenPayload(bogus, LinkKey(kKeyBytesA), large), RejectReason::kBadFormat);
}

// @verifies REQ-TG-018
TEST(Frame, RejectReasonNamesAreDistinct) {
  constexpr std::array<RejectReason, 12> kAll = {
      RejectReason::kNone,          RejectReason::kBadLength,  RejectReason::kRsUncorrectable,
      RejectReason::kBadFormat,     RejectReason::kCrcMismatch, RejectReason::kWrongAddress,
      RejectReason::kAuthFailed,    RejectReason::kRepeated,   RejectReason::kOutOfSequence,
      RejectReason::kNoEcho,        RejectReason::kUnknownEcho, RejectReason::kStale};
  for (std::size_t i = 0; i < kAll.size(); ++i) {
    for (std::size_t j = i + 1; j < kAll.size(); ++j) {
      EXPECT_STRNE(ToString(kAll[i]), ToString(kAll[j]));
    }
  }
  EXPECT_STREQ(ToString(RejectReason::kRsUncorrectable), "RsUncorrectable");
  EXPECT_STREQ(ToString(RejectReason::kStale), "Stale");
  EXPECT_STREQ(ToString(static_cast<RejectReason>(200)), "Invalid");
}

}  // namespace
}  // namespace railproof::tg
