// Unit tests of the simulation's models: the seeded channel (the train-motion model is tested
// in offline/common).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/sim/channel.hpp"

namespace railproof::sim {
namespace {

// ---- channel ---------------------------------------------------------------------------

std::vector<std::uint8_t> Bytes(std::size_t n, std::uint8_t fill) { return std::vector<std::uint8_t>(n, fill); }

struct Trace {
  std::vector<std::int64_t> due;
  std::uint64_t lost = 0;
};

enum class Other { kSent, kBlocked, kAbsent };  // what train 9's link does

Trace RunChannel(std::uint64_t seed, Other other) {
  Channel ch(ChannelConfig{0.1, 20, 400, 0.0}, seed);
  Trace tr;
  for (std::int64_t t = 0; t < 20'000; t += 100) {
    const auto b = Bytes(66, static_cast<std::uint8_t>(t));
    if (other != Other::kAbsent) {
      ch.Send(9, Direction::kUplink, t, b, other == Other::kBlocked);
    }
    ch.Send(2, Direction::kDownlink, t, b, false);
    for (const Frame& f : ch.Deliver(t)) {
      if (f.train == 2) {
        tr.due.push_back(f.due_ms);
      }
    }
  }
  tr.lost = ch.Stats(Direction::kDownlink).lost_random;
  return tr;
}

TEST(SimChannel, IsDeterministicForASeed) {
  const Trace a = RunChannel(42, Other::kSent);
  const Trace b = RunChannel(42, Other::kSent);
  const Trace c = RunChannel(43, Other::kSent);
  EXPECT_EQ(a.due, b.due);
  EXPECT_EQ(a.lost, b.lost);
  EXPECT_NE(a.due, c.due);
  // a radio-loss window on train 9's link draws nothing from the PRNG: train 2's link sees
  // the same losses and delays as if train 9 sent nothing at all
  const Trace blocked = RunChannel(42, Other::kBlocked);
  const Trace absent = RunChannel(42, Other::kAbsent);
  EXPECT_EQ(blocked.due, absent.due);
  EXPECT_EQ(blocked.lost, absent.lost);
  Prng p1(5);
  Prng p2(5);
  for (int k = 0; k < 100; ++k) {
    EXPECT_EQ(p1.Next(), p2.Next());
  }
}

TEST(SimChannel, LosesAndDelaysAsConfigured) {
  Channel ch(ChannelConfig{0.2, 100, 300, 0.0}, 7);
  const int n = 20'000;
  std::uint64_t delivered = 0;
  for (int k = 0; k < n; ++k) {
    ch.Send(2, Direction::kUplink, k * 10, Bytes(66, 1), false);
  }
  std::int64_t prev_due = -1;
  for (const Frame& f : ch.Deliver(1'000'000)) {
    const std::int64_t delay = f.due_ms - f.sent_ms;
    EXPECT_GE(delay, 100);
    EXPECT_LE(delay, 300);
    EXPECT_GE(f.due_ms, prev_due);  // delivered in due order
    prev_due = f.due_ms;
    ++delivered;
  }
  const auto& st = ch.Stats(Direction::kUplink);
  EXPECT_EQ(st.sent, static_cast<std::uint64_t>(n));
  EXPECT_EQ(st.lost_random + delivered, static_cast<std::uint64_t>(n));
  // 0.2 * 20000 = 4000 expected, sd = sqrt(n p (1-p)) ~ 57: accept 5 sd
  EXPECT_NEAR(static_cast<double>(st.lost_random), 4000.0, 300.0);
  EXPECT_EQ(ch.InFlight(), 0U);
  // a blocked (radio loss) frame is dropped and counted apart
  EXPECT_FALSE(ch.Send(2, Direction::kUplink, 0, Bytes(66, 1), true));
  EXPECT_EQ(ch.Stats(Direction::kUplink).lost_fault, 1U);
  // purge drops a train's frames in flight
  ch.Send(3, Direction::kDownlink, 0, Bytes(66, 1), false);
  ch.Purge(3);
  EXPECT_EQ(ch.InFlight(), 0U);
}

TEST(SimChannel, CorruptedFramesAreCorrectedOrRejectedByTheFrameDecoder) {
  // real frames: up to 8 symbol errors in a block are corrected, more are detected
  tg::TelegramHeader h{};
  h.version = tg::kVersion;
  h.type = tg::TelegramType::kPosition;
  h.src = 2;
  h.dst = 1;
  h.seq = 1;
  const std::vector<std::uint8_t> payload(40, 0x5A);
  const std::array<std::uint8_t, tg::kKeyBytes> kb{};
  const tg::LinkKey key(kb);
  tg::EncodedFrame frame{};
  ASSERT_EQ(tg::EncodeFrame(h, payload, key, frame), tg::EncodeStatus::kOk);
  Channel ch(ChannelConfig{0.0, 0, 0, 1.0}, 11);
  int corrected = 0;
  int rejected = 0;
  for (int k = 0; k < 400; ++k) {
    ch.Send(2, Direction::kUplink, k, frame.View(), false);
  }
  for (const Frame& f : ch.Deliver(1'000)) {
    ASSERT_GE(f.corrupted_symbols, 1U);
    ASSERT_LE(f.corrupted_symbols, 12U);
    tg::DecodedFrame out{};
    const auto r = tg::DecodeFrame(f.bytes, out);
    if (f.corrupted_symbols <= 8) {
      EXPECT_EQ(r, tg::RejectReason::kNone);
      ++corrected;
    } else {
      EXPECT_NE(r, tg::RejectReason::kNone);
      ++rejected;
    }
  }
  EXPECT_GT(corrected, 0);
  EXPECT_GT(rejected, 0);
  EXPECT_EQ(ch.Stats(Direction::kUplink).corrupted, 400U);
}

}  // namespace
}  // namespace railproof::sim
