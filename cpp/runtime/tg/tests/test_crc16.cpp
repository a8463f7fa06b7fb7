// Unit tests of CRC-16/IBM-3740 (REQ-TG-005, REQ-TG-010; ASM-009). Published vectors of
// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no xorout), and a bitwise
// reference implementation written independently of the table code.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <span>
#include <string_view>
#include <vector>

#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/crc16.hpp"

namespace {

using railproof::tg::Crc16;
using railproof::tg::Crc16Init;
using railproof::tg::Crc16Update;

std::vector<std::uint8_t> Bytes(std::string_view s) {
  return std::vector<std::uint8_t>(s.begin(), s.end());
}

// Bit-at-a-time MSB-first CRC straight from the definition.
std::uint16_t BitwiseCrc(std::span<const std::uint8_t> data) {
  const auto poly = static_cast<unsigned>(railproof::params::tg::crc16_poly);
  auto reg = static_cast<unsigned>(railproof::params::tg::crc16_init);
  for (const std::uint8_t byte : data) {
    for (unsigned bit = 8; bit-- > 0;) {
      const unsigned in = (byte >> bit) & 1U;
      const unsigned top = (reg >> 15U) & 1U;
      reg = (reg << 1U) & 0xFFFFU;
      if ((in ^ top) != 0U) {
        reg ^= poly;
      }
    }
  }
  return static_cast<std::uint16_t>(reg);
}

// @verifies REQ-TG-005
// @verifies REQ-TG-010
TEST(Crc16, PublishedCheckValue) {
  const auto check = Bytes("123456789");
  EXPECT_EQ(Crc16(check), 0x29B1);
}

// Vectors of the CRC-16/CCITT-FALSE catalogue entry: empty input leaves the initial value,
// "A" -> 0xB915, 256 x 'A' -> 0xEA0B.
// @verifies REQ-TG-005
TEST(Crc16, PublishedVectors) {
  EXPECT_EQ(Crc16({}), 0xFFFF);
  EXPECT_EQ(Crc16Init(), 0xFFFF);
  EXPECT_EQ(Crc16(Bytes("A")), 0xB915);
  EXPECT_EQ(Crc16(std::vector<std::uint8_t>(256, 'A')), 0xEA0B);
}

// @verifies REQ-TG-005
TEST(Crc16, MatchesBitwiseReferenceOnRandomData) {
  std::mt19937 rng(0xC0C0);
  std::uniform_int_distribution<unsigned> byte(0, 255);
  std::uniform_int_distribution<std::size_t> len(0, 300);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> data(len(rng));
    for (auto& b : data) {
      b = static_cast<std::uint8_t>(byte(rng));
    }
    ASSERT_EQ(Crc16(data), BitwiseCrc(data)) << "trial " << trial;
  }
}

// @verifies REQ-TG-005
TEST(Crc16, IncrementalEqualsOneShot) {
  const auto data = Bytes("the quick brown fox jumps over the lazy dog 0123456789");
  const std::span<const std::uint8_t> all(data);
  for (std::size_t cut = 0; cut <= data.size(); ++cut) {
    const std::uint16_t part = Crc16Update(Crc16Init(), all.first(cut));
    EXPECT_EQ(Crc16Update(part, all.subspan(cut)), Crc16(all)) << "cut " << cut;
  }
}

// Without reflection or final XOR, appending the CRC big-endian gives a zero register,
// and every single-bit error and every burst of at most 16 bits is detected.
// @verifies REQ-TG-005
TEST(Crc16, ResidueAndErrorDetection) {
  auto frame = Bytes("railproof frame check sequence");
  const std::uint16_t crc = Crc16(frame);
  frame.push_back(static_cast<std::uint8_t>(crc >> 8U));
  frame.push_back(static_cast<std::uint8_t>(crc & 0xFFU));
  EXPECT_EQ(Crc16(frame), 0U);

  const std::size_t bits = frame.size() * 8U;
  for (std::size_t start = 0; start < bits; ++start) {
    for (unsigned burst = 1; burst <= 16U && start + burst <= bits; ++burst) {
      auto corrupted = frame;
      // Burst pattern: first and last bit set (a genuine burst of this length).
      for (unsigned i = 0; i < burst; ++i) {
        if (i == 0U || i + 1U == burst || ((start + i) % 3U == 0U)) {
          const std::size_t pos = start + i;
          corrupted[pos / 8U] = static_cast<std::uint8_t>(corrupted[pos / 8U] ^ (0x80U >> (pos % 8U)));
        }
      }
      ASSERT_NE(Crc16(corrupted), 0U) << "burst " << burst << " at bit " << start;
    }
  }
}

}  // namespace
