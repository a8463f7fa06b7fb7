// Receiver and link-supervision state machine of one endpoint (spec/design/tg.md
// §4, §5). Mirror of models/tg.pml: Cycle = tick() (supervise, then r_send),
// Receive = receive(). Checks 1-3 are DecodeFrame's (frame.cpp); checks 4-8 below, each a
// named function, in the order of design §4.
//
// Seeded faults RAILPROOF_FAULT(FAULT_TG_*) (spec/design/seeded-faults.md): active only in the
// test-only schemata variant; the conformance vectors and the unit tests must detect each.
#include "railproof/core/seeded_fault.hpp"
#include "railproof/tg/endpoint.hpp"

namespace railproof::tg {
namespace {

constexpr std::array<std::uint8_t, kKeyBytes> kNoKey{};

// Wrap-safe age of an instant in the past (uint32 ms clock, design §6).
constexpr std::uint32_t Age(std::uint32_t now_ms, std::uint32_t then_ms) noexcept {
  return static_cast<std::uint32_t>(now_ms - then_ms);
}

void Zero(std::span<std::uint8_t> bytes) noexcept {
  for (auto& b : bytes) {
    b = 0;
  }
}

}  // namespace

Endpoint::Endpoint() noexcept
    : config_{},
      key_(kNoKey),
      initialised_(false),
      next_seq_(0),
      sent_(0),
      history_head_(0),
      history_{},
      peer_known_(false),
      peer_fresh_(false),
      peer_seq_(0),
      peer_update_ms_(0),
      link_(LinkState::kNone),
      last_accept_ms_(0) {}

void Endpoint::Reset() noexcept {
  next_seq_ = config_.initial_seq;
  sent_ = 0;
  history_head_ = 0;
  history_ = {};
  peer_known_ = false;
  peer_fresh_ = false;
  peer_seq_ = 0;
  peer_update_ms_ = 0;
  link_ = LinkState::kNone;
  last_accept_ms_ = 0;
}

ConfigError Endpoint::Init(const EndpointConfig& config, const LinkKey& key) noexcept {
  initialised_ = false;
  const ConfigError error = Validate(config);
  if (error != ConfigError::kNone) {
    return error;
  }
  if (CryptoInit() != AeadStatus::kOk) {
    return ConfigError::kCryptoUnavailable;  // GCOVR_EXCL_LINE defensive: libsodium failure
  }
  config_ = config;
  key_ = key;
  Reset();
  initialised_ = true;
  return ConfigError::kNone;
}

std::uint32_t Endpoint::HistoryCount() const noexcept {
  return sent_ < config_.history_depth ? sent_ : config_.history_depth;
}

const Endpoint::HistoryEntry& Endpoint::HistoryBack(std::uint32_t k) const noexcept {
  // history_head_ < history_depth <= kHistoryMax and k < history_depth
  const std::uint32_t depth = config_.history_depth;
  const std::uint32_t index = (history_head_ + depth - 1U - (k % depth)) % depth;
  return history_[index];
}

// Design §5: link supervision, plus the latched expiries of the echo and of own send times.
// Model: supervise() in tick().
// @implements REQ-TG-012
// @implements REQ-TG-013
void Endpoint::Supervise(std::uint32_t now_ms) noexcept {
  if (peer_fresh_ && Age(now_ms, peer_update_ms_) > config_.echo_validity_ms) {
    peer_fresh_ = false;
  }
  const std::uint32_t count = HistoryCount();
  for (std::uint32_t k = 0; k < count; ++k) {  // bounded by history_depth <= kHistoryMax
    const std::uint32_t depth = config_.history_depth;
    HistoryEntry& entry = history_[(history_head_ + depth - 1U - k) % depth];
    if (!entry.expired && Age(now_ms, entry.send_ms) > config_.turnaround_ms) {
      entry.expired = true;
    }
  }
  if (!RAILPROOF_FAULT(FAULT_TG_SKIP_LINK_TIMEOUT) && link_ == LinkState::kUp &&
      Age(now_ms, last_accept_ms_) > config_.link_timeout_ms) {
    link_ = LinkState::kLost;
  }
}

// Sending rule (design §5, REQ-TG-012): echo the last in-sequence peer number while its
// update is at most echo_validity_ms old. Model: r_send().
// @implements REQ-TG-012
bool Endpoint::EchoValid(std::uint32_t now_ms) const noexcept {
  if (RAILPROOF_FAULT(FAULT_TG_ECHO_NEVER_EXPIRES)) {
    return peer_known_;
  }
  return peer_known_ && peer_fresh_ && Age(now_ms, peer_update_ms_) <= config_.echo_validity_ms;
}

Endpoint::CycleOutput Endpoint::MakeCycleOutput(SendStatus status, const TelegramHeader& tx) const noexcept {
  const bool down = link_ != LinkState::kUp;
  return CycleOutput{tx, link_, down, down, status};
}

Endpoint::RxResult Endpoint::MakeRxResult(RejectReason reason, std::uint32_t gap,
                                          const TelegramHeader& header) const noexcept {
  const bool down = link_ != LinkState::kUp;
  return RxResult{reason, gap, link_, down, down, header};
}

// @implements REQ-TG-008
// @implements REQ-TG-012
// @implements REQ-TG-013
// @implements REQ-TG-014
// @implements REQ-TG-015
Endpoint::CycleOutput Endpoint::Cycle(std::uint32_t now_ms, std::span<const std::uint8_t> payload,
                                      EncodedFrame& out_frame) noexcept {
  out_frame.size = 0;
  if (!initialised_) {
    return MakeCycleOutput(SendStatus::kNotInitialised, TelegramHeader{});
  }
  Supervise(now_ms);
  if (payload.size() > kPayloadMax) {
    return MakeCycleOutput(SendStatus::kPayloadTooLong, TelegramHeader{});
  }
  TelegramHeader tx{};
  tx.version = kVersion;
  tx.type = SentType(config_.role);
  tx.src = config_.own_id;
  tx.dst = config_.peer_id;
  tx.seq = next_seq_;
  tx.echo_valid = EchoValid(now_ms);
  tx.echo = tx.echo_valid ? peer_seq_ : 0U;
  tx.timestamp_ms = now_ms;
  tx.payload_len = static_cast<std::uint16_t>(payload.size());
  if (EncodeFrame(tx, payload, key_, out_frame) != EncodeStatus::kOk) {
    out_frame.size = 0;  // GCOVR_EXCL_LINE defensive: libsodium checked at Init
    return MakeCycleOutput(SendStatus::kEncodeFailed, TelegramHeader{});  // GCOVR_EXCL_LINE
  }
  // Send-time ring of the last history_depth own sequence numbers (REQ-TG-008).
  history_[history_head_] = HistoryEntry{tx.seq, now_ms, false};
  history_head_ = (history_head_ + 1U) % config_.history_depth;
  if (sent_ < config_.history_depth) {
    ++sent_;
  }
  next_seq_ = static_cast<std::uint32_t>((std::uint64_t{next_seq_} + 1U) % config_.seq_modulus);
  return MakeCycleOutput(SendStatus::kSent, tx);
}

// Design §4 check 4: source = configured peer, destination = own id, type = the type the
// peer sends.
// @implements REQ-TG-003
RejectReason Endpoint::CheckAddressing(const TelegramHeader& header) const noexcept {
  const bool src_ok = RAILPROOF_FAULT(FAULT_TG_ADDRESS_SRC_IGNORED) || header.src == config_.peer_id;
  if (!src_ok || header.dst != config_.own_id || header.type != ExpectedType(config_.role)) {
    return RejectReason::kWrongAddress;
  }
  return RejectReason::kNone;
}

// Design §4 check 5: AEAD open with the link key (header as associated data).
// @implements REQ-TG-007
// @implements REQ-TG-011
RejectReason Endpoint::CheckAuthenticity(const DecodedFrame& frame, std::span<std::uint8_t> plaintext) const noexcept {
  if (OpenPayload(frame, key_, plaintext) != RejectReason::kNone) {
    return RejectReason::kAuthFailed;
  }
  return RejectReason::kNone;
}

// Design §4 check 6, only while the link is up: d = (seq - peer_seq) mod M; d = 0 repeated,
// d > W out of sequence, else d - 1 telegrams were deleted. The first authentic telegram
// (link NONE) and the first after a loss (link LOST) pass with any number. A number >= M
// cannot come from a genuine peer and is out of sequence (unreachable when M = 2^32).
// @implements REQ-TG-001
// @implements REQ-TG-002
// @implements REQ-TG-004
RejectReason Endpoint::CheckSequenceNumber(std::uint32_t seq, std::uint32_t& gap) const noexcept {
  gap = 0;
  const std::uint64_t modulus = config_.seq_modulus;
  if (seq >= modulus) {
    return RejectReason::kOutOfSequence;
  }
  if (link_ != LinkState::kUp) {
    return RejectReason::kNone;
  }
  const std::uint64_t d = (std::uint64_t{seq} + modulus - peer_seq_) % modulus;
  if (d == 0 && !RAILPROOF_FAULT(FAULT_TG_NO_REPEAT_CHECK)) {
    return RejectReason::kRepeated;
  }
  const std::uint64_t window = std::uint64_t{config_.seq_window} + (RAILPROOF_FAULT(FAULT_TG_SEQ_WINDOW_OFF_BY_ONE) ? 1U : 0U);
  if (d > window) {
    return RejectReason::kOutOfSequence;
  }
  gap = d == 0 ? 0U : static_cast<std::uint32_t>(d - 1U);
  return RejectReason::kNone;
}

// Design §4 check 7: the echo flag is set and the echo names one of the last
// min(sent, history_depth) own sequence numbers (distinct, since history_depth <= M).
// history_index is the number of own sends since that one (0: the newest).
// @implements REQ-TG-008
// @implements REQ-TG-012
// @implements REQ-TG-017
RejectReason Endpoint::CheckEcho(const TelegramHeader& header, std::uint32_t& history_index) const noexcept {
  history_index = kHistoryMax;
  if (!header.echo_valid) {
    return RejectReason::kNoEcho;
  }
  const std::uint32_t count = HistoryCount();
  for (std::uint32_t k = 0; k < count; ++k) {  // bounded by history_depth <= kHistoryMax
    if (HistoryBack(k).seq == header.echo) {
      history_index = k;
      return RejectReason::kNone;
    }
  }
  return RAILPROOF_FAULT(FAULT_TG_ECHO_NOT_CHECKED) ? RejectReason::kNone : RejectReason::kUnknownEcho;
}

// Design §4 check 8: now - send_time(echo) <= turnaround_ms.
// @implements REQ-TG-006
// @implements REQ-TG-009
RejectReason Endpoint::CheckTurnaround(std::uint32_t history_index, std::uint32_t now_ms) const noexcept {
  if (history_index >= HistoryCount()) {
    return RejectReason::kNone;  // GCOVR_EXCL_LINE defensive: CheckEcho found it (unless FAULT_TG_ECHO_NOT_CHECKED)
  }
  const HistoryEntry& entry = HistoryBack(history_index);
  const std::uint32_t age = Age(now_ms, entry.send_ms);
  const bool stale = RAILPROOF_FAULT(FAULT_TG_TURNAROUND_LE_AS_LT) ? age >= config_.turnaround_ms
                                                                    : age > config_.turnaround_ms;
  if (entry.expired || stale) {
    return RejectReason::kStale;
  }
  return RejectReason::kNone;
}

// @implements REQ-TG-001
// @implements REQ-TG-002
// @implements REQ-TG-003
// @implements REQ-TG-004
// @implements REQ-TG-005
// @implements REQ-TG-006
// @implements REQ-TG-007
// @implements REQ-TG-009
// @implements REQ-TG-012
// @implements REQ-TG-013
Endpoint::RxResult Endpoint::Receive(std::uint32_t now_ms, std::span<const std::uint8_t> rx_bytes,
                                     std::span<std::uint8_t> payload_out) noexcept {
  if (payload_out.size() < kPayloadMax) {
    return MakeRxResult(RejectReason::kBadLength, 0, TelegramHeader{});
  }
  Zero(payload_out);
  if (!initialised_) {
    return MakeRxResult(RejectReason::kAuthFailed, 0, TelegramHeader{});  // no link key
  }
  // Supervision at the receive instant: the vectors deliver telegrams at the time of the
  // last cycle, where this changes nothing; in service it keeps the outputs exact between
  // cycles.
  Supervise(now_ms);

  // Checks 1-3: RS decoding, format, CRC.
  DecodedFrame frame{};
  RejectReason reason = DecodeFrame(rx_bytes, frame);
  if (reason != RejectReason::kNone) {
    return MakeRxResult(reason, 0, TelegramHeader{});
  }
  const TelegramHeader header = frame.header;
  reason = CheckAddressing(header);
  std::array<std::uint8_t, kPayloadMax> plaintext{};
  if (reason == RejectReason::kNone) {
    reason = CheckAuthenticity(frame, plaintext);
  }
  std::uint32_t gap = 0;
  if (reason == RejectReason::kNone) {
    reason = CheckSequenceNumber(header.seq, gap);
  }
  if (reason != RejectReason::kNone) {
    Zero(plaintext);
    return MakeRxResult(reason, 0, TelegramHeader{});
  }
  // In sequence (design §4, REQ-TG-012): the echoed peer number advances even if the echo
  // check below rejects the telegram; its content is not used.
  peer_seq_ = header.seq;
  peer_known_ = true;
  peer_fresh_ = true;
  peer_update_ms_ = now_ms;

  std::uint32_t history_index = kHistoryMax;
  reason = CheckEcho(header, history_index);
  if (reason == RejectReason::kNone) {
    reason = CheckTurnaround(history_index, now_ms);
  }
  if (reason != RejectReason::kNone) {
    // The deletions before this in-sequence telegram are reported now, because peer_seq
    // has moved past them (model: the gap printed with every verdict after check 6).
    Zero(plaintext);
    return MakeRxResult(reason, gap, TelegramHeader{});
  }
  // Accepted.
  last_accept_ms_ = now_ms;
  link_ = LinkState::kUp;
  for (std::size_t i = 0; i < header.payload_len; ++i) {  // payload_len <= kPayloadMax
    payload_out[i] = plaintext[i];
  }
  Zero(plaintext);
  return MakeRxResult(RejectReason::kNone, gap, header);
}

}  // namespace railproof::tg
