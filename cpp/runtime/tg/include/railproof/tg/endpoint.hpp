// Receiver and link-supervision state machine of one endpoint of the radio telegram
// safety layer (spec/design/tg.md §4, §5). It mirrors `tick()` and
// `receive()` of models/tg.pml: the same checks in the same order, the same state
// update rules, the same outputs; the model counts ticks, this code counts integer
// milliseconds (uint32, wrap-safe differences).
//
// Runtime module: no heap, no exceptions, bounded loops, typed results, deterministic.
//
// Contract on time (ASM-010): `now_ms` never decreases between calls (modulo 2^32) and
// Cycle is called at least once per min(turnaround_ms, link_timeout_ms, echo_validity_ms)
// in service; every age is a wrap-safe uint32 difference, and expiries are latched at each
// call so that an age can never wrap back into validity while the endpoint is cycled.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "railproof/core/enum_names.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/aead.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"

namespace railproof::tg {

// @implements REQ-TG-008
enum class Role : std::uint8_t {
  kGround,  // sends CONTROL, receives POSITION; output: train tracking abnormal
  kTrain,   // sends POSITION, receives CONTROL; output: emergency brake demand
};

// @implements REQ-TG-013
enum class LinkState : std::uint8_t {
  kNone,  // nothing accepted yet
  kUp,    // a telegram was accepted at most link_timeout_ms ago
  kLost,  // more than link_timeout_ms without acceptance
};

// Capacity of the ring of own send times (fixed at compile time, no heap).
inline constexpr std::uint32_t kHistoryMax = 64;
// Largest time limit: wrap-safe uint32 differences stay unambiguous below 2^31 ms.
inline constexpr std::uint32_t kMaxIntervalMs = 0x7FFFFFFFU;
inline constexpr std::uint64_t kSeqModulusMax = std::uint64_t{1} << 32U;

// @implements REQ-TG-004
// @implements REQ-TG-008
// @implements REQ-TG-017
struct EndpointConfig {
  Role role;
  std::uint16_t own_id;
  std::uint16_t peer_id;
  std::uint64_t seq_modulus;        // M, 2 .. 2^32 (2^seq_bits in service)
  std::uint32_t seq_window;         // W, 1 .. M-1
  std::uint32_t history_depth;      // H, 1 .. min(kHistoryMax, M)
  std::uint32_t turnaround_ms;      // T_ta, 1 .. kMaxIntervalMs
  std::uint32_t link_timeout_ms;    // T_link, 1 .. kMaxIntervalMs
  std::uint32_t echo_validity_ms;   // T_echo, 1 .. kMaxIntervalMs
  std::uint32_t initial_seq;        // first own sequence number, < M
};

// @implements REQ-TG-018
enum class ConfigError : std::uint8_t {
  kNone,
  kInvalidRole,             // role is neither kGround nor kTrain
  kSameIds,                 // own_id == peer_id
  kSeqModulusOutOfRange,    // M < 2 or M > 2^32
  kSeqWindowOutOfRange,     // W == 0 or W >= M
  kHistoryDepthOutOfRange,  // H == 0, H > kHistoryMax or H > M (last H numbers must be distinct)
  kInitialSeqOutOfRange,    // initial_seq >= M
  kTurnaroundOutOfRange,    // 0 or > kMaxIntervalMs
  kLinkTimeoutOutOfRange,   // 0 or > kMaxIntervalMs
  kEchoValidityOutOfRange,  // 0 or > kMaxIntervalMs
  kCryptoUnavailable,       // libsodium could not be initialised
};

// @implements REQ-TG-018
enum class SendStatus : std::uint8_t {
  kSent,            // out_frame holds the telegram, the sequence number is consumed
  kPayloadTooLong,  // payload longer than kPayloadMax: nothing sent, nothing consumed
  kNotInitialised,  // Init has not succeeded: nothing sent
  kEncodeFailed,    // EncodeFrame failed (crypto unavailable): nothing sent, nothing consumed
};

constexpr const char* ToString(Role role) noexcept {
  return core::EnumName(role, std::array<const char*, 2>{"ground", "train"}, "invalid");
}

constexpr const char* ToString(LinkState link) noexcept {
  return core::EnumName(link, std::array<const char*, 3>{"NONE", "UP", "LOST"});
}

constexpr const char* ToString(ConfigError error) noexcept {
  return core::EnumName(error, std::array<const char*, 11>{"None", "InvalidRole", "SameIds", "SeqModulusOutOfRange", "SeqWindowOutOfRange", "HistoryDepthOutOfRange", "InitialSeqOutOfRange", "TurnaroundOutOfRange", "LinkTimeoutOutOfRange", "EchoValidityOutOfRange", "CryptoUnavailable"}, "Invalid");
}

constexpr const char* ToString(SendStatus status) noexcept {
  return core::EnumName(status, std::array<const char*, 4>{"Sent", "PayloadTooLong", "NotInitialised", "EncodeFailed"}, "Invalid");
}

// Type a role sends, and the type it expects from its peer (design §2).
constexpr TelegramType SentType(Role role) noexcept {
  return role == Role::kGround ? TelegramType::kControl : TelegramType::kPosition;
}
constexpr TelegramType ExpectedType(Role role) noexcept {
  return role == Role::kGround ? TelegramType::kPosition : TelegramType::kControl;
}

// The service configuration, built from spec/parameters/tg.yaml (generated header).
// @implements REQ-TG-004
// @implements REQ-TG-008
// @implements REQ-TG-017
constexpr EndpointConfig DeploymentConfig(Role role, std::uint16_t own_id, std::uint16_t peer_id) noexcept {
  namespace p = params::tg;
  static_assert(p::seq_bits >= 1 && p::seq_bits <= 32, "sequence numbers are carried in 32 bits");
  static_assert(p::seq_window >= 1 && p::history_depth >= 1 &&
                    p::history_depth <= static_cast<std::int64_t>(kHistoryMax),
                "seq_window / history_depth out of range");
  static_assert(p::turnaround_max_ms >= 1 && p::turnaround_max_ms <= kMaxIntervalMs &&
                    p::link_timeout_ms >= 1 && p::link_timeout_ms <= kMaxIntervalMs &&
                    p::echo_validity_ms >= 1 && p::echo_validity_ms <= kMaxIntervalMs,
                "time limits out of range");
  return EndpointConfig{
      role,
      own_id,
      peer_id,
      std::uint64_t{1} << static_cast<unsigned>(p::seq_bits),
      static_cast<std::uint32_t>(p::seq_window),
      static_cast<std::uint32_t>(p::history_depth),
      static_cast<std::uint32_t>(p::turnaround_max_ms),
      static_cast<std::uint32_t>(p::link_timeout_ms),
      static_cast<std::uint32_t>(p::echo_validity_ms),
      0U,
  };
}

// First violated rule of the list in EndpointConfig, in the order of ConfigError.
// @implements REQ-TG-018
constexpr ConfigError Validate(const EndpointConfig& c) noexcept {
  if (c.role != Role::kGround && c.role != Role::kTrain) {
    return ConfigError::kInvalidRole;
  }
  if (c.own_id == c.peer_id) {
    return ConfigError::kSameIds;
  }
  if (c.seq_modulus < 2 || c.seq_modulus > kSeqModulusMax) {
    return ConfigError::kSeqModulusOutOfRange;
  }
  if (c.seq_window == 0 || c.seq_window >= c.seq_modulus) {
    return ConfigError::kSeqWindowOutOfRange;
  }
  if (c.history_depth == 0 || c.history_depth > kHistoryMax || c.history_depth > c.seq_modulus) {
    return ConfigError::kHistoryDepthOutOfRange;
  }
  if (c.initial_seq >= c.seq_modulus) {
    return ConfigError::kInitialSeqOutOfRange;
  }
  if (c.turnaround_ms == 0 || c.turnaround_ms > kMaxIntervalMs) {
    return ConfigError::kTurnaroundOutOfRange;
  }
  if (c.link_timeout_ms == 0 || c.link_timeout_ms > kMaxIntervalMs) {
    return ConfigError::kLinkTimeoutOutOfRange;
  }
  if (c.echo_validity_ms == 0 || c.echo_validity_ms > kMaxIntervalMs) {
    return ConfigError::kEchoValidityOutOfRange;
  }
  return ConfigError::kNone;
}

static_assert(Validate(DeploymentConfig(Role::kGround, 1, 42)) == ConfigError::kNone);

// One endpoint (ground control unit or on-board unit) of one ground-train link.
// @implements REQ-TG-001
// @implements REQ-TG-002
// @implements REQ-TG-003
// @implements REQ-TG-004
// @implements REQ-TG-006
// @implements REQ-TG-007
// @implements REQ-TG-008
// @implements REQ-TG-009
// @implements REQ-TG-012
// @implements REQ-TG-013
// @implements REQ-TG-014
// @implements REQ-TG-015
class Endpoint {
 public:
  struct CycleOutput {
    TelegramHeader tx;         // the telegram sent; all zero unless status == kSent
    LinkState link;            // after supervision
    bool emergency_brake;      // link != kUp (the train role's output, REQ-TG-014)
    bool tracking_abnormal;    // link != kUp (the ground role's output, REQ-TG-015)
    SendStatus status;
  };

  struct RxResult {
    RejectReason reason;       // kNone: accepted
    std::uint32_t gap;         // deletions d - 1 detected by a telegram that passed checks 1-6
                               // while the link was UP (accepted, or rejected by check 7/8:
                               // peer_seq moved past them either way); else 0
    LinkState link;
    bool emergency_brake;
    bool tracking_abnormal;
    TelegramHeader header;     // the accepted telegram's header; all zero unless accepted
  };

  // Not initialised: Cycle sends nothing, Receive rejects everything (kAuthFailed: no
  // link key), outputs are the safe ones (link kNone, brake and abnormal demanded).
  Endpoint() noexcept;

  // Validates config, initialises libsodium and resets every state variable (the start
  // state of design §7: nothing sent, nothing received, link kNone). On an error the
  // endpoint is left not initialised.
  ConfigError Init(const EndpointConfig& config, const LinkKey& key) noexcept;

  // One cycle at now_ms: link supervision, then one telegram carrying `payload` is
  // encoded into out_frame (out_frame.size = 0 if nothing is sent).
  // @implements REQ-TG-008
  // @implements REQ-TG-012
  // @implements REQ-TG-013
  CycleOutput Cycle(std::uint32_t now_ms, std::span<const std::uint8_t> payload, EncodedFrame& out_frame) noexcept;

  // One received frame at now_ms. The decrypted payload of an accepted telegram is written
  // to payload_out[0, header.payload_len) and the rest of payload_out is zeroed; on any
  // rejection payload_out is zeroed and nothing of the telegram is exposed. payload_out
  // must hold kPayloadMax bytes, else kBadLength and no state changes.
  // @implements REQ-TG-001
  // @implements REQ-TG-003
  // @implements REQ-TG-004
  // @implements REQ-TG-006
  // @implements REQ-TG-007
  // @implements REQ-TG-009
  // @implements REQ-TG-012
  RxResult Receive(std::uint32_t now_ms, std::span<const std::uint8_t> rx_bytes,
                   std::span<std::uint8_t> payload_out) noexcept;

  [[nodiscard]] bool Initialised() const noexcept { return initialised_; }
  [[nodiscard]] LinkState Link() const noexcept { return link_; }
  [[nodiscard]] const EndpointConfig& Config() const noexcept { return config_; }

 private:
  struct HistoryEntry {
    std::uint32_t seq;
    std::uint32_t send_ms;
    bool expired;  // latched once now - send_ms > turnaround_ms
  };

  void Reset() noexcept;
  void Supervise(std::uint32_t now_ms) noexcept;
  [[nodiscard]] bool EchoValid(std::uint32_t now_ms) const noexcept;
  [[nodiscard]] std::uint32_t HistoryCount() const noexcept;
  [[nodiscard]] const HistoryEntry& HistoryBack(std::uint32_t k) const noexcept;  // k = 0: newest

  [[nodiscard]] RejectReason CheckAddressing(const TelegramHeader& header) const noexcept;
  [[nodiscard]] RejectReason CheckAuthenticity(const DecodedFrame& frame,
                                               std::span<std::uint8_t> plaintext) const noexcept;
  [[nodiscard]] RejectReason CheckSequenceNumber(std::uint32_t seq, std::uint32_t& gap) const noexcept;
  [[nodiscard]] RejectReason CheckEcho(const TelegramHeader& header, std::uint32_t& history_index) const noexcept;
  [[nodiscard]] RejectReason CheckTurnaround(std::uint32_t history_index, std::uint32_t now_ms) const noexcept;

  [[nodiscard]] CycleOutput MakeCycleOutput(SendStatus status, const TelegramHeader& tx) const noexcept;
  [[nodiscard]] RxResult MakeRxResult(RejectReason reason, std::uint32_t gap,
                                      const TelegramHeader& header) const noexcept;

  EndpointConfig config_;
  LinkKey key_;
  bool initialised_;

  // sending (REQ-TG-008)
  std::uint32_t next_seq_;
  std::uint32_t sent_;          // own telegrams sent, saturating at history_depth
  std::uint32_t history_head_;  // ring index of the next entry to write
  std::array<HistoryEntry, kHistoryMax> history_;

  // last in-sequence peer telegram (REQ-TG-012)
  bool peer_known_;
  bool peer_fresh_;  // latched false once now - peer_update_ms_ > echo_validity_ms
  std::uint32_t peer_seq_;
  std::uint32_t peer_update_ms_;

  // link supervision (REQ-TG-013)
  LinkState link_;
  std::uint32_t last_accept_ms_;
};

}  // namespace railproof::tg
