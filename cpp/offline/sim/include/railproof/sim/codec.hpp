// Application payloads the line simulation carries inside radio telegrams (the payload of
// a POSITION or CONTROL telegram, at most tg::kPayloadMax bytes, encrypted and
// authenticated by the telegram layer). Big-endian fixed layouts:
//
// POSITION (train -> ground), 51 bytes, or 1 byte {0} when the on-board unit has no
// valid position (tracking loss: the link stays up but no report is given):
//   u8 kind = 1 | u32 train_id | u32 front_block | i64 offset_mm | i64 length_mm |
//   i64 correction_mm | i64 last_balise_mm | i64 speed_mm_s | u8 direction (0 nominal)
//
// CONTROL (ground -> train), 24 + 16 n bytes, or 1 byte {0} (keep-alive: the ground has
// no stop limit for the train, e.g. its tracking is abnormal):
//   u8 kind = 1 | u32 train_id | i64 limit_mm | u8 obstruction | i64 issue_time_ms |
//   u8 n | u8 truncated | n x (u32 id | i32 begin_mm | i32 end_mm | u32 speed_mm_s)
// At most kControlRestrictionsMax restrictions fit; the rest set `truncated`.
// Offline module (the runtime coding of these messages belongs to a later issue).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "railproof/mb/wayside/ground.hpp"
#include "railproof/messages/stop_limit.hpp"

namespace railproof::sim {

inline constexpr std::size_t kControlRestrictionsMax = 6;

std::vector<std::uint8_t> EncodePosition(const messages::PositionReport& report);
std::vector<std::uint8_t> EncodeNoPosition();
// Empty optional for a {0} payload or a malformed one (`malformed` set for the latter).
std::optional<messages::PositionReport> DecodePosition(std::span<const std::uint8_t> payload, bool& malformed);

std::vector<std::uint8_t> EncodeStopLimit(const messages::StopLimitTelegram& telegram);
std::vector<std::uint8_t> EncodeKeepAlive();
std::optional<messages::StopLimitTelegram> DecodeStopLimit(std::span<const std::uint8_t> payload, bool& malformed);

}  // namespace railproof::sim
