// The tg vectors for the replays through both units: the set, read once per test run with the
// tg runner's reader, and the frame of a vector's "rx" step as the peer of the endpoint under
// test sends it: the vector's header fields, the link key or (auth "attacker") the
// key with one bit flipped, the telegram corrupted beyond the code's correction as the tg
// runner corrupts it (9 symbols of block 0, radius 8), and a payload the unit decodes.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "railproof/tg/aead.hpp"
#include "railproof/tg/frame.hpp"
#include "tg/conformance/vector_reader.hpp"

namespace railproof::units::test {

// Every tg*.jsonl vector of the pipeline's vector directory (RAILPROOF_UNITS_VECTORS).
inline const conformance::LoadResult& TgVectorSet() {
  static const conformance::LoadResult loaded = conformance::LoadVectorDirectory(RAILPROOF_UNITS_VECTORS);
  return loaded;
}

inline std::vector<std::uint8_t> VectorFrame(const conformance::RxTelegram& t, std::int64_t now_ms,
                                             std::array<std::uint8_t, tg::kKeyBytes> key,
                                             std::span<const std::uint8_t> payload) {
  tg::TelegramHeader h{};
  h.version = tg::kVersion;
  h.type = t.type;
  h.src = t.src;
  h.dst = t.dst;
  h.seq = t.seq;
  h.echo = t.echo.value_or(0U);
  h.echo_valid = t.echo.has_value();
  h.timestamp_ms = static_cast<std::uint32_t>(now_ms);
  if (!t.with_link_key) {
    key.back() = static_cast<std::uint8_t>(key.back() ^ 0x01U);
  }
  tg::EncodedFrame f{};
  EXPECT_EQ(tg::EncodeFrame(h, payload, tg::LinkKey(key), f), tg::EncodeStatus::kOk);
  if (t.corrupt) {
    for (std::size_t k = 0; k < 9; ++k) {
      f.bytes[k * 7] = static_cast<std::uint8_t>(f.bytes[k * 7] ^ 0xA5U);
    }
  }
  return {f.View().begin(), f.View().end()};
}

}  // namespace railproof::units::test
