#include "railproof/sim/channel.hpp"

#include <algorithm>

#include "railproof/tg/telegram.hpp"

namespace railproof::sim {

namespace {
std::uint64_t SplitMix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31U);
}
std::uint64_t Rotl(std::uint64_t x, unsigned k) { return (x << k) | (x >> (64U - k)); }

constexpr std::uint32_t kMaxCorruptSymbols = 12;  // RS(66,50) corrects 8: 9..12 are rejected
}  // namespace

Prng::Prng(std::uint64_t seed) {
  std::uint64_t x = seed;
  for (auto& s : s_) {
    s = SplitMix64(x);
  }
}

std::uint64_t Prng::Next() {
  const std::uint64_t result = Rotl(s_[1] * 5U, 7U) * 9U;
  const std::uint64_t t = s_[1] << 17U;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = Rotl(s_[3], 45U);
  return result;
}

double Prng::Uniform() { return static_cast<double>(Next() >> 11U) * 0x1.0p-53; }

std::int64_t Prng::UniformInt(std::int64_t lo, std::int64_t hi) {
  if (hi <= lo) {
    return lo;
  }
  const auto span = static_cast<std::uint64_t>(hi - lo) + 1U;
  // Lemire's nearly-divisionless method would avoid the bias; for spans below 2^32 the
  // bias of a 64-bit modulo is below 2^-32, irrelevant here.
  return lo + static_cast<std::int64_t>(Next() % span);
}

bool Prng::Bernoulli(double p) { return Uniform() < p; }

Channel::Channel(const ChannelConfig& config, std::uint64_t seed) : config_(config), prng_(seed) {}

bool Channel::Send(std::uint16_t train, Direction direction, std::int64_t now_ms, std::span<const std::uint8_t> bytes,
                   bool blocked, std::size_t wayside) {
  ChannelStats& st = direction == Direction::kUplink ? up_ : down_;
  ++st.sent;
  if (blocked) {
    ++st.lost_fault;
    return false;
  }
  const bool lost = prng_.Bernoulli(config_.loss_probability);
  const std::int64_t delay = prng_.UniformInt(config_.min_delay_ms, config_.max_delay_ms);
  const bool corrupt = prng_.Bernoulli(config_.corrupt_probability);
  if (lost) {
    ++st.lost_random;
    return false;
  }
  Frame f;
  f.train = train;
  f.wayside = wayside;
  f.direction = direction;
  f.sent_ms = now_ms;
  f.due_ms = now_ms + delay;
  f.order = order_++;
  f.bytes.assign(bytes.begin(), bytes.end());
  if (corrupt && f.bytes.size() >= tg::kBlockBytes) {
    ++st.corrupted;
    const auto blocks = static_cast<std::int64_t>(f.bytes.size() / tg::kBlockBytes);
    const auto block = static_cast<std::size_t>(prng_.UniformInt(0, blocks - 1));
    const auto count = static_cast<std::uint32_t>(prng_.UniformInt(1, kMaxCorruptSymbols));
    std::vector<std::size_t> positions;
    while (positions.size() < count) {  // distinct symbol positions in the block
      const auto pos = static_cast<std::size_t>(prng_.UniformInt(0, static_cast<std::int64_t>(tg::kBlockBytes) - 1));
      if (std::find(positions.begin(), positions.end(), pos) == positions.end()) {
        positions.push_back(pos);
      }
    }
    for (const std::size_t pos : positions) {
      const auto flip = static_cast<std::uint8_t>(prng_.UniformInt(1, 255));  // never 0: a real error
      f.bytes[block * tg::kBlockBytes + pos] ^= flip;
    }
    f.corrupted_symbols = count;
  }
  in_flight_.push_back(std::move(f));
  return true;
}

std::vector<Frame> Channel::Deliver(std::int64_t now_ms) {
  std::vector<Frame> due;
  auto it = std::stable_partition(in_flight_.begin(), in_flight_.end(), [&](const Frame& f) { return f.due_ms > now_ms; });
  due.assign(std::make_move_iterator(it), std::make_move_iterator(in_flight_.end()));
  in_flight_.erase(it, in_flight_.end());
  std::sort(due.begin(), due.end(), [](const Frame& a, const Frame& b) {
    return a.due_ms != b.due_ms ? a.due_ms < b.due_ms : a.order < b.order;
  });
  for (const auto& f : due) {
    ++(f.direction == Direction::kUplink ? up_ : down_).delivered;
  }
  return due;
}

void Channel::Purge(std::uint16_t train) {
  std::erase_if(in_flight_, [&](const Frame& f) { return f.train == train; });
}

}  // namespace railproof::sim
