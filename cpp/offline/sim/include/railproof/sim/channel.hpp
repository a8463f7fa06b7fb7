// Simulated radio channel of the line simulation: carries encoded telegram frames
// (tg::EncodedFrame bytes, RS + CRC + AEAD) between the ground and the on-board units,
// loses each one with a fixed probability, delays it uniformly in [min, max] ms (frames
// may overtake each other) and optionally corrupts symbols of one RS block. Every random
// draw comes from one seeded PRNG (xoshiro256**, seeded by SplitMix64), so a run is
// reproducible bit for bit on every platform. Offline module.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace railproof::sim {

// xoshiro256** (Blackman, Vigna), seeded by SplitMix64: portable and deterministic.
class Prng {
 public:
  explicit Prng(std::uint64_t seed);
  std::uint64_t Next();
  double Uniform();                              // [0, 1)
  std::int64_t UniformInt(std::int64_t lo, std::int64_t hi);  // [lo, hi]
  bool Bernoulli(double p);

 private:
  std::uint64_t s_[4];
};

enum class Direction : std::uint8_t { kUplink, kDownlink };  // train -> ground, ground -> train

struct ChannelConfig {
  double loss_probability = 0.0;
  std::int64_t min_delay_ms = 0;
  std::int64_t max_delay_ms = 0;
  double corrupt_probability = 0.0;
};

struct Frame {
  std::uint16_t train = 0;  // the train whose link carries it
  std::size_t wayside = 0;  // the wayside unit at the link's other end (index)
  Direction direction = Direction::kUplink;
  std::int64_t sent_ms = 0;
  std::int64_t due_ms = 0;
  std::uint64_t order = 0;  // send order, breaks ties of due_ms
  std::uint32_t corrupted_symbols = 0;
  std::vector<std::uint8_t> bytes;
};

struct ChannelStats {
  std::uint64_t sent = 0;
  std::uint64_t lost_random = 0;
  std::uint64_t lost_fault = 0;  // dropped by an injected radio loss
  std::uint64_t corrupted = 0;
  std::uint64_t delivered = 0;
};

class Channel {
 public:
  Channel(const ChannelConfig& config, std::uint64_t seed);

  // Sends a frame at now_ms. `blocked` (an injected radio loss) drops it without drawing
  // from the PRNG, so a fault window does not shift the random sequence of other links.
  // Returns false if the frame was lost.
  bool Send(std::uint16_t train, Direction direction, std::int64_t now_ms, std::span<const std::uint8_t> bytes,
            bool blocked, std::size_t wayside = 0);

  // Frames due at or before now_ms, by due time then send order; removed from the channel.
  std::vector<Frame> Deliver(std::int64_t now_ms);

  // Drops every frame in flight for a train (e.g. the train left the line).
  void Purge(std::uint16_t train);

  [[nodiscard]] const ChannelStats& Stats(Direction d) const { return d == Direction::kUplink ? up_ : down_; }
  [[nodiscard]] std::size_t InFlight() const { return in_flight_.size(); }

 private:
  ChannelConfig config_;
  Prng prng_;
  std::uint64_t order_ = 0;
  std::vector<Frame> in_flight_;
  ChannelStats up_;
  ChannelStats down_;
};

}  // namespace railproof::sim
