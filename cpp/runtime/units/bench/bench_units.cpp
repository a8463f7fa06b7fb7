// The two units' cycles (spec/design/units.md; issue targets on one core):
//   BM_OnboardUnitCycleWorstCase   one on-board cycle <= 100 us (0.1 % of its 100 ms cycle) in
//       its worst case: the odometry compensating with both parallel start points (a wheel
//       slipping at 12 m/s), the braking supervision evaluated in the cycle against a stop
//       limit 5 km ahead over a profile of 60 gradient and 40 line-limit segments and the four
//       restrictions of the last stop-limit telegram, 32 crossings ahead of the train, one
//       telegram received (a stop limit with four restrictions and a crossing report: as many
//       as one payload carries with it) and one
//       sent (the position report). Supervision and radio are configured to run every cycle so
//       that every timed cycle does all of it. Counters: the 99.9th percentile and the slowest
//       single cycle (with the machine's interruptions in it), and worst_cycle_us, the
//       scenario's slowest cycle with each cycle at its fastest over the identical runs (the
//       unit's worst-case work as measured; a measurement, not a static timing analysis).
//   BM_WaysideUnitCycle            one ground cycle of the wayside unit with 1,000 trains on the
//       10,000 blocks of the moving-block benchmark line (bench_line.hpp): every train's position
//       report received through its radio endpoint (Reed-Solomon decoding of a frame with bit
//       errors at the design bit error rate 1e-3, CRC, AEAD, the receiver's checks, the codec),
//       then Cycle (tracking, interlocking, stop limits, one telegram encoded and sealed per
//       train) <= 25 ms (5 % of the 500 ms ground cycle).
// Both use manual time: only the units' own calls are timed; the peers that produce and read
// the frames, and any restart of the scenario, are not.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <span>
#include <vector>

#include "../../mb/bench/bench_line.hpp"
#include "../../ra/bench/slip_stream.hpp"
#include "railproof/generated/tg_params.hpp"
#include "railproof/messages/codec.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/units/onboard_unit.hpp"
#include "railproof/units/wayside_unit.hpp"

namespace {

namespace ru = railproof::units;
namespace rm = railproof::messages;
namespace tg = railproof::tg;
namespace core = railproof::core;
namespace ra = railproof::ra;

using Clock = std::chrono::steady_clock;

constexpr std::uint16_t kGroundId = 1;

std::array<std::uint8_t, tg::kKeyBytes> KeyOf(std::uint32_t id) {
  std::array<std::uint8_t, tg::kKeyBytes> k{};
  for (std::size_t i = 0; i < k.size(); ++i) {
    k[i] = static_cast<std::uint8_t>(0xA5U ^ (id * 31U + i * 7U));
  }
  return k;
}

// ---- on-board unit --------------------------------------------------------------------------

constexpr std::uint32_t kTrainId = 42;
constexpr std::int64_t kLineMm = 20'000'000;
constexpr std::int64_t kLookAheadMm = 5'000'000;

// A 20 km line: 100 m blocks, 60 gradient segments (+-5 per mille), 40 line limits (16.7 to
// 27.8 m/s), a balise every km, 32 crossings between 1.5 km and 17 km, one level odometry
// section.
struct OnboardLine {
  std::vector<std::int64_t> blocks;
  std::vector<core::GradientSegment> gradients;
  std::vector<core::RestrictionSegment> limits;
  std::vector<ru::BaliseEntry> balises;
  std::vector<railproof::lc::CrossingData> crossings;
  std::vector<ra::OdometrySection> sections{{0, kLineMm, 0, 20'000, 0}};
  OnboardLine() {
    for (std::int64_t b = 0; b <= kLineMm; b += 100'000) {
      blocks.push_back(b);
    }
    const std::int64_t g = kLineMm / 60;
    for (std::int64_t i = 0; i < 60; ++i) {
      gradients.push_back({i * g, (i + 1) * g, i % 2 == 0 ? 50 : -50});
    }
    const std::int64_t l = kLineMm / 40;
    for (std::int64_t i = 0; i < 40; ++i) {
      limits.push_back({i * l, (i + 1) * l, 16'667 + (i % 4) * 3'704});
    }
    for (std::uint32_t km = 1; km < 20; ++km) {
      balises.push_back({km, static_cast<std::int64_t>(km) * 1'000'000});
    }
    for (std::uint32_t c = 0; c < 32; ++c) {
      const std::int64_t at = 1'500'000 + static_cast<std::int64_t>(c) * 480'000;
      crossings.push_back({c + 1, at, at + 10'000, 30'000});
    }
  }
};

ru::OnboardConfig OnboardBenchConfig(const OnboardLine& line) {
  ru::OnboardConfig c;
  c.train_id = kTrainId;
  c.train = railproof::br::TrainData{.length_mm = 60'000,
                                     .accel_max_mm_s2 = 1'000,
                                     .beta_e_mm_s2 = 1'100,
                                     .beta_n7_mm_s2 = 900,
                                     .emergency_free_running_ms = 1'500,
                                     .service_free_running_ms = 2'500,
                                     .overspeed_mm_s = 2'778,
                                     .speed_error_ppm = 20'000,
                                     .speed_error_abs_mm_s = 200};
  c.supervision.cycle_ms = ru::kOnboardCycleMs;  // supervise in every (timed) cycle
  c.odometry.method = ra::Method::kImu;
  c.initial_front_mm = 1'000'000;
  c.line = ru::LineData{line.blocks, line.gradients, line.limits, line.balises, line.crossings, line.sections};
  c.radio = tg::DeploymentConfig(tg::Role::kTrain, static_cast<std::uint16_t>(kTrainId), kGroundId);
  c.link_key.emplace(KeyOf(kTrainId));
  c.radio_period_ms = ru::kOnboardCycleMs;  // a telegram in every (timed) cycle
  return c;
}

// The ground's end of the train's link: reads every telegram of the unit and answers it with a
// stop limit 5 km ahead of the reported front (four restrictions) and a report of the nearest
// crossing ahead, closed for the train.
class GroundPeer {
 public:
  explicit GroundPeer(const tg::EndpointConfig& train_side) {
    tg::EndpointConfig g = train_side;
    g.role = tg::Role::kGround;
    std::swap(g.own_id, g.peer_id);
    if (endpoint_.Init(g, tg::LinkKey(KeyOf(kTrainId))) != tg::ConfigError::kNone) {
      std::abort();
    }
  }
  void Hear(std::int64_t now_ms, std::span<const std::uint8_t> frame) {
    std::array<std::uint8_t, tg::kPayloadMax> payload{};
    (void)endpoint_.Receive(static_cast<std::uint32_t>(now_ms), frame, payload);
  }
  std::span<const std::uint8_t> Answer(std::int64_t now_ms, std::int64_t front_mm) {
    rm::StopLimitTelegram t{};
    t.train_id = kTrainId;
    t.limit_mm = std::min(kLineMm - 1'000, front_mm + kLookAheadMm);
    t.kind = rm::Obstruction::kPrecedingTrain;
    t.issue_time_ms = now_ms;
    t.restriction_count = 4;
    for (std::uint32_t i = 0; i < 4; ++i) {
      const std::int64_t begin = front_mm + 400'000 + static_cast<std::int64_t>(i) * 700'000;
      t.restrictions[i] = rm::SpeedRestriction{i + 1, begin, begin + 300'000, 11'111};
    }
    rm::CrossingReport r{};
    r.crossing_id = NextCrossing(front_mm);
    r.status = rm::CrossingStatus::kClosed;
    r.warning_start_ms = now_ms - 30'000;
    r.issued_ms = now_ms;
    r.requesters[0] = kTrainId;
    r.requester_count = 1;
    const std::array<rm::Message, 2> bundle = {rm::Message{t}, rm::Message{r}};
    const rm::Encoded e = rm::EncodeBundle(bundle);
    if (!e.Ok()) {
      std::fprintf(stderr, "bench_units: the ground's bundle is refused: %s\n", rm::ToString(e.error));
      std::abort();
    }
    endpoint_.Cycle(static_cast<std::uint32_t>(now_ms), e.payload.View(), frame_);
    return frame_.View();
  }

 private:
  static std::uint32_t NextCrossing(std::int64_t front_mm) {
    const std::int64_t k = (front_mm - 1'500'000) / 480'000 + 1;
    return static_cast<std::uint32_t>(std::clamp<std::int64_t>(k + 1, 1, 32));
  }
  tg::Endpoint endpoint_;
  tg::EncodedFrame frame_{};
};

// The unit and its ground, run through the slip stream: untimed up to the slip, then one
// timed cycle per benchmark iteration while the odometry compensates with both start points.
class OnboardScenario {
 public:
  OnboardScenario() : config_(OnboardBenchConfig(line_)), peer_(config_.radio) {
    auto created = ru::OnboardUnit::Create(config_);
    if (created.check.error != ru::OnboardConfigError::kNone) {
      std::fprintf(stderr, "bench_units: the on-board configuration is refused: %s (entry %zu)\n",
                   ru::ToString(created.check.error), created.check.entry);
      std::abort();
    }
    unit_.emplace(std::move(*created.unit));
    stream_ = ra::bench::MakeStream(WarmupCycles(), 400, 200, false);
  }
  static int WarmupCycles() {
    // the odometry's warm-up as its configuration gives it (REQ-RA-015): moving averages and the
    // TG window, in cycles
    return static_cast<int>((railproof::params::ra::moving_average_ms + railproof::params::ra::tg_window_ms) /
                            railproof::params::ra::cycle_ms);
  }
  // Runs untimed cycles until the odometry compensates with both start points; false at the
  // stream's end.
  bool ToCompensation() {
    while (next_ < stream_.size()) {
      if (TwoCandidates()) {
        return true;
      }
      (void)Cycle(nullptr);
    }
    return false;
  }
  [[nodiscard]] bool TwoCandidates() const {
    const ra::OdometryOutput& o = unit_->Odometry();
    return o.mode == ra::Mode::kCompensating && o.v_comp[0] > 0.0 && o.v_comp[1] > 0.0;
  }
  [[nodiscard]] bool Exhausted() const { return next_ >= stream_.size(); }
  // One cycle; with `state`, the unit's Cycle is timed.
  const ru::OnboardOutputs& Cycle(benchmark::State* state) {
    ru::OnboardInputs in;
    in.sensors = stream_[next_++];
    in.now_ms = in.sensors.time_ms;
    std::array<std::span<const std::uint8_t>, 1> frames{};
    if (!pending_.empty()) {
      frames[0] = pending_;
      in.frames = frames;
    }
    const auto t0 = Clock::now();
    const ru::OnboardOutputs& out = unit_->Cycle(in);
    benchmark::DoNotOptimize(out);
    const auto t1 = Clock::now();
    if (state != nullptr) {
      const double seconds = std::chrono::duration<double>(t1 - t0).count();
      state->SetIterationTime(seconds);
      times_s_.push_back(seconds);
      received_ += frames[0].empty() ? 0U : 1U;
      sent_ += out.sent ? 1U : 0U;
      supervised_ += out.authority_usable ? 1U : 0U;
    }
    if (out.sent) {
      peer_.Hear(out.now_ms, out.frame.View());
    }
    const auto answer = peer_.Answer(out.now_ms, out.front_mm);
    pending_.assign(answer.begin(), answer.end());
    return out;
  }
  std::uint64_t received_ = 0;
  std::uint64_t sent_ = 0;
  std::uint64_t supervised_ = 0;
  std::vector<double> times_s_;  // every timed cycle

 private:
  OnboardLine line_;
  ru::OnboardConfig config_;
  GroundPeer peer_;
  std::optional<ru::OnboardUnit> unit_;
  std::vector<ra::CycleInput> stream_;
  std::size_t next_ = 0;
  std::vector<std::uint8_t> pending_;
};

void BM_OnboardUnitCycleWorstCase(benchmark::State& state) {
  auto sc = std::make_unique<OnboardScenario>();
  if (!sc->ToCompensation()) {
    state.SkipWithError("the odometry never compensated with both start points");
    return;
  }
  std::uint64_t timed = 0, received = 0, sent = 0, supervised = 0;
  std::vector<double> times;
  // per cycle of the scenario (its index from the start of compensation), the fastest of its
  // runs: the scenario is deterministic, so every run does the same work in its i-th cycle,
  // and an interruption of the process (another process, the hypervisor) only adds time
  std::vector<double> fastest;
  std::size_t runs = 0;
  const auto collect = [&](const OnboardScenario& s) {
    times.insert(times.end(), s.times_s_.begin(), s.times_s_.end());
    if (s.Exhausted() || !s.TwoCandidates()) {  // a whole run (the last may be cut short)
      ++runs;
      fastest.resize(std::max(fastest.size(), s.times_s_.size()), std::numeric_limits<double>::infinity());
      for (std::size_t i = 0; i < s.times_s_.size(); ++i) {
        fastest[i] = std::min(fastest[i], s.times_s_[i]);
      }
    }
  };
  for (auto _ : state) {
    if (sc->Exhausted() || !sc->TwoCandidates()) {
      state.PauseTiming();
      received += sc->received_;
      sent += sc->sent_;
      supervised += sc->supervised_;
      collect(*sc);
      sc = std::make_unique<OnboardScenario>();
      (void)sc->ToCompensation();
      state.ResumeTiming();
    }
    (void)sc->Cycle(&state);
    ++timed;
  }
  received += sc->received_;
  sent += sc->sent_;
  supervised += sc->supervised_;
  collect(*sc);
  // every timed cycle received a telegram, sent one and supervised a usable authority
  if (received != timed || sent != timed || supervised != timed) {
    state.SkipWithError("a timed cycle did not receive, send and supervise");
  }
  state.counters["crossings"] = 32;
  // the tail of the distribution: the 99.9th percentile and the slowest cycle (on a shared
  // machine the slowest includes the operating system's interruptions of the process)
  std::sort(times.begin(), times.end());
  if (!times.empty()) {
    state.counters["p99.9_us"] = times[times.size() * 999 / 1000] * 1e6;
    state.counters["longest_us"] = times.back() * 1e6;
  }
  // The worst cycle of the scenario, each cycle taken at its fastest over the runs: the unit's
  // own worst-case work, which the slowest single sample above cannot separate from the
  // interruptions of a shared machine.
  if (runs >= 3 && !fastest.empty()) {
    state.counters["worst_cycle_us"] = *std::max_element(fastest.begin(), fastest.end()) * 1e6;
    state.counters["runs"] = static_cast<double>(runs);
  }
  state.SetLabel("compensating (2 start points), 5 km look-ahead, 32 crossings, 1 telegram in + 1 out");
}
BENCHMARK(BM_OnboardUnitCycleWorstCase)->UseManualTime()->Unit(benchmark::kMicrosecond);

// ---- wayside unit ---------------------------------------------------------------------------

constexpr std::int64_t kTrains = 1'000;

bool BenchKeys(const void* /*context*/, std::uint32_t train_id, std::array<std::uint8_t, tg::kKeyBytes>& key) {
  key = KeyOf(train_id);
  return true;
}

// Flips every bit of the frame with probability `ber` (the channel at the design bit error
// rate; the Reed-Solomon code corrects up to 8 symbols a block).
void ApplyBitErrors(tg::EncodedFrame& f, double ber, std::mt19937_64& rng) {
  std::bernoulli_distribution flip(ber);
  for (std::size_t i = 0; i < f.size; ++i) {
    for (unsigned b = 0; b < 8; ++b) {
      if (flip(rng)) {
        f.bytes[i] = static_cast<std::uint8_t>(f.bytes[i] ^ (1U << b));
      }
    }
  }
}

class WaysideScenario {
 public:
  WaysideScenario() {
    ru::WaysideConfig c;
    c.keys = BenchKeys;
    c.line = line_.Config();
    c.capacity = railproof::mb::wayside::DefaultCapacity();
    c.capacity.blocks = line_.blocks.size() - 1;
    c.capacity.handovers = line_.handovers.size();
    c.secure_ahead_mm = 500'000;
    auto created = ru::WaysideUnit::Create(c);
    if (created.error != ru::ConfigError::kNone) {
      std::abort();
    }
    unit_ = std::move(created.unit);
    const std::int64_t spacing = 480'000'000 / kTrains;
    for (std::int64_t i = 0; i < kTrains; ++i) {
      const auto id = static_cast<std::uint32_t>(i + 1);
      const auto radio = static_cast<std::uint16_t>(100 + i);
      const std::int64_t front = 10'000'000 + i * spacing + kLengthMm;
      if (unit_->Admit(id, radio) != ru::AdmitStatus::kAdmitted ||
          unit_->Register({id, kLengthMm, front, 500, railproof::mb::wayside::InitialPosition::kEntryBalise}).status !=
              ru::RegisterStatus::kRegistered) {
        std::abort();
      }
      tg::EndpointConfig tc = tg::DeploymentConfig(tg::Role::kTrain, radio, kGroundId);
      auto& t = trains_.emplace_back();
      t.id = id;
      t.front_mm = front;
      if (t.endpoint.Init(tc, tg::LinkKey(KeyOf(id))) != tg::ConfigError::kNone) {
        std::abort();
      }
    }
    frames_.resize(trains_.size());
    Prepare();
  }

  // The trains' telegrams of the next cycle (untimed): each train's position report, framed by
  // its endpoint, with bit errors at the design rate.
  void Prepare() {
    now_ += ru::kGroundCycleMs;
    for (std::size_t i = 0; i < trains_.size(); ++i) {
      Train& t = trains_[i];
      const auto loc = unit_->Ground().LocateFront(t.front_mm);
      const rm::PositionReport r{t.id, loc->block, loc->offset_mm, kLengthMm, 500, 0, 10'000,
                                 rm::Direction::kNominal};
      const rm::Encoded e = rm::Encode(rm::Message{r});
      (void)t.endpoint.Cycle(static_cast<std::uint32_t>(now_), e.payload.View(), frames_[i]);
      ApplyBitErrors(frames_[i], railproof::params::tg::design_ber, rng_);
    }
  }

  // One ground cycle: every train's telegram received, then Cycle; timed with `state`.
  void Cycle(benchmark::State* state) {
    const auto t0 = Clock::now();
    for (std::size_t i = 0; i < trains_.size(); ++i) {
      const ru::ReceiveResult r = unit_->Receive(now_, trains_[i].id, frames_[i].View());
      accepted_ += r.status == ru::FrameStatus::kAccepted ? 1U : 0U;
    }
    const ru::CycleOutput& out = unit_->Cycle(now_, ru::CycleInput{});
    benchmark::DoNotOptimize(out);
    const auto t1 = Clock::now();
    if (state == nullptr) {
      accepted_ = 0;
    } else {
      state->SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
      sent_ += out.frames.Size();
    }
    // the trains read their telegrams (keeps their echoes fresh), then prepare the next cycle
    for (const ru::TrainFrame& f : out.frames) {
      std::array<std::uint8_t, tg::kPayloadMax> payload{};
      (void)trains_[f.train_id - 1].endpoint.Receive(static_cast<std::uint32_t>(now_), f.frame.View(), payload);
    }
    Prepare();
  }
  std::uint64_t accepted_ = 0;
  std::uint64_t sent_ = 0;

 private:
  static constexpr std::int64_t kLengthMm = 200'000;
  struct Train {
    std::uint32_t id = 0;
    std::int64_t front_mm = 0;
    tg::Endpoint endpoint;
  };
  railproof::mb::wayside::bench::BenchLine line_;
  std::unique_ptr<ru::WaysideUnit> unit_;
  std::vector<Train> trains_;
  std::vector<tg::EncodedFrame> frames_;
  std::int64_t now_ = 0;
  std::mt19937_64 rng_{20261127};
};

void BM_WaysideUnitCycle(benchmark::State& state) {
  WaysideScenario sc;
  for (int k = 0; k < 4; ++k) {
    sc.Cycle(nullptr);  // untimed: the links come up (the first telegrams carry no echo yet)
  }
  std::uint64_t cycles = 0;
  for (auto _ : state) {
    sc.Cycle(&state);
    ++cycles;
  }
  if (sc.accepted_ != cycles * static_cast<std::uint64_t>(kTrains)) {
    state.SkipWithError("a train's telegram was not accepted in a timed cycle");
  }
  state.counters["trains"] = static_cast<double>(kTrains);
  state.counters["blocks"] = static_cast<double>(railproof::mb::wayside::bench::kBlocks);
  state.counters["accepted_per_cycle"] = static_cast<double>(sc.accepted_) / static_cast<double>(cycles);
  state.counters["telegrams_per_cycle"] = static_cast<double>(sc.sent_) / static_cast<double>(cycles);
  state.SetLabel("1,000 trains, 10,000 blocks, BER 1e-3");
}
BENCHMARK(BM_WaysideUnitCycle)->UseManualTime()->Unit(benchmark::kMillisecond);

}  // namespace
