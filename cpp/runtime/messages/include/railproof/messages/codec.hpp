// Byte coding of the application messages train and ground exchange: the payload of a radio
// telegram (at most params::tg::payload_max_bytes bytes, encrypted and authenticated by the
// telegram layer, spec/design/tg.md §2). spec/design/layout.md "The application codec".
//
// Every payload starts with one type byte (MessageType); the rest is a fixed big-endian layout
// of that type (i64/i32 two's complement, u32/u8 unsigned, flags 0 or 1):
//
//   1 POSITION_REPORT (train -> ground, PositionReport), 50 bytes:
//     u8 type | u32 train_id | u32 front_block | i64 offset_mm | i64 length_mm |
//     i64 correction_mm | i64 last_balise_mm | i64 speed_mm_s | u8 direction (0 nominal, 1 reverse)
//   2 NO_POSITION (train -> ground: the on-board unit has no valid position), 1 byte: u8 type
//   3 STOP_LIMIT (ground -> train, StopLimitTelegram), 24 + 16 n bytes, n <= kWireRestrictionsMax:
//     u8 type | u32 train_id | i64 limit_mm | u8 kind (Obstruction 0..8) | i64 issue_time_ms |
//     u8 n | u8 truncated | n x (u32 id | i32 begin_mm | i32 end_mm | u32 speed_mm_s)
//   4 KEEP_ALIVE (ground -> train: no stop limit for the train, e.g. abnormal tracking), 1 byte
//   5 CROSSING_REQUEST (train -> crossing controller, CrossingRequest), 9 bytes:
//     u8 type | u32 train_id | u32 crossing_id
//   6 CROSSING_WITHDRAWAL (train -> crossing controller, CrossingWithdrawal), 9 bytes: as 5
//   7 CROSSING_REPORT (crossing controller -> trains and centre, CrossingReport), 24 + 4 n bytes,
//     n <= kMaxReportRequesters:
//     u8 type | u32 crossing_id | u8 status (CrossingStatus 0..3) | i64 warning_start_ms |
//     i64 issued_ms | u8 clock_fault | u8 n | n x u32 requester
//   8 WITHDRAWAL_ACK (crossing controller -> train, WithdrawalAck), 9 bytes:
//     u8 type | u32 crossing_id | u32 train_id
//   9 CENTRE_POSITION_REPORT (train -> centre, CentrePositionReport), 37 bytes:
//     u8 type | u32 train_id | i64 time_ms | i64 front_mm | i64 rear_mm | i64 speed_mm_s
//  10 BUNDLE (either way: several messages in one telegram), 2 + sum(1 + size_i) bytes:
//     u8 type | u8 n (2 .. kBundleMax) | n x (u8 size_i | the payload of message i, types 1..9)
//     A bundle of one message is that message's plain payload; a bundle holds no bundle.
//
// Ranges (checked by Decode, and by Encode before it writes a byte; core/units.hpp):
//   positions (last_balise_mm, limit_mm, front_mm, rear_mm)  |x| <= core::kMaxPositionMm
//   offset_mm                                                0 .. core::kMaxPositionMm
//   length_mm                                                1 .. core::kMaxTrainLengthMm
//   correction_mm                                            0 .. core::kMaxPositionErrorMm
//   speed_mm_s of a report                                   0 .. core::kMaxMeasuredSpeedMmS
//   speed_mm_s of a restriction                              1 .. core::kMaxLimitMmS
//   restrictions: begin_mm < end_mm, in ascending (begin_mm, id) order, no entry twice;
//   envelope of a centre report: rear_mm <= front_mm.
// Identifiers, block numbers and clock values (issue, report and warning times) take every
// value of their type: their receivers check them (registered trains, blocks of the line,
// lc::ClockOk, the authority's newer-than rule).
//
// A stop-limit telegram holds up to kTelegramRestrictionsMax restrictions, the wire up to
// kWireRestrictionsMax (the POSITION and CONTROL payload lengths of the line simulator, whose
// lossy channel draws its random numbers per byte): Encode writes the first (nearest)
// kWireRestrictionsMax and sets `truncated` when it leaves any out; this is the only value it
// does not write as it is. A restriction bound outside int32 is refused (kNotRepresentable).
//
// Runtime rules: no heap (fixed buffers), no exceptions, no recursion, bounded loops; a
// decoded message is whole or absent (std::monostate), never partly filled.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <variant>

#include "railproof/core/enum_names.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/messages/crossing.hpp"
#include "railproof/messages/position_report.hpp"
#include "railproof/messages/stop_limit.hpp"

namespace railproof::messages {

// The largest payload of a telegram (the telegram layer's kPayloadMax; messages does not link tg).
inline constexpr std::size_t kPayloadCapacity = static_cast<std::size_t>(params::tg::payload_max_bytes);
// Restrictions one STOP_LIMIT payload carries.
inline constexpr std::size_t kWireRestrictionsMax = 6;

// The type byte. Its value is also the index of the message in `Message` (0: no message).
enum class MessageType : std::uint8_t {
  kPositionReport = 1,
  kNoPosition = 2,
  kStopLimit = 3,
  kKeepAlive = 4,
  kCrossingRequest = 5,
  kCrossingWithdrawal = 6,
  kCrossingReport = 7,
  kWithdrawalAck = 8,
  kCentrePositionReport = 9,
};

constexpr const char* ToString(MessageType t) noexcept {
  return core::EnumName(t, std::array<const char*, 10>{"INVALID", "POSITION_REPORT", "NO_POSITION", "STOP_LIMIT",
                                                       "KEEP_ALIVE", "CROSSING_REQUEST", "CROSSING_WITHDRAWAL",
                                                       "CROSSING_REPORT", "WITHDRAWAL_ACK", "CENTRE_POSITION_REPORT"});
}

// The on-board unit has no valid position (tracking loss: the link stays up, no report).
// @implements REQ-MB-001
struct NoPosition {};

// The ground has no stop limit for the train; the telegram keeps the link supervised.
// @implements REQ-MB-024
struct KeepAlive {};

// A withdrawal of the warning of one crossing by one train (design lc §3); a request and a
// withdrawal carry the same fields and differ in their type byte.
// @implements REQ-LC-004
struct CrossingWithdrawal {
  CrossingRequest request;
};

// One message of any type; std::monostate is no message (a decoding error).
using Message = std::variant<std::monostate, PositionReport, NoPosition, StopLimitTelegram, KeepAlive,
                             CrossingRequest, CrossingWithdrawal, CrossingReport, WithdrawalAck, CentrePositionReport>;

// The fields a rejection names.
enum class Field : std::uint8_t {
  kNone,
  kOffset,            // offset_mm
  kLength,            // length_mm
  kCorrection,        // correction_mm
  kLastBalise,        // last_balise_mm
  kSpeed,             // speed_mm_s (position report, centre position report)
  kDirection,         // direction
  kLimit,             // limit_mm
  kKind,              // kind (obstruction)
  kRestrictionCount,  // n of STOP_LIMIT, restriction_count
  kTruncated,         // truncated flag
  kRestrictionBegin,  // begin_mm of a restriction
  kRestrictionEnd,    // end_mm of a restriction
  kRestrictionSpeed,  // speed_mm_s of a restriction
  kRestrictionOrder,  // restrictions not in ascending (begin_mm, id) order
  kStatus,            // status (crossing)
  kClockFault,        // clock_fault flag
  kRequesterCount,    // n of CROSSING_REPORT, requester_count
  kFront,             // front_mm
  kRear,              // rear_mm
  kBundleCount,       // n of a BUNDLE
};

constexpr const char* ToString(Field f) noexcept {
  return core::EnumName(f, std::array<const char*, 21>{
                               "none", "offset_mm", "length_mm", "correction_mm", "last_balise_mm", "speed_mm_s",
                               "direction", "limit_mm", "kind", "restriction_count", "restrictions_truncated",
                               "restriction.begin_mm", "restriction.end_mm", "restriction.speed_mm_s",
                               "restriction order", "status", "clock_fault", "requester_count", "front_mm",
                               "rear_mm", "bundle count"});
}

// Why a payload is not a message, checked in this order: kEmpty, kUnknownType, kWrongLength
// (for the variable types: the fixed part first, then kTooManyEntries, then the whole
// length), then the fields in layout order.
enum class DecodeError : std::uint8_t {
  kNone,
  kEmpty,           // no byte
  kUnknownType,     // the type byte names no message type
  kWrongLength,     // the length is not the type's (with its entry count)
  kTooManyEntries,  // a restriction or requester count above the maximum (`field`)
  kOutOfRange,      // a number outside its range (`field`)
  kBadEnum,         // an enumeration byte outside the enumeration (`field`)
  kBadFlag,         // a flag byte other than 0 or 1 (`field`)
  kEmptyRange,      // a restriction with begin_mm >= end_mm, an envelope with rear_mm > front_mm
  kUnsorted,        // restrictions not in strictly ascending (begin_mm, id) order
};

constexpr const char* ToString(DecodeError e) noexcept {
  return core::EnumName(e, std::array<const char*, 10>{"NONE", "EMPTY", "UNKNOWN_TYPE", "WRONG_LENGTH",
                                                       "TOO_MANY_ENTRIES", "OUT_OF_RANGE", "BAD_ENUM", "BAD_FLAG",
                                                       "EMPTY_RANGE", "UNSORTED"});
}

enum class EncodeError : std::uint8_t {
  kNone,
  kNoMessage,         // std::monostate
  kInvalidMessage,    // a value the decoder would reject (`invalid`, `field`)
  kNotRepresentable,  // a valid value the layout cannot hold (a restriction bound outside int32)
  kTooLarge,          // a bundle of more than kBundleMax messages or kPayloadCapacity bytes
};

constexpr const char* ToString(EncodeError e) noexcept {
  return core::EnumName(e, std::array<const char*, 5>{"NONE", "NO_MESSAGE", "INVALID_MESSAGE", "NOT_REPRESENTABLE",
                                                      "TOO_LARGE"});
}

// An encoded message: the first `size` bytes of `bytes`.
struct Payload {
  std::array<std::uint8_t, kPayloadCapacity> bytes{};
  std::size_t size = 0;
  [[nodiscard]] std::span<const std::uint8_t> View() const noexcept { return {bytes.data(), size}; }
};

struct Decoded {
  Message message;                        // std::monostate unless error == kNone
  DecodeError error = DecodeError::kNone;
  Field field = Field::kNone;             // the field of kTooManyEntries .. kUnsorted
  [[nodiscard]] bool Ok() const noexcept { return error == DecodeError::kNone; }
};

struct Encoded {
  Payload payload;                          // size 0 unless error == kNone
  EncodeError error = EncodeError::kNone;
  DecodeError invalid = DecodeError::kNone;  // kInvalidMessage: the decoder's reason for it
  Field field = Field::kNone;                // kInvalidMessage, kNotRepresentable: which field
  [[nodiscard]] bool Ok() const noexcept { return error == EncodeError::kNone; }
};

// The type of a message (its index in Message); std::monostate has none (0, "INVALID").
[[nodiscard]] constexpr MessageType TypeOf(const Message& m) noexcept { return static_cast<MessageType>(m.index()); }

// The payload length of a message of type t with n entries (restrictions or requesters; 0
// for the fixed types), or 0 if t is no type. Does not check n.
[[nodiscard]] std::size_t PayloadSize(MessageType t, std::size_t n) noexcept;

// The message of a payload (its whole length), or the first reason it is none.
[[nodiscard]] Decoded Decode(std::span<const std::uint8_t> payload) noexcept;

// The payload of a message, or why there is none: Decode(Encode(m).payload.View()) gives m
// back (with at most kWireRestrictionsMax restrictions, `truncated` set if any were left out).
[[nodiscard]] Encoded Encode(const Message& message) noexcept;

// ---- Bundles: the messages one telegram carries (a unit sends one telegram per cycle of its
// telegram layer: the position report or stop limit first, then the crossing messages that fit).

inline constexpr std::uint8_t kBundleType = 10;
inline constexpr std::size_t kBundleMax = 8;

// Up to kBundleMax messages, in order.
struct Bundle {
  std::array<Message, kBundleMax> messages{};
  std::size_t size = 0;
  [[nodiscard]] std::span<const Message> View() const noexcept { return {messages.data(), size}; }
  // Appends m; false (and no change) when the bundle is full.
  [[nodiscard]] bool Add(const Message& m) noexcept {
    if (size >= kBundleMax) {
      return false;
    }
    messages[size] = m;
    ++size;
    return true;
  }
};

struct DecodedBundle {
  Bundle bundle;                          // empty unless error == kNone
  DecodeError error = DecodeError::kNone;
  Field field = Field::kNone;             // as Decoded::field; kBundleCount for a bad n
  std::size_t entry = 0;                  // the message the error is in (0 for the bundle's own bytes)
  [[nodiscard]] bool Ok() const noexcept { return error == DecodeError::kNone; }
};

// The payload bytes Encode(m) writes (0 if m is no message or is refused).
[[nodiscard]] std::size_t EncodedSize(const Message& m) noexcept;

// The payload bytes EncodeBundle(messages) writes (0 for no message or a refused one); may
// exceed kPayloadCapacity (then EncodeBundle refuses).
[[nodiscard]] std::size_t BundleSize(std::span<const Message> messages) noexcept;

// Appends m to the bundle if the bundle then still fits one payload (kBundleMax messages,
// kPayloadCapacity bytes); false and no change otherwise (or when m is refused). Senders fill
// a bundle in priority order with it and keep what does not fit for their next telegram.
[[nodiscard]] bool AddIfFits(Bundle& bundle, const Message& m) noexcept;

// The messages of a payload: a plain payload (types 1..9) is a bundle of one; a BUNDLE is read
// entry by entry, each with Decode. Whole or nothing: any error leaves the bundle empty.
// Errors: those of Decode (the entry's, with `entry`), kWrongLength for a bundle whose entries do
// not fill it exactly or that is longer than kPayloadCapacity, kTooManyEntries (kBundleCount) for n < 2 or n > kBundleMax.
[[nodiscard]] DecodedBundle DecodeBundle(std::span<const std::uint8_t> payload) noexcept;

// One payload for the messages: the plain payload of a single message, else a BUNDLE; refused
// with the first refused message's error, kNoMessage for none, kTooLarge when over capacity.
[[nodiscard]] Encoded EncodeBundle(std::span<const Message> messages) noexcept;

}  // namespace railproof::messages
