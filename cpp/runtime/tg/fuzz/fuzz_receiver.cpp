// libFuzzer target: the receiver / link-supervision state machine of a train Endpoint
// (spec/design/tg.md §4, §5) driven by a script. The genuine peer is a real
// ground Endpoint holding the same fuzz link key; the script decides when each side
// cycles, how time advances and what reaches the train: genuine frames (in any order,
// repeated, delayed), genuine frames with channel errors or surgery, forged frames sealed
// with the attacker's key, and raw bytes. Deployment configuration (sequence modulus 2^32),
// so no sequence number wraps back within one input.
//
// Script (all integers big-endian; the run stops where the input ends):
//   bytes 0-3 start clock (ms), 4-7 train initial seq, 8-11 ground initial seq; then ops,
//   one byte each: kind = b & 7, arg = b >> 3:
//     0 advance time by kDeltas[arg], or by a u16 that follows if arg == 31
//     1 train cycles            2 ground cycles (its frame joins the genuine ring)
//     3 train receives genuine frame arg % 16 back from the newest, intact
//     4 same, mutated: mode byte m, seed byte s follow; m & 3: 0 up to t symbol errors per
//       block, 1 t+1 .. t+4 errors in one block, 2 one bit of the inner frame flipped with
//       CRC repaired and RS re-applied, 3 seq/echo/flags field overwritten likewise
//     5 ground receives train frame arg % 8 back from the newest
//     6 train receives raw bytes: u16 length n (capped at kRxMax), then n bytes
//     7 train receives a forged frame sealed with the attacker key: seq u32, echo u32,
//       flags byte (bit 0 echo valid, bit 1 from another train, bit 2 copy seq/echo of the
//       newest genuine frame)
//
// Oracles (each violation prints "railproof-fuzz: oracle violated: ..." and traps):
//  - an accepted telegram is one the genuine ground sent (header and payload), REQ-TG-007,
//    REQ-TG-003, REQ-TG-005;
//  - accepted telegrams are strictly in sending order: no repetition, no re-sequencing,
//    REQ-TG-001, REQ-TG-004;
//  - the echo of an accepted telegram names one of the train's last history_depth sends,
//    sent at most turnaround_ms before (true age from the script's clock), REQ-TG-006,
//    REQ-TG-008, REQ-TG-009;
//  - after every call the link is UP only if a telegram was accepted at most
//    link_timeout_ms before, REQ-TG-013; emergency brake and tracking abnormal equal
//    link != UP, REQ-TG-014, REQ-TG-015;
//  - only authentic telegrams pass checks 1-6; every train telegram echoes exactly the last
//    of them while it is at most echo_validity_ms old, and otherwise carries no echo,
//    REQ-TG-012;
//  - a rejected telegram exposes nothing (payload and header zero, no gap unless in
//    sequence), REQ-TG-018.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fuzz_common.hpp"
#include "railproof/tg/endpoint.hpp"

namespace {

namespace rf = railproof::fuzz;
namespace rr = railproof::tg;

constexpr std::array<std::uint32_t, 31> kDeltas = {
    0,    1,    2,    10,   100,  250,  499,  500,  501,  999,  1000, 1001, 1500, 1999, 2000, 2500,
    2998, 2999, 3000, 3001, 3002, 3500, 4000, 5999, 6000, 6001, 9000, 10000, 30000, 60000, 65535};
constexpr std::size_t kGenuineRing = 16;
constexpr std::size_t kTrainRing = 8;
constexpr std::size_t kMaxLog = 8192;  // ground and train sends per input
constexpr std::size_t kGroundPayload = 16;
constexpr auto kOtherTrainId = static_cast<std::uint16_t>(railproof::params::tg::model::model_other_train_id);
constexpr std::uint32_t kHistory = static_cast<std::uint32_t>(railproof::params::tg::history_depth);

struct Reader {
  std::span<const std::uint8_t> data;
  std::size_t at = 0;
  bool Has(std::size_t n) const { return data.size() - at >= n; }
  std::uint8_t U8() { return data[at++]; }
  std::uint16_t U16() {
    const auto hi = static_cast<std::uint16_t>(U8());
    return static_cast<std::uint16_t>((hi << 8U) | U8());
  }
  std::uint32_t U32() {
    const std::uint32_t hi = U16();
    return (hi << 16U) | U16();
  }
};

struct GenuineTelegram {
  rr::TelegramHeader header;
  std::array<std::uint8_t, kGroundPayload> payload;
};

std::array<std::uint8_t, kGroundPayload> GroundPayload(std::uint32_t index) {
  std::array<std::uint8_t, kGroundPayload> p{};
  p[0] = static_cast<std::uint8_t>(index >> 24U);
  p[1] = static_cast<std::uint8_t>(index >> 16U);
  p[2] = static_cast<std::uint8_t>(index >> 8U);
  p[3] = static_cast<std::uint8_t>(index);
  for (std::size_t i = 4; i < p.size(); ++i) {
    p[i] = static_cast<std::uint8_t>(0xC3U ^ (29U * i + 13U * index));
  }
  return p;
}

class Run {
 public:
  explicit Run(Reader& in) : in_(in) {}

  void Execute() {
    if (!in_.Has(12)) {
      return;
    }
    clock_ = 0;
    t0_ = in_.U32();
    const std::uint32_t train_seq = in_.U32();
    const std::uint32_t ground_seq = in_.U32();
    rr::EndpointConfig tc = rr::DeploymentConfig(rr::Role::kTrain, rf::kTrainId, rf::kGroundId);
    tc.initial_seq = train_seq;
    rr::EndpointConfig gc = rr::DeploymentConfig(rr::Role::kGround, rf::kGroundId, rf::kTrainId);
    gc.initial_seq = ground_seq;
    if (train_.Init(tc, rf::FuzzKey()) != rr::ConfigError::kNone ||
        ground_.Init(gc, rf::FuzzKey()) != rr::ConfigError::kNone) {
      rf::OracleViolation("deployment configuration rejected");
    }
    config_ = tc;
    while (in_.Has(1) && genuine_.size() < kMaxLog && train_sends_.size() < kMaxLog) {
      const std::uint8_t op = in_.U8();
      const unsigned arg = op >> 3U;
      switch (op & 7U) {
        case 0: Advance(arg); break;
        case 1: TrainCycle(); break;
        case 2: GroundCycle(); break;
        case 3: DeliverGenuine(arg, false); break;
        case 4: DeliverGenuine(arg, true); break;
        case 5: DeliverToGround(arg); break;
        case 6: DeliverRaw(); break;
        default: DeliverForged(); break;
      }
    }
  }

 private:
  std::uint32_t Now() const { return static_cast<std::uint32_t>(t0_ + clock_); }

  void Advance(unsigned arg) {
    if (arg < kDeltas.size()) {
      clock_ += kDeltas[arg];
    } else if (in_.Has(2)) {
      clock_ += in_.U16();
    }
  }

  void CheckOutputs(rr::LinkState link, bool eb, bool abnormal) const {
    const bool down = link != rr::LinkState::kUp;
    if (eb != down || abnormal != down) {
      rf::OracleViolation("emergency brake / tracking abnormal differ from link != UP");
    }
    if (link == rr::LinkState::kUp && (!accepted_any_ || clock_ - last_accept_clock_ > config_.link_timeout_ms)) {
      rf::OracleViolation("link UP more than link_timeout_ms after the last acceptance");
    }
    if (link == rr::LinkState::kNone && accepted_any_) {
      rf::OracleViolation("link NONE after an acceptance");
    }
  }

  void TrainCycle() {
    rr::EncodedFrame frame{};
    const std::array<std::uint8_t, 4> payload = {0x50, 0x4f, 0x53, 0x21};
    const auto out = train_.Cycle(Now(), payload, frame);
    if (out.status != rr::SendStatus::kSent) {
      rf::OracleViolation("train cycle did not send");
    }
    CheckOutputs(out.link, out.emergency_brake, out.tracking_abnormal);
    // Sending rule (REQ-TG-012, the model's R_GUARANTEE_ECHO_AGE): echo exactly the last
    // in-sequence peer number, and only while it is at most echo_validity_ms old.
    const bool fresh = in_sequence_any_ && clock_ - in_sequence_clock_ <= config_.echo_validity_ms;
    if (out.tx.echo_valid != fresh) {
      rf::OracleViolation(fresh ? "echo withheld although the peer number is fresh"
                                : "echo sent although older than echo_validity_ms");
    }
    if (out.tx.echo_valid && out.tx.echo != in_sequence_seq_) {
      rf::OracleViolation("echo is not the last in-sequence peer number");
    }
    if (train_sends_.empty()) {
      first_train_seq_ = out.tx.seq;
    }
    train_sends_.push_back(clock_);
    train_ring_[train_ring_next_ % kTrainRing] = frame;
    ++train_ring_next_;
  }

  void GroundCycle() {
    const auto index = static_cast<std::uint32_t>(genuine_.size());
    const auto payload = GroundPayload(index);
    rr::EncodedFrame frame{};
    const auto out = ground_.Cycle(Now(), payload, frame);
    if (out.status != rr::SendStatus::kSent) {
      rf::OracleViolation("ground cycle did not send");
    }
    genuine_.push_back(GenuineTelegram{out.tx, payload});
    genuine_ring_[genuine_ring_next_ % kGenuineRing] = frame;
    ++genuine_ring_next_;
  }

  void DeliverToGround(unsigned arg) {
    if (train_ring_next_ == 0) {
      return;
    }
    const std::size_t back = std::min<std::size_t>(arg % kTrainRing, train_ring_next_ - 1);
    const rr::EncodedFrame& frame = train_ring_[(train_ring_next_ - 1 - back) % kTrainRing];
    std::array<std::uint8_t, rr::kPayloadMax> payload{};
    const auto r = ground_.Receive(Now(), frame.View(), payload);
    const bool down = r.link != rr::LinkState::kUp;
    if (r.emergency_brake != down || r.tracking_abnormal != down) {
      rf::OracleViolation("ground outputs differ from link != UP");
    }
  }

  void DeliverGenuine(unsigned arg, bool mutate) {
    if (genuine_ring_next_ == 0) {
      return;
    }
    const std::size_t back = std::min<std::size_t>(arg % kGenuineRing, genuine_ring_next_ - 1);
    rr::EncodedFrame frame = genuine_ring_[(genuine_ring_next_ - 1 - back) % kGenuineRing];
    if (mutate) {
      if (!in_.Has(2)) {
        return;
      }
      const std::uint8_t mode = in_.U8();
      rf::SplitMix64 rng{in_.U8()};
      Mutate(frame, mode, rng);
    }
    DeliverToTrain(frame.View());
  }

  void Mutate(rr::EncodedFrame& frame, std::uint8_t mode, rf::SplitMix64& rng) {
    const std::size_t blocks = frame.size / rr::kBlockBytes;
    switch (mode & 3U) {
      case 0:
        for (std::size_t b = 0; b < blocks; ++b) {
          rf::InjectSymbolErrors(frame, b, (mode >> 2U) % (rf::kRsRadius + 1), rng);
        }
        return;
      case 1:
        rf::InjectSymbolErrors(frame, rng.Below(blocks), rf::kRsRadius + 1 + (mode >> 2U) % 4U, rng);
        return;
      default: break;
    }
    rr::InnerFrame inner{};
    if (rr::CheckBlockDecoding(frame.View(), inner) != rr::RejectReason::kNone) {
      rf::OracleViolation("genuine frame does not decode");
    }
    const std::size_t len = rf::PayloadLenField(inner);
    if ((mode & 3U) == 2U) {
      const std::size_t bit = rng.Below(rr::FrameBytes(len) * 8);
      inner.bytes[bit / 8] ^= static_cast<std::uint8_t>(1U << (bit % 8));
    } else {
      static constexpr std::array<std::size_t, 9> kAt = {rr::layout::kSeq,      rr::layout::kSeq + 3,
                                                         rr::layout::kEcho,     rr::layout::kEcho + 3,
                                                         rr::layout::kFlags,    rr::layout::kSrc + 1,
                                                         rr::layout::kDst + 1,  rr::layout::kType,
                                                         rr::layout::kTimestamp + 3};
      inner.bytes[kAt[rng.Below(kAt.size())]] = static_cast<std::uint8_t>(rng.Next());
    }
    (void)rf::FixCrc(inner, len);
    (void)rr::EncodeBlocks(std::span<const std::uint8_t>(inner.bytes).first(inner.blocks * rr::kBlockData), frame);
  }

  void DeliverRaw() {
    if (!in_.Has(2)) {
      return;
    }
    std::size_t n = std::min<std::size_t>(in_.U16(), rr::kRxMax);
    n = std::min(n, in_.data.size() - in_.at);
    const auto bytes = in_.data.subspan(in_.at, n);
    in_.at += n;
    DeliverToTrain(bytes);
  }

  void DeliverForged() {
    if (!in_.Has(9)) {
      return;
    }
    rr::TelegramHeader h{};
    h.version = rr::kVersion;
    h.type = rr::TelegramType::kControl;
    h.src = rf::kGroundId;
    h.dst = rf::kTrainId;
    h.seq = in_.U32();
    h.echo = in_.U32();
    const std::uint8_t flags = in_.U8();
    h.echo_valid = (flags & 1U) != 0;
    if ((flags & 2U) != 0) {
      h.src = kOtherTrainId;
    }
    if ((flags & 4U) != 0 && !genuine_.empty()) {
      h.seq = genuine_.back().header.seq;
      h.echo = genuine_.back().header.echo;
      h.echo_valid = genuine_.back().header.echo_valid;
      h.timestamp_ms = genuine_.back().header.timestamp_ms;
    }
    static const rr::LinkKey attacker(rf::kAttackerKeyBytes);
    const auto payload = GroundPayload(static_cast<std::uint32_t>(genuine_.size()));
    rr::EncodedFrame frame{};
    if (rr::EncodeFrame(h, payload, attacker, frame) != rr::EncodeStatus::kOk) {
      rf::OracleViolation("forged frame could not be encoded");
    }
    DeliverToTrain(frame.View());
  }

  void DeliverToTrain(std::span<const std::uint8_t> bytes) {
    // The harness's own view: is this an authentic telegram (sealed with the link key)?
    rr::DecodedFrame decoded{};
    std::array<std::uint8_t, rr::kPayloadMax> plain{};
    const bool authentic = rr::DecodeFrame(bytes, decoded) == rr::RejectReason::kNone &&
                           rr::OpenPayload(decoded, rf::FuzzKey(), plain) == rr::RejectReason::kNone;
    std::array<std::uint8_t, rr::kPayloadMax> payload{};
    payload.fill(0x5A);
    const auto r = train_.Receive(Now(), bytes, payload);
    const bool in_sequence = r.reason == rr::RejectReason::kNone || r.reason == rr::RejectReason::kNoEcho ||
                             r.reason == rr::RejectReason::kUnknownEcho || r.reason == rr::RejectReason::kStale;
    if (in_sequence) {
      if (!authentic) {
        rf::OracleViolation("a telegram without the link key passed checks 1-6");
      }
      in_sequence_any_ = true;
      in_sequence_seq_ = decoded.header.seq;
      in_sequence_clock_ = clock_;
    }
    if (r.reason != rr::RejectReason::kNone) {
      if (r.header != rr::TelegramHeader{} ||
          !std::all_of(payload.begin(), payload.end(), [](std::uint8_t b) { return b == 0; })) {
        rf::OracleViolation("rejected telegram exposed content");
      }
      if (!in_sequence && r.gap != 0) {
        rf::OracleViolation("gap reported with a telegram that is not in sequence");
      }
      CheckOutputs(r.link, r.emergency_brake, r.tracking_abnormal);
      return;
    }
    // Accepted: must be exactly a genuine telegram, newer than the last accepted one.
    const std::uint32_t index = (static_cast<std::uint32_t>(payload[0]) << 24U) |
                                (static_cast<std::uint32_t>(payload[1]) << 16U) |
                                (static_cast<std::uint32_t>(payload[2]) << 8U) | payload[3];
    if (index >= genuine_.size() || !(genuine_[index].header == r.header) ||
        !std::equal(genuine_[index].payload.begin(), genuine_[index].payload.end(), payload.begin()) ||
        !std::all_of(payload.begin() + kGroundPayload, payload.end(), [](std::uint8_t b) { return b == 0; })) {
      rf::OracleViolation("accepted telegram not sent by the genuine peer");
    }
    if (accepted_any_ && index <= last_accepted_index_) {
      rf::OracleViolation("accepted telegram repeated or out of sending order");
    }
    if (!r.header.echo_valid) {
      rf::OracleViolation("accepted telegram without echo");
    }
    const std::uint32_t sends_back = static_cast<std::uint32_t>(train_sends_.size()) - 1U -
                                     static_cast<std::uint32_t>(r.header.echo - first_train_seq_);
    const std::uint32_t send_index = r.header.echo - first_train_seq_;
    if (train_sends_.empty() || send_index >= train_sends_.size() || sends_back >= kHistory) {
      rf::OracleViolation("accepted echo is not one of the last history_depth own sends");
    }
    if (clock_ - train_sends_[send_index] > config_.turnaround_ms) {
      rf::OracleViolation("accepted telegram's echo is older than turnaround_ms");
    }
    accepted_any_ = true;
    last_accepted_index_ = index;
    last_accept_clock_ = clock_;
    CheckOutputs(r.link, r.emergency_brake, r.tracking_abnormal);
    if (r.link != rr::LinkState::kUp) {
      rf::OracleViolation("link not UP after an acceptance");
    }
  }

  Reader& in_;
  rr::Endpoint train_;
  rr::Endpoint ground_;
  rr::EndpointConfig config_{};
  std::uint32_t t0_ = 0;
  std::uint64_t clock_ = 0;  // ms since the start of the input (never wraps)

  std::vector<GenuineTelegram> genuine_;
  std::array<rr::EncodedFrame, kGenuineRing> genuine_ring_{};
  std::size_t genuine_ring_next_ = 0;

  std::vector<std::uint64_t> train_sends_;  // send clock of the n-th train telegram
  std::uint32_t first_train_seq_ = 0;
  std::array<rr::EncodedFrame, kTrainRing> train_ring_{};
  std::size_t train_ring_next_ = 0;

  bool in_sequence_any_ = false;  // a telegram passed checks 1-6 (REQ-TG-012)
  std::uint32_t in_sequence_seq_ = 0;
  std::uint64_t in_sequence_clock_ = 0;

  bool accepted_any_ = false;
  std::uint32_t last_accepted_index_ = 0;
  std::uint64_t last_accept_clock_ = 0;
};

}  // namespace

// @verifies REQ-TG-001
// @verifies REQ-TG-003
// @verifies REQ-TG-004
// @verifies REQ-TG-005
// @verifies REQ-TG-006
// @verifies REQ-TG-007
// @verifies REQ-TG-009
// @verifies REQ-TG-012
// @verifies REQ-TG-013
// @verifies REQ-TG-014
// @verifies REQ-TG-015
// @verifies REQ-TG-018
extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Reader in{std::span<const std::uint8_t>(data, size)};
  Run run(in);
  run.Execute();
  return 0;
}
