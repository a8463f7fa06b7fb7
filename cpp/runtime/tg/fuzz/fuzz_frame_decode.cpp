// libFuzzer target: arbitrary received bytes -> DecodeFrame (design §4 checks 1-3) ->
// OpenPayload (check 5) with the fixed fuzz key. Besides the sanitizers, the oracles are:
//  - the length rule of CheckBlockDecoding holds exactly (REQ-TG-018);
//  - decoding is deterministic, and a rejected frame leaves no content behind;
//  - an accepted telegram is one of the corpus catalogue (fuzz_common.hpp): nothing else
//    was ever sealed with the fuzz key, so anything else accepted would be a forgery
//    (REQ-TG-007);
//  - an accepted frame re-encodes to a valid frame with the same header, ciphertext and
//    tag, and the received blocks differ from that encoding in at most t = 8 symbols per
//    block, exactly as many as the decoder reported corrected (REQ-TG-005, REQ-TG-010).
// Any violation prints "railproof-fuzz: oracle violated: ..." and traps.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fuzz_common.hpp"

namespace {

namespace rf = railproof::fuzz;
namespace rr = railproof::tg;

bool SameDecoded(const rr::DecodedFrame& a, const rr::DecodedFrame& b) noexcept {
  return a.header == b.header && a.ciphertext == b.ciphertext && a.tag == b.tag &&
         a.header_bytes == b.header_bytes && a.corrected_symbols == b.corrected_symbols;
}

bool IsWiped(const rr::DecodedFrame& f) noexcept {
  return SameDecoded(f, rr::DecodedFrame{});
}

void CheckAccepted(std::span<const std::uint8_t> rx, const rr::DecodedFrame& frame,
                   std::span<const std::uint8_t> plaintext) noexcept {
  if (!rf::IsCorpusTelegram(frame.header, plaintext)) {
    rf::OracleViolation("accepted telegram not in corpus");
  }
  rr::EncodedFrame again{};
  if (rr::EncodeFrame(frame.header, plaintext, rf::FuzzKey(), again) != rr::EncodeStatus::kOk) {
    rf::OracleViolation("accepted telegram does not re-encode");
  }
  rr::DecodedFrame back{};
  if (rr::DecodeFrame(again.View(), back) != rr::RejectReason::kNone || back.corrected_symbols != 0) {
    rf::OracleViolation("re-encoded frame does not decode cleanly");
  }
  back.corrected_symbols = frame.corrected_symbols;
  if (!SameDecoded(back, frame)) {
    rf::OracleViolation("re-encoded frame differs in header, ciphertext or tag");
  }
  if (again.size != rx.size()) {
    rf::OracleViolation("re-encoded frame has a different block count");
  }
  std::size_t total = 0;
  for (std::size_t b = 0; b < rx.size() / rr::kBlockBytes; ++b) {
    std::size_t differing = 0;
    for (std::size_t i = b * rr::kBlockBytes; i < (b + 1) * rr::kBlockBytes; ++i) {
      differing += again.bytes[i] != rx[i] ? 1U : 0U;
    }
    if (differing > rf::kRsRadius) {
      rf::OracleViolation("accepted block is farther than t symbols from its codeword");
    }
    total += differing;
  }
  if (total != frame.corrected_symbols) {
    rf::OracleViolation("reported corrections differ from the actual distance");
  }
}

}  // namespace

extern "C" std::size_t LLVMFuzzerMutate(std::uint8_t* data, std::size_t size, std::size_t max_size);

extern "C" std::size_t LLVMFuzzerCustomMutator(std::uint8_t* data, std::size_t size, std::size_t max_size,
                                               unsigned int seed) {
  return rf::MutateFrame(data, size, max_size, seed, &LLVMFuzzerMutate);
}

// @verifies REQ-TG-005
// @verifies REQ-TG-007
// @verifies REQ-TG-010
// @verifies REQ-TG-018
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> rx(data, size);
  rr::DecodedFrame frame{};
  const rr::RejectReason decoded = rr::DecodeFrame(rx, frame);

  const bool length_ok = size > 0 && size % rr::kBlockBytes == 0 && size <= rr::kRxMax;
  if (length_ok == (decoded == rr::RejectReason::kBadLength)) {
    rf::OracleViolation("length rule of CheckBlockDecoding");
  }
  rr::DecodedFrame twice{};
  if (rr::DecodeFrame(rx, twice) != decoded || !SameDecoded(frame, twice)) {
    rf::OracleViolation("DecodeFrame is not deterministic");
  }
  if (decoded != rr::RejectReason::kNone) {
    if (decoded != rr::RejectReason::kBadLength && decoded != rr::RejectReason::kRsUncorrectable &&
        decoded != rr::RejectReason::kBadFormat && decoded != rr::RejectReason::kCrcMismatch) {
      rf::OracleViolation("DecodeFrame returned a reason outside checks 1-3");
    }
    if (!IsWiped(frame)) {
      rf::OracleViolation("rejected frame left content behind");
    }
    return 0;
  }
  if (frame.header.payload_len > rr::kPayloadMax) {
    rf::OracleViolation("decoded payload length beyond kPayloadMax");
  }

  std::array<std::uint8_t, rr::kPayloadMax> plaintext{};
  plaintext.fill(0xA5);
  const rr::RejectReason opened = rr::OpenPayload(frame, rf::FuzzKey(), plaintext);
  const auto payload = std::span<const std::uint8_t>(plaintext).first(frame.header.payload_len);
  if (opened == rr::RejectReason::kAuthFailed) {
    if (!std::all_of(payload.begin(), payload.end(), [](std::uint8_t b) { return b == 0; })) {
      rf::OracleViolation("rejected payload is readable");
    }
    return 0;
  }
  if (opened != rr::RejectReason::kNone) {
    rf::OracleViolation("OpenPayload returned a reason other than None or AuthFailed");
  }
  CheckAccepted(rx, frame, payload);
  return 0;
}
