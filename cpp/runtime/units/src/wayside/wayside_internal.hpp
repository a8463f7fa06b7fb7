// Helpers shared by the wayside unit's sources (not part of its interface).
#pragma once

#include <cstdint>

namespace railproof::units::detail {

// The telegram layer counts ms modulo 2^32 (wrap-safe differences, tg::Endpoint).
constexpr std::uint32_t Clock32(std::int64_t now_ms) noexcept { return static_cast<std::uint32_t>(now_ms); }

}  // namespace railproof::units::detail
