// CRC-16/IBM-3740 (a.k.a. CRC-16/CCITT-FALSE) frame check sequence of the telegram layer
// (REQ-TG-005, REQ-TG-010; ASM-009): polynomial crc16_poly = 0x1021, initial value
// crc16_init = 0xFFFF, no input/output reflection, no final XOR. Check value: "123456789"
// -> 0x29B1. Table-driven (constexpr table); no heap, no exceptions.
#pragma once

#include <cstdint>
#include <span>

namespace railproof::tg {

// Register value before the first byte (crc16_init from the generated parameters).
// @implements REQ-TG-005
std::uint16_t Crc16Init() noexcept;

// Incremental form: feeds data into a running register. Crc16(a ‖ b) ==
// Crc16Update(Crc16Update(Crc16Init(), a), b). The final register is the CRC (no xorout).
// @implements REQ-TG-005
std::uint16_t Crc16Update(std::uint16_t crc, std::span<const std::uint8_t> data) noexcept;

// One-shot CRC over data.
// @implements REQ-TG-005
std::uint16_t Crc16(std::span<const std::uint8_t> data) noexcept;

}  // namespace railproof::tg
