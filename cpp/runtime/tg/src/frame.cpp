// Frame coding and receiver checks 1-3 of spec/design/tg.md §2-§4.
#include "railproof/tg/frame.hpp"

#include "railproof/tg/crc16.hpp"
#include "railproof/tg/reed_solomon.hpp"

namespace railproof::tg {
namespace {

void PutU16(std::span<std::uint8_t> out, std::size_t at, std::uint16_t v) noexcept {
  out[at] = static_cast<std::uint8_t>(v >> 8U);
  out[at + 1] = static_cast<std::uint8_t>(v);
}

void PutU32(std::span<std::uint8_t> out, std::size_t at, std::uint32_t v) noexcept {
  out[at] = static_cast<std::uint8_t>(v >> 24U);
  out[at + 1] = static_cast<std::uint8_t>(v >> 16U);
  out[at + 2] = static_cast<std::uint8_t>(v >> 8U);
  out[at + 3] = static_cast<std::uint8_t>(v);
}

std::uint16_t GetU16(std::span<const std::uint8_t> in, std::size_t at) noexcept {
  return static_cast<std::uint16_t>((static_cast<unsigned>(in[at]) << 8U) | in[at + 1]);
}

std::uint32_t GetU32(std::span<const std::uint8_t> in, std::size_t at) noexcept {
  return (static_cast<std::uint32_t>(in[at]) << 24U) | (static_cast<std::uint32_t>(in[at + 1]) << 16U) |
         (static_cast<std::uint32_t>(in[at + 2]) << 8U) | static_cast<std::uint32_t>(in[at + 3]);
}

constexpr bool IsKnownType(std::uint8_t type) noexcept {
  return type == static_cast<std::uint8_t>(TelegramType::kControl) ||
         type == static_cast<std::uint8_t>(TelegramType::kPosition);
}

template <typename T>
void Wipe(T& object) noexcept {
  object = T{};
}

}  // namespace

// @implements REQ-TG-007
std::array<std::uint8_t, kHeaderBytes> SerializeHeader(const TelegramHeader& header) noexcept {
  std::array<std::uint8_t, kHeaderBytes> bytes{};
  bytes[layout::kVersion] = header.version;
  bytes[layout::kType] = static_cast<std::uint8_t>(header.type);
  PutU16(bytes, layout::kSrc, header.src);
  PutU16(bytes, layout::kDst, header.dst);
  PutU32(bytes, layout::kSeq, header.seq);
  PutU32(bytes, layout::kEcho, header.echo);
  PutU32(bytes, layout::kTimestamp, header.timestamp_ms);
  bytes[layout::kFlags] = header.echo_valid ? kFlagEchoValid : std::uint8_t{0};
  PutU16(bytes, layout::kPayloadLen, header.payload_len);
  return bytes;
}

// @implements REQ-TG-010
bool EncodeBlocks(std::span<const std::uint8_t> frame, EncodedFrame& out) noexcept {
  out.size = 0;
  if (frame.empty() || frame.size() > kInnerMax) {
    return false;
  }
  const std::size_t blocks = (frame.size() + kBlockData - 1) / kBlockData;
  for (std::size_t b = 0; b < blocks; ++b) {
    std::array<std::uint8_t, kBlockData> data{};  // zero padding of the last block
    const std::size_t begin = b * kBlockData;
    const std::size_t count = frame.size() - begin < kBlockData ? frame.size() - begin : kBlockData;
    for (std::size_t i = 0; i < count; ++i) {
      data[i] = frame[begin + i];
    }
    const auto codeword = std::span<std::uint8_t>(out.bytes).subspan(b * kBlockBytes, kBlockBytes);
    if (Rs6650().Encode(data, codeword) != RsStatus::kOk) {
      return false;  // GCOVR_EXCL_LINE defensive: sizes are fixed at 50 and 66
    }
  }
  out.size = blocks * kBlockBytes;
  return true;
}

// @implements REQ-TG-005
// @implements REQ-TG-007
// @implements REQ-TG-010
// @implements REQ-TG-011
EncodeStatus EncodeFrame(const TelegramHeader& header, std::span<const std::uint8_t> payload,
                         const LinkKey& key, EncodedFrame& out) noexcept {
  out.size = 0;
  if (payload.size() > kPayloadMax) {
    return EncodeStatus::kPayloadTooLong;
  }
  if (header.version != kVersion || !IsKnownType(static_cast<std::uint8_t>(header.type))) {
    return EncodeStatus::kBadHeader;
  }
  TelegramHeader h = header;
  h.payload_len = static_cast<std::uint16_t>(payload.size());
  const std::size_t len = payload.size();

  std::array<std::uint8_t, kInnerMax> frame{};
  const auto header_bytes = SerializeHeader(h);
  for (std::size_t i = 0; i < kHeaderBytes; ++i) {
    frame[i] = header_bytes[i];
  }
  const auto frame_span = std::span<std::uint8_t>(frame);
  const AeadStatus sealed =
      Seal(key, DeriveNonce(h), header_bytes, payload, frame_span.subspan(layout::kPayload, len),
           frame_span.subspan(layout::TagOffset(len)).first<kTagBytes>());
  if (sealed != AeadStatus::kOk) {
    return EncodeStatus::kCryptoError;  // GCOVR_EXCL_LINE defensive: libsodium unavailable
  }
  const std::size_t crc_at = layout::CrcOffset(len);
  PutU16(frame_span, crc_at, Crc16(frame_span.first(crc_at)));
  if (!EncodeBlocks(frame_span.first(FrameBytes(len)), out)) {
    return EncodeStatus::kPayloadTooLong;  // GCOVR_EXCL_LINE defensive: length checked above
  }
  return EncodeStatus::kOk;
}

// Design §4 check 1.
// @implements REQ-TG-005
// @implements REQ-TG-010
// @implements REQ-TG-018
RejectReason CheckBlockDecoding(std::span<const std::uint8_t> rx, InnerFrame& inner) noexcept {
  Wipe(inner);
  if (rx.empty() || rx.size() % kBlockBytes != 0 || rx.size() > kRxMax) {
    return RejectReason::kBadLength;
  }
  const std::size_t blocks = rx.size() / kBlockBytes;
  unsigned corrected = 0;
  for (std::size_t b = 0; b < blocks; ++b) {
    std::array<std::uint8_t, kBlockBytes> codeword{};
    for (std::size_t i = 0; i < kBlockBytes; ++i) {
      codeword[i] = rx[b * kBlockBytes + i];
    }
    const RsDecodeResult result = Rs6650().Decode(codeword);
    if (result.status != RsStatus::kOk && result.status != RsStatus::kCorrected) {
      Wipe(inner);
      return RejectReason::kRsUncorrectable;
    }
    corrected += result.corrected_symbols;
    for (std::size_t i = 0; i < kBlockData; ++i) {
      inner.bytes[b * kBlockData + i] = codeword[i];
    }
  }
  inner.blocks = blocks;
  inner.corrected_symbols = static_cast<std::uint8_t>(corrected);  // <= 4 blocks * 8
  return RejectReason::kNone;
}

// Design §4 check 2.
// @implements REQ-TG-005
// @implements REQ-TG-018
RejectReason CheckFrameFormat(const InnerFrame& inner, TelegramHeader& header) noexcept {
  Wipe(header);
  if (inner.blocks == 0 || inner.blocks > kMaxBlocks) {
    return RejectReason::kBadFormat;  // not produced by CheckBlockDecoding
  }
  const auto data = inner.Data();
  const std::uint8_t version = data[layout::kVersion];
  const std::uint8_t type = data[layout::kType];
  const std::uint8_t flags = data[layout::kFlags];
  const std::uint16_t payload_len = GetU16(data, layout::kPayloadLen);
  if (version != kVersion) {
    return RejectReason::kBadFormat;
  }
  if (!IsKnownType(type)) {
    return RejectReason::kBadFormat;
  }
  if ((flags & static_cast<std::uint8_t>(~kFlagEchoValid)) != 0) {
    return RejectReason::kBadFormat;
  }
  if (payload_len > kPayloadMax) {
    return RejectReason::kBadFormat;
  }
  if (inner.blocks != BlockCount(payload_len)) {
    return RejectReason::kBadFormat;
  }
  for (std::size_t i = FrameBytes(payload_len); i < data.size(); ++i) {
    if (data[i] != 0) {
      return RejectReason::kBadFormat;
    }
  }
  header.version = version;
  header.type = static_cast<TelegramType>(type);
  header.src = GetU16(data, layout::kSrc);
  header.dst = GetU16(data, layout::kDst);
  header.seq = GetU32(data, layout::kSeq);
  header.echo = GetU32(data, layout::kEcho);
  header.echo_valid = (flags & kFlagEchoValid) != 0;
  header.timestamp_ms = GetU32(data, layout::kTimestamp);
  header.payload_len = payload_len;
  return RejectReason::kNone;
}

// Design §4 check 3.
// @implements REQ-TG-005
// @implements REQ-TG-010
RejectReason CheckFrameCrc(const InnerFrame& inner, const TelegramHeader& header) noexcept {
  const auto data = inner.Data();
  const std::size_t crc_at = layout::CrcOffset(header.payload_len);
  if (header.payload_len > kPayloadMax || crc_at + kCrcBytes > data.size()) {
    return RejectReason::kBadFormat;  // header did not come from CheckFrameFormat
  }
  if (Crc16(data.first(crc_at)) != GetU16(data, crc_at)) {
    return RejectReason::kCrcMismatch;
  }
  return RejectReason::kNone;
}

// @implements REQ-TG-005
// @implements REQ-TG-018
RejectReason DecodeFrame(std::span<const std::uint8_t> rx, DecodedFrame& out) noexcept {
  Wipe(out);
  InnerFrame inner{};
  TelegramHeader header{};
  RejectReason reason = CheckBlockDecoding(rx, inner);
  if (reason == RejectReason::kNone) {
    reason = CheckFrameFormat(inner, header);
  }
  if (reason == RejectReason::kNone) {
    reason = CheckFrameCrc(inner, header);
  }
  if (reason != RejectReason::kNone) {
    return reason;
  }
  const auto data = inner.Data();
  out.header = header;
  for (std::size_t i = 0; i < kHeaderBytes; ++i) {
    out.header_bytes[i] = data[i];
  }
  for (std::size_t i = 0; i < header.payload_len; ++i) {
    out.ciphertext[i] = data[layout::kPayload + i];
  }
  const std::size_t tag_at = layout::TagOffset(header.payload_len);
  for (std::size_t i = 0; i < kTagBytes; ++i) {
    out.tag[i] = data[tag_at + i];
  }
  out.corrected_symbols = inner.corrected_symbols;
  return RejectReason::kNone;
}

// Design §4 check 5 (CheckAuthenticity uses it).
// @implements REQ-TG-007
// @implements REQ-TG-011
RejectReason OpenPayload(const DecodedFrame& frame, const LinkKey& key,
                         std::span<std::uint8_t> plaintext_out) noexcept {
  const std::size_t len = frame.header.payload_len;
  if (len > kPayloadMax) {
    return RejectReason::kBadFormat;
  }
  if (plaintext_out.size() < len) {
    return RejectReason::kBadLength;
  }
  const auto associated = SerializeHeader(frame.header);
  const AeadStatus opened =
      Open(key, DeriveNonce(frame.header), associated, std::span<const std::uint8_t>(frame.ciphertext).first(len),
           frame.tag, plaintext_out.first(len));
  if (opened != AeadStatus::kOk) {
    return RejectReason::kAuthFailed;  // kCryptoUnavailable also rejects: fail-safe
  }
  return RejectReason::kNone;
}

}  // namespace railproof::tg
