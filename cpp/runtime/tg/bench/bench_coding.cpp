// Benchmarks of the link coding (REQ-TG-010, REQ-TG-005): RS(66,50) encode and decode,
// CRC-16 over one RS block (66 bytes) and over a long frame (200 bytes). Speed only; the
// behaviour is asserted by the unit tests.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "railproof/tg/crc16.hpp"
#include "railproof/tg/reed_solomon.hpp"

namespace {

using railproof::tg::Crc16;
using railproof::tg::ReedSolomon;
using railproof::tg::Rs6650;

std::array<std::uint8_t, 66> MakeCodeword(std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::array<std::uint8_t, 50> msg{};
  for (auto& b : msg) {
    b = static_cast<std::uint8_t>(rng() & 0xFFU);
  }
  std::array<std::uint8_t, 66> cw{};
  if (Rs6650().Encode(msg, cw) != railproof::tg::RsStatus::kOk) {
    cw.fill(0);
  }
  return cw;
}

// Decodes a copy of `word` in every iteration (the 66-byte copy is part of each iteration).
void DecodeCopies(benchmark::State& state, const std::array<std::uint8_t, 66>& word) {
  const ReedSolomon& rs = Rs6650();
  for (auto _ : state) {
    auto rx = word;
    benchmark::DoNotOptimize(rs.Decode(rx));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 66);
}

// Measures REQ-TG-010
void BM_Rs6650Encode(benchmark::State& state) {
  const ReedSolomon& rs = Rs6650();
  std::array<std::uint8_t, 50> msg{};
  for (unsigned i = 0; i < msg.size(); ++i) {
    msg[i] = static_cast<std::uint8_t>(i * 31U + 7U);
  }
  std::array<std::uint8_t, 66> cw{};
  for (auto _ : state) {
    benchmark::DoNotOptimize(rs.Encode(msg, cw));
    benchmark::ClobberMemory();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * 50);
}
BENCHMARK(BM_Rs6650Encode);

// Decode of an error-free block (syndromes only).
// Measures REQ-TG-010
void BM_Rs6650DecodeClean(benchmark::State& state) { DecodeCopies(state, MakeCodeword(1)); }
BENCHMARK(BM_Rs6650DecodeClean);

// Decode with t = 8 symbol errors (the full correction path: BM, Chien, Forney, re-check).
// Measures REQ-TG-010
void BM_Rs6650Decode8Errors(benchmark::State& state) {
  auto corrupted = MakeCodeword(2);
  const unsigned positions[8] = {0, 7, 13, 25, 38, 49, 57, 65};
  for (unsigned i = 0; i < 8U; ++i) {
    corrupted[positions[i]] = static_cast<std::uint8_t>(corrupted[positions[i]] ^ (0x11U * (i + 1U)));
  }
  DecodeCopies(state, corrupted);
}
BENCHMARK(BM_Rs6650Decode8Errors);

// Decode of a word beyond the radius (9 errors): rejected after BM / Chien.
// Measures REQ-TG-010
void BM_Rs6650Decode9ErrorsRejected(benchmark::State& state) {
  auto corrupted = MakeCodeword(3);
  for (unsigned i = 0; i < 9U; ++i) {
    corrupted[i * 7U] = static_cast<std::uint8_t>(corrupted[i * 7U] ^ (0x23U + i));
  }
  DecodeCopies(state, corrupted);
}
BENCHMARK(BM_Rs6650Decode9ErrorsRejected);

// Measures REQ-TG-005
void BM_Crc16(benchmark::State& state) {
  std::vector<std::uint8_t> data(static_cast<std::size_t>(state.range(0)));
  for (std::size_t i = 0; i < data.size(); ++i) {
    data[i] = static_cast<std::uint8_t>(i * 13U + 1U);
  }
  for (auto _ : state) {
    benchmark::DoNotOptimize(Crc16(data));
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * state.range(0));
}
BENCHMARK(BM_Crc16)->Arg(66)->Arg(200);

}  // namespace
