// Keys of the telegram unit tests (public test values).
#pragma once

#include <array>
#include <cstdint>

#include "railproof/tg/aead.hpp"

namespace railproof::tg::test {

using KeyBytes = std::array<std::uint8_t, kKeyBytes>;

// `key` with the lowest bit of its last byte flipped: a wrong key as close to the right one
// as a key can be.
constexpr KeyBytes OneBitApart(KeyBytes key) {
  key.back() = static_cast<std::uint8_t>(key.back() ^ 0x01U);
  return key;
}

}  // namespace railproof::tg::test
