// Test support of the wayside unit's GoogleTest tests: link keys, a small line, and the train's
// end of a radio link (a train-role telegram endpoint that sends bundles and opens the unit's
// frames).
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <initializer_list>
#include <vector>

#include "railproof/messages/codec.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/units/wayside_unit.hpp"
#include "mb/tests/line_data.hpp"

namespace railproof::units::test {

// Every train's key is derived from its id; train 999 has none.
inline std::array<std::uint8_t, tg::kKeyBytes> KeyOf(std::uint32_t train_id) {
  std::array<std::uint8_t, tg::kKeyBytes> k{};
  for (std::size_t i = 0; i < k.size(); ++i) {
    k[i] = static_cast<std::uint8_t>(train_id * 31U + i * 7U + 1U);
  }
  return k;
}

inline bool TestKeys(const void* /*context*/, std::uint32_t train_id, std::array<std::uint8_t, tg::kKeyBytes>& key) {
  if (train_id == 999) {
    return false;
  }
  key = KeyOf(train_id);
  return true;
}

// A straight line of `length_mm` with 100 m virtual blocks, the parameters of mb.yaml.
inline mb::wayside::test::LineData StraightLine(std::int64_t length_mm) {
  mb::wayside::test::LineData d;
  for (std::int64_t b = 0; b <= length_mm; b += 100'000) {
    d.blocks.push_back(b);
  }
  d.base.length_mm = length_mm;
  return d;
}

inline WaysideConfig BaseConfig(const mb::wayside::test::LineData& line) {
  WaysideConfig c;
  c.keys = TestKeys;
  c.line = line.Config();
  c.capacity = mb::wayside::DefaultCapacity();
  c.capacity.blocks = line.blocks.size() - 1;
  c.capacity.handovers = line.handovers.size();
  c.secure_ahead_mm = 500'000;
  return c;
}

// The train's end of its link with one unit.
class TrainRadio {
 public:
  TrainRadio(std::uint32_t train_id, std::uint16_t radio_id, std::uint16_t ground_id,
             tg::EndpointConfig config = tg::DeploymentConfig(tg::Role::kTrain, 1, 2))
      : train_id_(train_id) {
    config.role = tg::Role::kTrain;
    config.own_id = radio_id;
    config.peer_id = ground_id;
    const tg::ConfigError init = endpoint_.Init(config, tg::LinkKey(KeyOf(train_id)));
    EXPECT_EQ(init, tg::ConfigError::kNone) << "train " << train_id << ": " << tg::ToString(init);
  }

  // One telegram carrying the messages (a plain payload for one).
  std::vector<std::uint8_t> Send(std::int64_t now_ms, std::initializer_list<messages::Message> ms) {
    std::vector<messages::Message> v(ms);
    return SendPayload(now_ms, messages::EncodeBundle(v).payload.View());
  }
  std::vector<std::uint8_t> SendPayload(std::int64_t now_ms, std::span<const std::uint8_t> payload) {
    tg::EncodedFrame f{};
    (void)endpoint_.Cycle(static_cast<std::uint32_t>(now_ms), payload, f);
    return {f.View().begin(), f.View().end()};
  }
  // The messages of the unit's frame for this train this cycle (empty: none, or rejected).
  messages::Bundle Take(std::int64_t now_ms, const CycleOutput& out) {
    for (const TrainFrame& f : out.frames) {
      if (f.train_id == train_id_) {
        std::array<std::uint8_t, tg::kPayloadMax> payload{};
        const auto r = endpoint_.Receive(static_cast<std::uint32_t>(now_ms), f.frame.View(), payload);
        last_reason_ = r.reason;
        if (r.reason != tg::RejectReason::kNone) {
          return {};
        }
        return messages::DecodeBundle(std::span<const std::uint8_t>(payload).first(r.header.payload_len)).bundle;
      }
    }
    return {};
  }
  [[nodiscard]] tg::RejectReason LastReason() const { return last_reason_; }

 private:
  std::uint32_t train_id_;
  tg::Endpoint endpoint_;
  tg::RejectReason last_reason_ = tg::RejectReason::kNone;
};

// The position report of a train with its front at front_mm on the unit's line.
inline messages::PositionReport ReportAt(const WaysideUnit& unit, std::uint32_t train_id, std::int64_t front_mm,
                                         std::int64_t length_mm, std::int64_t correction_mm = 0) {
  const auto loc = unit.Ground().LocateFront(front_mm);
  messages::PositionReport r{};
  r.train_id = train_id;
  r.front_block = loc ? loc->block : 0;
  r.offset_mm = loc ? loc->offset_mm : 0;
  r.length_mm = length_mm;
  r.correction_mm = correction_mm;
  r.last_balise_mm = 0;
  r.speed_mm_s = 0;
  r.direction = messages::Direction::kNominal;
  return r;
}

// The stop-limit telegram of a bundle, or null.
inline const messages::StopLimitTelegram* StopLimitOf(const messages::Bundle& b) {
  return b.size > 0 ? std::get_if<messages::StopLimitTelegram>(&b.messages[0]) : nullptr;
}

}  // namespace railproof::units::test
