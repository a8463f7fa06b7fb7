// Full receive path of the on-board endpoint (issue target: <= 50 us per 66-byte
// codeword on one core): RS(66,50) decoding with 8 symbol errors, CRC-16, AEAD open
// (ChaCha20-Poly1305) and the receiver/supervision state machine, for a genuine,
// fresh control telegram that is accepted. The frames are produced outside the timed
// region by a real ground endpoint that also receives the train's position reports, so
// that every timed telegram passes every check (sequence, echo, turnaround).
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"

namespace {

using namespace railproof::tg;  // NOLINT(google-build-using-namespace)

constexpr std::uint16_t kGroundId = 1;
constexpr std::uint16_t kTrainId = 42;

LinkKey BenchKey() {
  std::array<std::uint8_t, 32> k{};
  for (std::size_t i = 0; i < k.size(); ++i) {
    k[i] = static_cast<std::uint8_t>(0xA5U ^ (i * 7U));
  }
  return LinkKey(k);
}

// Overwrite `errors` symbols of every block with different values (within the decoder's
// radius when errors <= 8), at positions spread over the block.
void InjectSymbolErrors(EncodedFrame& f, unsigned errors, std::uint32_t salt) {
  for (std::size_t b = 0; b * kBlockBytes < f.size; ++b) {
    for (unsigned e = 0; e < errors; ++e) {
      const std::size_t pos = b * kBlockBytes + (e * 8U + salt % 8U) % kBlockBytes;
      f.bytes[pos] = static_cast<std::uint8_t>(f.bytes[pos] ^ (0x5AU + e + salt));
      if (f.bytes[pos] == 0) {
        f.bytes[pos] = 1;  // keep it a change even if xor produced the original
      }
    }
  }
}

struct Link {
  Endpoint ground;
  Endpoint train;
  std::uint32_t now = 0;
  EncodedFrame g_frame{};
  EncodedFrame t_frame{};
  std::array<std::uint8_t, kPayloadMax> out{};

  Link() {
    const LinkKey key = BenchKey();
    EndpointConfig g = railproof::tg::DeploymentConfig(Role::kGround, kGroundId, kTrainId);
    EndpointConfig t = railproof::tg::DeploymentConfig(Role::kTrain, kTrainId, kGroundId);
    if (ground.Init(g, key) != railproof::tg::ConfigError::kNone ||
        train.Init(t, key) != railproof::tg::ConfigError::kNone) {
      std::abort();
    }
  }

  // One cycle of both endpoints; the train's report reaches the ground at once, so the
  // ground's next control telegram echoes a fresh position sequence number.
  void Step() {
    now += static_cast<std::uint32_t>(railproof::params::tg::ground_cycle_ms);
    train.Cycle(now, {}, t_frame);
    ground.Receive(now, t_frame.View(), out);
    ground.Cycle(now, {}, g_frame);
  }
};

void BM_ReceivePath(benchmark::State& state) {
  const auto errors = static_cast<unsigned>(state.range(0));
  Link link;
  for (int i = 0; i < 4; ++i) {  // handshake: both links up
    link.Step();
    link.train.Receive(link.now, link.g_frame.View(), link.out);
  }
  std::uint32_t salt = 0;
  std::int64_t accepted = 0;
  for (auto _ : state) {
    state.PauseTiming();
    link.Step();
    InjectSymbolErrors(link.g_frame, errors, ++salt);
    state.ResumeTiming();
    const auto r = link.train.Receive(link.now, link.g_frame.View(), link.out);
    benchmark::DoNotOptimize(r);
    accepted += (r.reason == RejectReason::kNone) ? 1 : 0;
  }
  if (accepted != static_cast<std::int64_t>(state.iterations())) {
    state.SkipWithError("a genuine telegram was not accepted: the benchmark is not measuring the full path");
  }
  state.counters["blocks"] = static_cast<double>(link.g_frame.size / kBlockBytes);
}
BENCHMARK(BM_ReceivePath)->Arg(0)->Arg(8)->Unit(benchmark::kMicrosecond);

}  // namespace
