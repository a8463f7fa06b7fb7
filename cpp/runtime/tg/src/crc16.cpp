// CRC-16/IBM-3740 (REQ-TG-005, REQ-TG-010; ASM-009). MSB-first (non-reflected) table
// algorithm: crc = (crc << 8) ^ T[(crc >> 8) ^ byte], T[i] = i * x^16 mod p(x).
#include "railproof/tg/crc16.hpp"

#include <array>
#include <cstddef>

#include "railproof/generated/tg_params.hpp"

namespace railproof::tg {

namespace {

namespace tg = railproof::params::tg;
static_assert(tg::crc16_poly >= 0 && tg::crc16_poly <= 0xFFFF, "crc16_poly is 16 bits");
static_assert(tg::crc16_init >= 0 && tg::crc16_init <= 0xFFFF, "crc16_init is 16 bits");

constexpr std::uint16_t kPoly = static_cast<std::uint16_t>(tg::crc16_poly);
constexpr std::uint16_t kInit = static_cast<std::uint16_t>(tg::crc16_init);

constexpr std::array<std::uint16_t, 256> MakeTable() noexcept {
  std::array<std::uint16_t, 256> table{};
  for (unsigned i = 0; i < 256U; ++i) {
    unsigned reg = i << 8U;
    for (unsigned bit = 0; bit < 8U; ++bit) {
      reg = ((reg & 0x8000U) != 0U) ? ((reg << 1U) ^ kPoly) : (reg << 1U);
    }
    table[i] = static_cast<std::uint16_t>(reg & 0xFFFFU);
  }
  return table;
}

constexpr std::array<std::uint16_t, 256> kTable = MakeTable();

constexpr std::uint16_t UpdateBytes(std::uint16_t crc, const std::uint8_t* data,
                                    std::size_t size) noexcept {
  unsigned reg = crc;
  for (std::size_t i = 0; i < size; ++i) {
    const unsigned idx = ((reg >> 8U) ^ data[i]) & 0xFFU;
    reg = ((reg << 8U) ^ kTable[idx]) & 0xFFFFU;
  }
  return static_cast<std::uint16_t>(reg);
}

// Compile-time self-check of the table against the published check value (ASM-009).
constexpr std::uint8_t kCheckInput[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
static_assert(tg::crc16_poly != 0x1021 || tg::crc16_init != 0xFFFF ||
                  UpdateBytes(kInit, kCheckInput, sizeof kCheckInput) == 0x29B1,
              "CRC-16/IBM-3740 check value");

}  // namespace

// @implements REQ-TG-005
std::uint16_t Crc16Init() noexcept { return kInit; }

// @implements REQ-TG-005
// @implements REQ-TG-010
std::uint16_t Crc16Update(std::uint16_t crc, std::span<const std::uint8_t> data) noexcept {
  return UpdateBytes(crc, data.data(), data.size());
}

// @implements REQ-TG-005
// @implements REQ-TG-010
std::uint16_t Crc16(std::span<const std::uint8_t> data) noexcept {
  return UpdateBytes(kInit, data.data(), data.size());
}

}  // namespace railproof::tg
