// Unit tests of the receiver / link-supervision state machine (spec/design/tg.md
// §4, §5) at millisecond resolution and with the deployment configuration (sequence
// modulus 2^32). The model's boundaries at tick resolution are covered by the conformance
// vectors; these tests cover what the model abstracts away (bytes, ms, 32-bit wrap).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <optional>
#include <span>

#include "railproof/generated/tg_params.hpp"
#include "railproof/tg/aead.hpp"
#include "railproof/tg/endpoint.hpp"
#include "railproof/tg/frame.hpp"
#include "railproof/tg/telegram.hpp"
#include "railproof/testing/alloc_counter.hpp"
#include "test_keys.hpp"

// Allocation counter (REQ-TG-018: no heap per telegram): cpp/testing/src/alloc_counter.cpp.

namespace railproof::tg {
namespace {

namespace p = params::tg;

constexpr std::array<std::uint8_t, kKeyBytes> kLinkKeyBytes = {
    0x4c, 0x69, 0x6e, 0x6b, 0x2d, 0x6b, 0x65, 0x79, 0x2d, 0x75, 0x6e, 0x69, 0x74, 0x2d, 0x74, 0x65,
    0x73, 0x74, 0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0x99, 0xaa, 0xbb, 0xcc, 0xdd, 0xee};
constexpr std::array<std::uint8_t, kKeyBytes> kAttackerKeyBytes = test::OneBitApart(kLinkKeyBytes);

constexpr auto kGroundId = static_cast<std::uint16_t>(p::ground_id);
constexpr auto kTrainId = static_cast<std::uint16_t>(p::model::model_train_id);
constexpr auto kOtherTrainId = static_cast<std::uint16_t>(p::model::model_other_train_id);
constexpr auto kTurnaround = static_cast<std::uint32_t>(p::turnaround_max_ms);
constexpr auto kLinkTimeout = static_cast<std::uint32_t>(p::link_timeout_ms);
constexpr auto kEchoValidity = static_cast<std::uint32_t>(p::echo_validity_ms);
constexpr auto kWindow = static_cast<std::uint32_t>(p::seq_window);
constexpr auto kHistory = static_cast<std::uint32_t>(p::history_depth);
constexpr std::array<std::uint8_t, 5> kPayload = {0x10, 0x20, 0x30, 0x40, 0x50};

const LinkKey& Key() {
  static const LinkKey key(kLinkKeyBytes);
  return key;
}
const LinkKey& AttackerKey() {
  static const LinkKey key(kAttackerKeyBytes);
  return key;
}

EndpointConfig TrainConfig(std::uint32_t initial_seq = 0) {
  EndpointConfig c = DeploymentConfig(Role::kTrain, kTrainId, kGroundId);
  c.initial_seq = initial_seq;
  return c;
}
EndpointConfig GroundConfig(std::uint32_t initial_seq = 0) {
  EndpointConfig c = DeploymentConfig(Role::kGround, kGroundId, kTrainId);
  c.initial_seq = initial_seq;
  return c;
}

// A telegram as the ground (the train's peer) would send it, sealed with `key`.
struct PeerTelegram {
  std::uint32_t seq = 0;
  std::optional<std::uint32_t> echo;
  TelegramType type = TelegramType::kControl;
  std::uint16_t src = kGroundId;
  std::uint16_t dst = kTrainId;
  std::uint32_t timestamp_ms = 0;
};

EncodedFrame Seal(const PeerTelegram& t, const LinkKey& key = Key(),
                  std::span<const std::uint8_t> payload = kPayload) {
  TelegramHeader h{};
  h.version = kVersion;
  h.type = t.type;
  h.src = t.src;
  h.dst = t.dst;
  h.seq = t.seq;
  h.echo = t.echo.value_or(0);
  h.echo_valid = t.echo.has_value();
  h.timestamp_ms = t.timestamp_ms;
  EncodedFrame frame{};
  EXPECT_EQ(EncodeFrame(h, payload, key, frame), EncodeStatus::kOk);
  return frame;
}

class Harness {
 public:
  explicit Harness(const EndpointConfig& config) { EXPECT_EQ(ep.Init(config, Key()), ConfigError::kNone); }

  Endpoint::CycleOutput Cycle(std::uint32_t now) {
    last_tx = ep.Cycle(now, kPayload, frame);
    return last_tx;
  }
  Endpoint::RxResult Rx(std::uint32_t now, const EncodedFrame& f) {
    payload.fill(0xEE);
    return ep.Receive(now, f.View(), payload);
  }
  Endpoint::RxResult Rx(std::uint32_t now, const PeerTelegram& t) { return Rx(now, Seal(t)); }
  // The cycles exactly at the link timeout after a receipt at `ta` (the link still up) and
  // 1 ms later (lost).
  std::array<Endpoint::CycleOutput, 2> CyclesAtTimeout(std::uint32_t ta) {
    const Endpoint::CycleOutput at = Cycle(ta + kLinkTimeout);
    return {at, Cycle(ta + kLinkTimeout + 1U)};
  }

  [[nodiscard]] bool PayloadIs(std::span<const std::uint8_t> want) const {
    return std::equal(want.begin(), want.end(), payload.begin()) &&
           std::all_of(payload.begin() + static_cast<std::ptrdiff_t>(want.size()), payload.end(),
                       [](std::uint8_t b) { return b == 0; });
  }
  [[nodiscard]] bool PayloadZero() const {
    return std::all_of(payload.begin(), payload.end(), [](std::uint8_t b) { return b == 0; });
  }

  Endpoint ep;
  EncodedFrame frame{};
  Endpoint::CycleOutput last_tx{};
  std::array<std::uint8_t, kPayloadMax> payload{};
};

// A train endpoint that has sent one telegram (seq `own`) at t0 and has its link UP with
// peer number `peer` accepted at t0 (the telegram echoes `own`, age 0).
Harness TrainUp(std::uint32_t t0, std::uint32_t own, std::uint32_t peer) {
  Harness h(TrainConfig(own));
  EXPECT_EQ(h.Cycle(t0).tx.seq, own);
  const auto r = h.Rx(t0, PeerTelegram{.seq = peer, .echo = own});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.link, LinkState::kUp);
  return h;
}

// ---- configuration ---------------------------------------------------------------------

// @verifies REQ-TG-004
// @verifies REQ-TG-008
// @verifies REQ-TG-017
TEST(EndpointConfigTest, DeploymentConfigComesFromTheParameters) {
  const EndpointConfig c = DeploymentConfig(Role::kTrain, kTrainId, kGroundId);
  EXPECT_EQ(c.seq_modulus, std::uint64_t{1} << static_cast<unsigned>(p::seq_bits));
  EXPECT_EQ(c.seq_modulus, std::uint64_t{1} << 32U);  // REQ-TG-017: 32-bit sequence numbers
  EXPECT_EQ(c.seq_window, kWindow);
  EXPECT_EQ(c.history_depth, kHistory);
  EXPECT_EQ(c.turnaround_ms, kTurnaround);
  EXPECT_EQ(c.link_timeout_ms, kLinkTimeout);
  EXPECT_EQ(c.echo_validity_ms, kEchoValidity);
  EXPECT_EQ(c.role, Role::kTrain);
  EXPECT_EQ(c.own_id, kTrainId);
  EXPECT_EQ(c.peer_id, kGroundId);
  EXPECT_EQ(Validate(c), ConfigError::kNone);
}

// @verifies REQ-TG-018
TEST(EndpointConfigTest, ValidateReportsEachErrorTyped) {
  const EndpointConfig ok = TrainConfig();
  struct Case {
    EndpointConfig config;
    ConfigError want;
  };
  auto with = [&](auto mutate) {
    EndpointConfig c = ok;
    mutate(c);
    return c;
  };
  const Case cases[] = {
      {with([](EndpointConfig& c) { c.role = static_cast<Role>(7); }), ConfigError::kInvalidRole},
      {with([](EndpointConfig& c) { c.peer_id = c.own_id; }), ConfigError::kSameIds},
      {with([](EndpointConfig& c) { c.seq_modulus = 1; }), ConfigError::kSeqModulusOutOfRange},
      {with([](EndpointConfig& c) { c.seq_modulus = (std::uint64_t{1} << 32U) + 1U; }),
       ConfigError::kSeqModulusOutOfRange},
      {with([](EndpointConfig& c) { c.seq_window = 0; }), ConfigError::kSeqWindowOutOfRange},
      {with([](EndpointConfig& c) { c.seq_modulus = 9; c.seq_window = 9; c.history_depth = 4; }),
       ConfigError::kSeqWindowOutOfRange},
      {with([](EndpointConfig& c) { c.history_depth = 0; }), ConfigError::kHistoryDepthOutOfRange},
      {with([](EndpointConfig& c) { c.history_depth = kHistoryMax + 1U; }), ConfigError::kHistoryDepthOutOfRange},
      {with([](EndpointConfig& c) { c.seq_modulus = 4; c.seq_window = 2; c.history_depth = 5; }),
       ConfigError::kHistoryDepthOutOfRange},
      {with([](EndpointConfig& c) { c.seq_modulus = 9; c.seq_window = 4; c.history_depth = 4; c.initial_seq = 9; }),
       ConfigError::kInitialSeqOutOfRange},
      {with([](EndpointConfig& c) { c.turnaround_ms = 0; }), ConfigError::kTurnaroundOutOfRange},
      {with([](EndpointConfig& c) { c.turnaround_ms = kMaxIntervalMs + 1U; }), ConfigError::kTurnaroundOutOfRange},
      {with([](EndpointConfig& c) { c.link_timeout_ms = 0; }), ConfigError::kLinkTimeoutOutOfRange},
      {with([](EndpointConfig& c) { c.link_timeout_ms = 0xFFFFFFFFU; }), ConfigError::kLinkTimeoutOutOfRange},
      {with([](EndpointConfig& c) { c.echo_validity_ms = 0; }), ConfigError::kEchoValidityOutOfRange},
      {with([](EndpointConfig& c) { c.echo_validity_ms = kMaxIntervalMs + 1U; }),
       ConfigError::kEchoValidityOutOfRange},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(Validate(c.config), c.want) << ToString(c.want);
    Endpoint ep;
    EXPECT_EQ(ep.Init(c.config, Key()), c.want) << ToString(c.want);
    EXPECT_FALSE(ep.Initialised());
  }
  // Edges that are valid: W = M - 1, H = M, H = kHistoryMax, initial_seq = M - 1, 2^31 - 1 ms.
  EXPECT_EQ(Validate(with([](EndpointConfig& c) { c.seq_modulus = 9; c.seq_window = 8; c.history_depth = 9;
                                                   c.initial_seq = 8; })),
            ConfigError::kNone);
  EXPECT_EQ(Validate(with([](EndpointConfig& c) { c.history_depth = kHistoryMax; c.turnaround_ms = kMaxIntervalMs; })),
            ConfigError::kNone);
  EXPECT_EQ(Validate(with([](EndpointConfig& c) { c.seq_modulus = 2; c.seq_window = 1; c.history_depth = 2; })),
            ConfigError::kNone);
}

// @verifies REQ-TG-014
// @verifies REQ-TG-015
// @verifies REQ-TG-018
TEST(EndpointConfigTest, UninitialisedEndpointIsSafe) {
  Endpoint ep;
  EncodedFrame frame{};
  frame.size = 17;
  const auto out = ep.Cycle(1000, kPayload, frame);
  EXPECT_EQ(out.status, SendStatus::kNotInitialised);
  EXPECT_EQ(frame.size, 0U);
  EXPECT_EQ(out.link, LinkState::kNone);
  EXPECT_TRUE(out.emergency_brake);
  EXPECT_TRUE(out.tracking_abnormal);

  std::array<std::uint8_t, kPayloadMax> payload{};
  payload.fill(0xEE);
  const auto r = ep.Receive(1000, Seal(PeerTelegram{.seq = 1, .echo = 0}).View(), payload);
  EXPECT_EQ(r.reason, RejectReason::kAuthFailed);
  EXPECT_EQ(r.link, LinkState::kNone);
  EXPECT_TRUE(r.emergency_brake);
  EXPECT_TRUE(std::all_of(payload.begin(), payload.end(), [](std::uint8_t b) { return b == 0; }));

  // A failed re-initialisation leaves a working endpoint not initialised.
  Harness h(TrainConfig());
  EndpointConfig bad = TrainConfig();
  bad.seq_window = 0;
  EXPECT_EQ(h.ep.Init(bad, Key()), ConfigError::kSeqWindowOutOfRange);
  EXPECT_EQ(h.Cycle(0).status, SendStatus::kNotInitialised);
}

// ---- sending ---------------------------------------------------------------------------

// @verifies REQ-TG-008
// @verifies REQ-TG-011
TEST(EndpointSend, CycleSendsNumberedTelegramsOfItsRole) {
  Harness train(TrainConfig(100));
  Harness ground(GroundConfig(7));
  for (std::uint32_t i = 0; i < 3; ++i) {
    const auto t = train.Cycle(1000U * i);
    EXPECT_EQ(t.status, SendStatus::kSent);
    EXPECT_EQ(t.tx.seq, 100U + i);
    EXPECT_EQ(t.tx.type, TelegramType::kPosition);
    EXPECT_EQ(t.tx.src, kTrainId);
    EXPECT_EQ(t.tx.dst, kGroundId);
    EXPECT_EQ(t.tx.timestamp_ms, 1000U * i);
    EXPECT_FALSE(t.tx.echo_valid);  // nothing received yet
    EXPECT_EQ(t.tx.payload_len, kPayload.size());
    // The frame on the air is exactly that telegram, sealed with the link key.
    DecodedFrame decoded{};
    ASSERT_EQ(DecodeFrame(train.frame.View(), decoded), RejectReason::kNone);
    EXPECT_EQ(decoded.header, t.tx);
    std::array<std::uint8_t, kPayloadMax> plain{};
    ASSERT_EQ(OpenPayload(decoded, Key(), plain), RejectReason::kNone);
    EXPECT_TRUE(std::equal(kPayload.begin(), kPayload.end(), plain.begin()));

    const auto g = ground.Cycle(500U * i);
    EXPECT_EQ(g.tx.seq, 7U + i);
    EXPECT_EQ(g.tx.type, TelegramType::kControl);
    EXPECT_EQ(g.tx.src, kGroundId);
    EXPECT_EQ(g.tx.dst, kTrainId);
  }
}

// @verifies REQ-TG-018
TEST(EndpointSend, OverlongPayloadSendsNothingAndConsumesNoNumber) {
  Harness h(TrainConfig(5));
  std::array<std::uint8_t, kPayloadMax + 1> big{};
  const auto out = h.ep.Cycle(0, big, h.frame);
  EXPECT_EQ(out.status, SendStatus::kPayloadTooLong);
  EXPECT_EQ(h.frame.size, 0U);
  EXPECT_EQ(out.tx, TelegramHeader{});
  EXPECT_EQ(h.Cycle(10).tx.seq, 5U);
  // The full payload is fine.
  const auto full = h.ep.Cycle(20, std::span<const std::uint8_t>(big).first(kPayloadMax), h.frame);
  EXPECT_EQ(full.status, SendStatus::kSent);
  EXPECT_EQ(full.tx.seq, 6U);
  EXPECT_EQ(full.tx.payload_len, kPayloadMax);
}

// ---- bootstrap between two real endpoints ----------------------------------------------

// @verifies REQ-TG-008
// @verifies REQ-TG-012
// @verifies REQ-TG-014
// @verifies REQ-TG-015
// @verifies REQ-TG-016
TEST(EndpointHandshake, GroundAndTrainBootstrapOverRealFrames) {
  Harness ground(GroundConfig(1000));
  Harness train(TrainConfig(0xFFFFFFFFU));

  // t = 0: the ground sends first, without echo. The train cannot accept it (no echo),
  // but the telegram is in sequence, so the train echoes it next (REQ-TG-012).
  auto g0 = ground.Cycle(0);
  EXPECT_TRUE(g0.tracking_abnormal);
  EXPECT_FALSE(g0.tx.echo_valid);
  auto r = train.Rx(40, ground.frame);
  EXPECT_EQ(r.reason, RejectReason::kNoEcho);
  EXPECT_EQ(r.link, LinkState::kNone);
  EXPECT_TRUE(r.emergency_brake);
  EXPECT_TRUE(train.PayloadZero());

  // t = 500: the train sends, echoing the ground's number; the ground accepts it.
  auto t0 = train.Cycle(500);
  EXPECT_TRUE(t0.emergency_brake);
  ASSERT_TRUE(t0.tx.echo_valid);
  EXPECT_EQ(t0.tx.echo, g0.tx.seq);
  r = ground.Rx(560, train.frame);
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.link, LinkState::kUp);
  EXPECT_FALSE(r.tracking_abnormal);
  EXPECT_EQ(r.header, t0.tx);
  EXPECT_TRUE(ground.PayloadIs(kPayload));

  // t = 1000: the ground echoes the train; the train accepts: both links up.
  auto g1 = ground.Cycle(1000);
  EXPECT_EQ(g1.link, LinkState::kUp);
  ASSERT_TRUE(g1.tx.echo_valid);
  EXPECT_EQ(g1.tx.echo, t0.tx.seq);
  r = train.Rx(1050, ground.frame);
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
  EXPECT_EQ(r.link, LinkState::kUp);
  EXPECT_FALSE(r.emergency_brake);
  EXPECT_TRUE(train.PayloadIs(kPayload));

  // Steady state over the train's own wrap-around (initial 0xFFFFFFFF): 20 more cycles,
  // ground every 500 ms and train every 1000 ms, no rejection, links stay up.
  for (std::uint32_t i = 3; i < 23; ++i) {
    const std::uint32_t now = 500U * i;
    const auto g = ground.Cycle(now);
    EXPECT_EQ(g.link, LinkState::kUp);
    EXPECT_EQ(train.Rx(now + 50, ground.frame).reason, RejectReason::kNone);
    if (i % 2 == 0) {
      const auto t = train.Cycle(now + 100);
      EXPECT_EQ(t.link, LinkState::kUp);
      EXPECT_FALSE(t.emergency_brake);
      EXPECT_EQ(ground.Rx(now + 150, train.frame).reason, RejectReason::kNone);
    }
  }
  EXPECT_EQ(train.Cycle(11600).tx.seq, 10U);  // 0xFFFFFFFF, 0, 1, ... : wrapped
  EXPECT_EQ(ground.ep.Link(), LinkState::kUp);
  EXPECT_EQ(train.ep.Link(), LinkState::kUp);
}

// ---- turnaround (check 8) at ms resolution ---------------------------------------------

// @verifies REQ-TG-006
// @verifies REQ-TG-009
TEST(EndpointTurnaround, BoundaryAtMillisecondResolution) {
  const std::uint32_t t0 = 10000;
  struct Case {
    std::uint32_t age;
    RejectReason want;
  };
  for (const Case c : {Case{kTurnaround - 1U, RejectReason::kNone}, Case{kTurnaround, RejectReason::kNone},
                       Case{kTurnaround + 1U, RejectReason::kStale}}) {
    Harness h(TrainConfig(50));
    ASSERT_EQ(h.Cycle(t0).tx.seq, 50U);
    const auto r = h.Rx(t0 + c.age, PeerTelegram{.seq = 9, .echo = 50});
    EXPECT_EQ(r.reason, c.want) << "echo age " << c.age;
    if (c.want == RejectReason::kNone) {
      EXPECT_TRUE(h.PayloadIs(kPayload));
      EXPECT_EQ(r.link, LinkState::kUp);
    } else {
      EXPECT_TRUE(h.PayloadZero());
      EXPECT_EQ(r.header, TelegramHeader{});
      EXPECT_EQ(r.link, LinkState::kNone);
    }
  }
}

// The age counts from the sending of the echoed number, not from the newest send.
// @verifies REQ-TG-006
// @verifies REQ-TG-009
TEST(EndpointTurnaround, AgeOfAnOlderEchoedNumber) {
  Harness h(TrainConfig(0));
  h.Cycle(0);     // seq 0
  h.Cycle(1000);  // seq 1
  h.Cycle(2000);  // seq 2
  EXPECT_EQ(h.Rx(3001, PeerTelegram{.seq = 1, .echo = 0}).reason, RejectReason::kStale);
  EXPECT_EQ(h.Rx(3001, PeerTelegram{.seq = 2, .echo = 1}).reason, RejectReason::kNone);
}

// ---- link supervision at ms resolution -------------------------------------------------

// @verifies REQ-TG-013
// @verifies REQ-TG-014
// @verifies REQ-TG-015
TEST(EndpointLink, TimeoutExactlyAtLimitStaysUpOneMsLaterIsLost) {
  const std::uint32_t ta = 20000;
  Harness train = TrainUp(ta, 3, 77);
  const auto [c, c1] = train.CyclesAtTimeout(ta);
  EXPECT_EQ(c.link, LinkState::kUp);
  EXPECT_FALSE(c.emergency_brake);
  EXPECT_EQ(c1.link, LinkState::kLost);
  EXPECT_TRUE(c1.emergency_brake);
  EXPECT_TRUE(c1.tracking_abnormal);

  // Ground role: tracking abnormal at the same boundary.
  Harness ground(GroundConfig(3));
  ground.Cycle(ta);
  ASSERT_EQ(ground.Rx(ta, PeerTelegram{.seq = 5, .echo = 3, .type = TelegramType::kPosition, .src = kTrainId,
                                       .dst = kGroundId})
                .reason,
            RejectReason::kNone);
  const auto [g, g1] = ground.CyclesAtTimeout(ta);
  EXPECT_EQ(g.link, LinkState::kUp);
  EXPECT_FALSE(g.tracking_abnormal);
  EXPECT_EQ(g1.link, LinkState::kLost);
  EXPECT_TRUE(g1.tracking_abnormal);
}

// @verifies REQ-TG-013
// @verifies REQ-TG-014
TEST(EndpointLink, ReceiveAfterTheTimeoutReportsLostAndRecoveryNeedsAFreshTelegram) {
  const std::uint32_t ta = 5000;
  Harness h = TrainUp(ta, 3, 77);
  // A rejected telegram after the timeout: the receive-time supervision reports LOST.
  auto r = h.Rx(ta + kLinkTimeout + 1U, Seal(PeerTelegram{.seq = 78, .echo = 3}, AttackerKey()));
  EXPECT_EQ(r.reason, RejectReason::kAuthFailed);
  EXPECT_EQ(r.link, LinkState::kLost);
  EXPECT_TRUE(r.emergency_brake);
  // Link LOST: the sequence check is not applied, but a stale echo is still rejected.
  r = h.Rx(ta + kLinkTimeout + 2U, PeerTelegram{.seq = 78, .echo = 3});
  EXPECT_EQ(r.reason, RejectReason::kStale);
  EXPECT_EQ(r.link, LinkState::kLost);
  // A fresh exchange restores the link; an acceptance while LOST reports no gap.
  const std::uint32_t t1 = ta + 4000;
  ASSERT_EQ(h.Cycle(t1).tx.seq, 4U);
  r = h.Rx(t1 + 10U, PeerTelegram{.seq = 90, .echo = 4});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
  EXPECT_EQ(r.link, LinkState::kUp);
  EXPECT_FALSE(r.emergency_brake);
}

// ---- echo validity (sending rule) at ms resolution -------------------------------------

// @verifies REQ-TG-012
TEST(EndpointEcho, EchoValidityBoundaryAtMillisecondResolution) {
  Harness h(TrainConfig(0));
  const std::uint32_t tu = 7000;
  // In sequence but rejected (no echo): the peer number is still taken for the echo.
  EXPECT_EQ(h.Rx(tu, PeerTelegram{.seq = 300, .echo = std::nullopt}).reason, RejectReason::kNoEcho);
  auto c = h.Cycle(tu + kEchoValidity - 1U);
  EXPECT_TRUE(c.tx.echo_valid);
  EXPECT_EQ(c.tx.echo, 300U);
  c = h.Cycle(tu + kEchoValidity);
  EXPECT_TRUE(c.tx.echo_valid);
  EXPECT_EQ(c.tx.echo, 300U);
  c = h.Cycle(tu + kEchoValidity + 1U);
  EXPECT_FALSE(c.tx.echo_valid);
  EXPECT_EQ(c.tx.echo, 0U);
  // Expiry is latched: even 2^32 ms later (the age wraps to a small value) no echo.
  c = h.Cycle(tu + 5U);
  EXPECT_FALSE(c.tx.echo_valid);
}

// @verifies REQ-TG-012
TEST(EndpointEcho, OnlyTelegramsPassingChecksOneToSixUpdateTheEchoedNumber) {
  Harness h = TrainUp(0, 10, 500);
  // Unknown echo: in sequence, so the number advances (REQ-TG-012).
  EXPECT_EQ(h.Rx(100, PeerTelegram{.seq = 501, .echo = 9999}).reason, RejectReason::kUnknownEcho);
  EXPECT_EQ(h.Cycle(200).tx.echo, 501U);
  // Forged, misaddressed or out-of-window telegrams do not touch it.
  EXPECT_EQ(h.Rx(300, Seal(PeerTelegram{.seq = 502, .echo = 11}, AttackerKey())).reason, RejectReason::kAuthFailed);
  EXPECT_EQ(h.Rx(300, PeerTelegram{.seq = 502, .echo = 11, .dst = kOtherTrainId}).reason,
            RejectReason::kWrongAddress);
  EXPECT_EQ(h.Rx(300, PeerTelegram{.seq = 501 + kWindow + 1U, .echo = 11}).reason, RejectReason::kOutOfSequence);
  EXPECT_EQ(h.Rx(300, PeerTelegram{.seq = 501, .echo = 11}).reason, RejectReason::kRepeated);
  const auto c = h.Cycle(400);
  EXPECT_TRUE(c.tx.echo_valid);
  EXPECT_EQ(c.tx.echo, 501U);
}

// @verifies REQ-TG-008
TEST(EndpointEcho, NoEchoAndUnknownEchoAreRejected) {
  Harness h(TrainConfig(20));
  h.Cycle(0);
  EXPECT_EQ(h.Rx(10, PeerTelegram{.seq = 1, .echo = std::nullopt}).reason, RejectReason::kNoEcho);
  EXPECT_EQ(h.Rx(10, PeerTelegram{.seq = 2, .echo = 21}).reason, RejectReason::kUnknownEcho);  // not sent yet
  EXPECT_EQ(h.Rx(10, PeerTelegram{.seq = 3, .echo = 19}).reason, RejectReason::kUnknownEcho);  // never sent
  EXPECT_EQ(h.Rx(10, PeerTelegram{.seq = 4, .echo = 20}).reason, RejectReason::kNone);
}

// @verifies REQ-TG-008
// @verifies REQ-TG-009
TEST(EndpointEcho, OnlyTheLastHistoryDepthNumbersAreKnown) {
  const std::uint32_t period = kTurnaround / (kHistory + 1U);  // all H + 1 sends within T_ta
  Harness h(TrainConfig(0));
  for (std::uint32_t i = 0; i <= kHistory; ++i) {  // sends 0 .. H
    h.Cycle(period * i);
  }
  const std::uint32_t now = period * kHistory;
  // seq 0 is the (H+1)-th most recent: forgotten; seq 1 is the H-th: known and fresh.
  EXPECT_EQ(h.Rx(now, PeerTelegram{.seq = 1, .echo = 0}).reason, RejectReason::kUnknownEcho);
  EXPECT_EQ(h.Rx(now, PeerTelegram{.seq = 2, .echo = 1}).reason, RejectReason::kNone);
}

// ---- sequence numbers (check 6) --------------------------------------------------------

// @verifies REQ-TG-002
// @verifies REQ-TG-004
TEST(EndpointSequence, WindowEdgeAtDeploymentWindow) {
  const std::uint32_t peer = 1000;
  Harness h = TrainUp(0, 0, peer);
  // Rejections leave the state unchanged, so W + 1 first, then W.
  auto r = h.Rx(10, PeerTelegram{.seq = peer + kWindow + 1U, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kOutOfSequence);
  EXPECT_EQ(r.gap, 0U);
  EXPECT_TRUE(h.PayloadZero());
  r = h.Rx(10, PeerTelegram{.seq = peer + kWindow, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, kWindow - 1U);  // REQ-TG-002: deletions reported
  r = h.Rx(20, PeerTelegram{.seq = peer + kWindow + 1U, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
}

// Every deletion is reported exactly once: with the telegram that moves peer_seq past it,
// even if that telegram then fails the echo check (model: receive() prints the gap with
// every verdict after check 6).
// @verifies REQ-TG-002
// @verifies REQ-TG-012
TEST(EndpointSequence, GapIsReportedByTheInSequenceTelegramEvenIfItsEchoFails) {
  Harness h = TrainUp(0, 0, 100);
  auto r = h.Rx(10, PeerTelegram{.seq = 103, .echo = std::nullopt});  // 101, 102 deleted
  EXPECT_EQ(r.reason, RejectReason::kNoEcho);
  EXPECT_EQ(r.gap, 2U);
  r = h.Rx(20, PeerTelegram{.seq = 105, .echo = 77});  // 104 deleted
  EXPECT_EQ(r.reason, RejectReason::kUnknownEcho);
  EXPECT_EQ(r.gap, 1U);
  r = h.Rx(30, PeerTelegram{.seq = 106, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);  // relative to 105, the last in-sequence number
  // Rejections before check 6 and rejections by check 6 report no gap.
  EXPECT_EQ(h.Rx(40, PeerTelegram{.seq = 109, .echo = 0, .dst = kOtherTrainId}).gap, 0U);
  EXPECT_EQ(h.Rx(40, Seal(PeerTelegram{.seq = 109, .echo = 0}, AttackerKey())).gap, 0U);
  EXPECT_EQ(h.Rx(40, PeerTelegram{.seq = 106 + kWindow + 1U, .echo = 0}).gap, 0U);
  // While the link is not up no gap is reported (the sequence check is not applied).
  Harness fresh(TrainConfig(0));
  fresh.Cycle(0);
  r = fresh.Rx(10, PeerTelegram{.seq = 500, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
}

// @verifies REQ-TG-004
// @verifies REQ-TG-017
TEST(EndpointSequence, PeerNumbersWrapAtTwoToThe32) {
  Harness h = TrainUp(0, 0, 0xFFFFFFFEU);
  auto r = h.Rx(10, PeerTelegram{.seq = 0xFFFFFFFFU, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
  r = h.Rx(20, PeerTelegram{.seq = 0, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 0U);
  // Behind across the wrap: 0xFFFFFFFF is now 2^32 - 1 ahead, i.e. out of the window.
  EXPECT_EQ(h.Rx(30, PeerTelegram{.seq = 0xFFFFFFFFU, .echo = 0}).reason, RejectReason::kOutOfSequence);
  // Window edge across the wrap, from 0xFFFFFFFA.
  Harness w = TrainUp(0, 0, 0xFFFFFFFAU);
  const std::uint32_t edge = 0xFFFFFFFAU + kWindow;  // wraps
  EXPECT_EQ(w.Rx(10, PeerTelegram{.seq = edge + 1U, .echo = 0}).reason, RejectReason::kOutOfSequence);
  r = w.Rx(10, PeerTelegram{.seq = edge, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, kWindow - 1U);
}

// @verifies REQ-TG-008
// @verifies REQ-TG-017
TEST(EndpointSequence, OwnNumbersWrapAndEchoesAcrossTheWrapAreFound) {
  Harness h(TrainConfig(0xFFFFFFFEU));
  EXPECT_EQ(h.Cycle(0).tx.seq, 0xFFFFFFFEU);
  EXPECT_EQ(h.Cycle(500).tx.seq, 0xFFFFFFFFU);
  EXPECT_EQ(h.Cycle(1000).tx.seq, 0U);
  EXPECT_EQ(h.Cycle(1500).tx.seq, 1U);
  // An echo of a number sent before the wrap is found with its own send time.
  auto r = h.Rx(1500, PeerTelegram{.seq = 40, .echo = 0xFFFFFFFFU});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  r = h.Rx(3501, PeerTelegram{.seq = 41, .echo = 0xFFFFFFFFU});  // 3001 ms after its sending
  EXPECT_EQ(r.reason, RejectReason::kStale);
  r = h.Rx(3501, PeerTelegram{.seq = 42, .echo = 0U});  // 2501 ms
  EXPECT_EQ(r.reason, RejectReason::kNone);
}

// The conformance configuration reduces the modulus (design §3, §7): numbers wrap at M, and
// a number >= M, which no genuine peer sends, is out of sequence even before the link is up.
// @verifies REQ-TG-004
// @verifies REQ-TG-017
TEST(EndpointSequence, ReducedModulusOfTheModelConfiguration) {
  namespace m = p::model;
  EndpointConfig c = TrainConfig();
  c.seq_modulus = static_cast<std::uint64_t>(m::model_seq_modulus);
  c.seq_window = static_cast<std::uint32_t>(m::model_seq_window);
  c.history_depth = static_cast<std::uint32_t>(m::model_history_depth);
  c.initial_seq = static_cast<std::uint32_t>(m::model_seq_modulus - 1);
  ASSERT_EQ(Validate(c), ConfigError::kNone);
  Harness h(c);
  const auto top = static_cast<std::uint32_t>(m::model_seq_modulus - 1);
  EXPECT_EQ(h.Cycle(0).tx.seq, top);
  EXPECT_EQ(h.Cycle(100).tx.seq, 0U);  // wrapped at M
  EXPECT_EQ(h.Rx(100, PeerTelegram{.seq = top + 1U, .echo = 0}).reason, RejectReason::kOutOfSequence);
  EXPECT_EQ(h.Cycle(200).tx.echo_valid, false);  // nothing taken from it
  auto r = h.Rx(200, PeerTelegram{.seq = top, .echo = 0});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  r = h.Rx(200, PeerTelegram{.seq = c.seq_window - 1U, .echo = 1});  // top + W mod M
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, c.seq_window - 1U);
}

// @verifies REQ-TG-001
TEST(EndpointSequence, ReplayOfAnAcceptedFrameIsRejected) {
  Harness h(TrainConfig(0));
  h.Cycle(0);
  const EncodedFrame frame = Seal(PeerTelegram{.seq = 70, .echo = 0});
  EXPECT_EQ(h.Rx(10, frame).reason, RejectReason::kNone);
  const auto r = h.Rx(20, frame);
  EXPECT_EQ(r.reason, RejectReason::kRepeated);
  EXPECT_EQ(r.link, LinkState::kUp);
  EXPECT_EQ(r.header, TelegramHeader{});
  EXPECT_TRUE(h.PayloadZero());
}

// @verifies REQ-TG-002
// @verifies REQ-TG-004
TEST(EndpointSequence, ReorderedFramesAreRejected) {
  Harness h = TrainUp(0, 0, 100);
  const EncodedFrame f101 = Seal(PeerTelegram{.seq = 101, .echo = 0});
  const EncodedFrame f102 = Seal(PeerTelegram{.seq = 102, .echo = 0});
  auto r = h.Rx(10, f102);
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_EQ(r.gap, 1U);  // 101 missing
  r = h.Rx(20, f101);    // overtaken: behind the last in-sequence number
  EXPECT_EQ(r.reason, RejectReason::kOutOfSequence);
  EXPECT_TRUE(h.PayloadZero());
}

// ---- addressing, authenticity, integrity (checks 1-5) ----------------------------------

// @verifies REQ-TG-007
TEST(EndpointAuth, ForgedFrameIsRejectedWithoutEffect) {
  Harness h(TrainConfig(0));
  h.Cycle(0);
  const auto r = h.Rx(10, Seal(PeerTelegram{.seq = 5, .echo = 0}, AttackerKey()));
  EXPECT_EQ(r.reason, RejectReason::kAuthFailed);
  EXPECT_EQ(r.link, LinkState::kNone);
  EXPECT_EQ(r.header, TelegramHeader{});
  EXPECT_TRUE(h.PayloadZero());
  EXPECT_FALSE(h.Cycle(20).tx.echo_valid);  // nothing was taken from it
}

// @verifies REQ-TG-003
TEST(EndpointAddressing, WrongSourceDestinationOrTypeIsRejected) {
  Harness train(TrainConfig(0));
  train.Cycle(0);
  const PeerTelegram good{.seq = 5, .echo = 0};
  PeerTelegram t = good;
  t.src = kOtherTrainId;
  EXPECT_EQ(train.Rx(10, t).reason, RejectReason::kWrongAddress);
  t = good;
  t.dst = kOtherTrainId;
  EXPECT_EQ(train.Rx(10, t).reason, RejectReason::kWrongAddress);
  t = good;
  t.type = TelegramType::kPosition;
  EXPECT_EQ(train.Rx(10, t).reason, RejectReason::kWrongAddress);
  EXPECT_TRUE(train.PayloadZero());
  EXPECT_EQ(train.Rx(10, good).reason, RejectReason::kNone);

  Harness ground(GroundConfig(0));
  ground.Cycle(0);
  const PeerTelegram pos{.seq = 5, .echo = 0, .type = TelegramType::kPosition, .src = kTrainId, .dst = kGroundId};
  t = pos;
  t.src = kOtherTrainId;  // another train's position telegram
  EXPECT_EQ(ground.Rx(10, t).reason, RejectReason::kWrongAddress);
  t = pos;
  t.type = TelegramType::kControl;
  EXPECT_EQ(ground.Rx(10, t).reason, RejectReason::kWrongAddress);
  t = pos;
  t.dst = kTrainId;
  EXPECT_EQ(ground.Rx(10, t).reason, RejectReason::kWrongAddress);
  EXPECT_EQ(ground.Rx(10, pos).reason, RejectReason::kNone);
}

// @verifies REQ-TG-005
// @verifies REQ-TG-010
// @verifies REQ-TG-018
TEST(EndpointIntegrity, CorruptedFramesAreRejectedCorrectableOnesAccepted) {
  Harness h(TrainConfig(0));
  h.Cycle(0);
  const EncodedFrame good = Seal(PeerTelegram{.seq = 5, .echo = 0});
  EncodedFrame bad = good;
  for (std::size_t i = 0; i < 9; ++i) {  // 9 symbols of block 0: beyond the radius t = 8
    bad.bytes[3 * i] = static_cast<std::uint8_t>(bad.bytes[3 * i] ^ 0xA5U);
  }
  auto r = h.Rx(10, bad);
  EXPECT_TRUE(r.reason == RejectReason::kRsUncorrectable || r.reason == RejectReason::kBadFormat ||
              r.reason == RejectReason::kCrcMismatch)
      << ToString(r.reason);
  EXPECT_TRUE(h.PayloadZero());

  EncodedFrame truncated = good;
  truncated.size -= 1;
  EXPECT_EQ(h.Rx(10, truncated).reason, RejectReason::kBadLength);
  EXPECT_EQ(h.ep.Receive(10, std::span<const std::uint8_t>(), h.payload).reason, RejectReason::kBadLength);

  EncodedFrame noisy = good;
  for (std::size_t i = 0; i < 8; ++i) {  // within the radius: corrected
    noisy.bytes[5 * i + 1] = static_cast<std::uint8_t>(noisy.bytes[5 * i + 1] ^ 0x3CU);
  }
  r = h.Rx(10, noisy);
  EXPECT_EQ(r.reason, RejectReason::kNone);
  EXPECT_TRUE(h.PayloadIs(kPayload));
}

// @verifies REQ-TG-018
TEST(EndpointReceive, TooSmallPayloadBufferIsATypedErrorWithoutStateChange) {
  Harness h(TrainConfig(0));
  h.Cycle(0);
  std::array<std::uint8_t, kPayloadMax - 1> small{};
  const EncodedFrame f = Seal(PeerTelegram{.seq = 5, .echo = 0});
  EXPECT_EQ(h.ep.Receive(10, f.View(), small).reason, RejectReason::kBadLength);
  EXPECT_FALSE(h.Cycle(20).tx.echo_valid);  // the telegram was not processed
  EXPECT_EQ(h.Rx(20, f).reason, RejectReason::kNone);
}

// ---- time wrap of the uint32 ms clock --------------------------------------------------

// @verifies REQ-TG-006
// @verifies REQ-TG-009
// @verifies REQ-TG-013
TEST(EndpointTime, ClockWrapIsHandledByWrapSafeDifferences) {
  const std::uint32_t t0 = 0xFFFFFFFFU - 1000U;  // 1001 ms before the wrap
  Harness h = TrainUp(t0, 0, 10);
  // Turnaround across the wrap: send at t0, receipts at t0 + 3000 and t0 + 3001 (wrapped).
  h.Cycle(t0 + 1000U);  // seq 1 at 0xFFFFFFFF
  EXPECT_EQ(h.Rx(t0 + kTurnaround + 1U, PeerTelegram{.seq = 11, .echo = 0}).reason, RejectReason::kStale);
  auto r = h.Rx(t0 + kTurnaround + 1U, PeerTelegram{.seq = 12, .echo = 1});
  EXPECT_EQ(r.reason, RejectReason::kNone);
  const std::uint32_t ta = t0 + kTurnaround + 1U;  // = 2000 after the wrap
  EXPECT_LT(ta, t0);
  const auto [at, after] = h.CyclesAtTimeout(ta);
  EXPECT_EQ(at.link, LinkState::kUp);
  EXPECT_EQ(after.link, LinkState::kLost);

  // Link timeout across the wrap itself.
  Harness w = TrainUp(0xFFFFFFFFU - 100U, 0, 10);
  EXPECT_EQ(w.Cycle(kLinkTimeout - 101U).link, LinkState::kUp);
  EXPECT_EQ(w.Cycle(kLinkTimeout - 100U).link, LinkState::kLost);
}

// A send time older than the turnaround is latched expired, so it stays stale even when
// its uint32 age would wrap back to a small value.
// @verifies REQ-TG-009
TEST(EndpointTime, ExpiredSendTimesStayExpired) {
  Harness h(TrainConfig(0));
  h.Cycle(0);                       // seq 0 at t = 0
  h.Cycle(kTurnaround + 1U);        // latches seq 0 expired
  EXPECT_EQ(h.Rx(5, PeerTelegram{.seq = 1, .echo = 0}).reason, RejectReason::kStale);  // t = 2^32 + 5
}

// ---- determinism and no heap -----------------------------------------------------------

// @verifies REQ-TG-018
TEST(EndpointRuntime, SameInputsSameOutputsBitForBit) {
  Harness a = TrainUp(0, 0, 10);
  Harness b = TrainUp(0, 0, 10);
  for (std::uint32_t i = 1; i < 10; ++i) {
    const auto ca = a.Cycle(700U * i);
    const auto cb = b.Cycle(700U * i);
    EXPECT_EQ(ca.tx, cb.tx);
    EXPECT_EQ(a.frame.size, b.frame.size);
    EXPECT_TRUE(std::equal(a.frame.bytes.begin(), a.frame.bytes.end(), b.frame.bytes.begin()));
    const EncodedFrame f = Seal(PeerTelegram{.seq = 10U + i, .echo = ca.tx.seq});
    const auto ra = a.Rx(700U * i + 5U, f);
    const auto rb = b.Rx(700U * i + 5U, f);
    EXPECT_EQ(ra.reason, RejectReason::kNone);
    EXPECT_EQ(ra.reason, rb.reason);
    EXPECT_EQ(ra.header, rb.header);
    EXPECT_EQ(a.payload, b.payload);
  }
}

// @verifies REQ-TG-018
TEST(EndpointRuntime, NoHeapAllocationInCycleOrReceiveAfterInit) {
  Endpoint train;
  Endpoint ground;
  ASSERT_EQ(train.Init(TrainConfig(0xFFFFFFF0U), Key()), ConfigError::kNone);
  ASSERT_EQ(ground.Init(GroundConfig(3), Key()), ConfigError::kNone);
  // Inputs of every kind, prepared before counting starts.
  const EncodedFrame forged = Seal(PeerTelegram{.seq = 9, .echo = 1}, AttackerKey());
  EncodedFrame corrupt = Seal(PeerTelegram{.seq = 9, .echo = 1});
  for (std::size_t i = 0; i < 12; ++i) {
    corrupt.bytes[i] = static_cast<std::uint8_t>(corrupt.bytes[i] ^ 0xFFU);
  }
  const std::array<std::uint8_t, 3> garbage = {1, 2, 3};
  EncodedFrame to_train{};
  EncodedFrame to_ground{};
  std::array<std::uint8_t, kPayloadMax> payload{};
  std::size_t accepted = 0;
  std::size_t rejected = 0;

  railproof::testing::StartCountingAllocations();
  for (std::uint32_t i = 0; i < 50; ++i) {
    const std::uint32_t now = 500U * i;
    (void)ground.Cycle(now, kPayload, to_train);
    accepted += train.Receive(now + 10U, to_train.View(), payload).reason == RejectReason::kNone ? 1U : 0U;
    (void)train.Cycle(now + 20U, kPayload, to_ground);
    accepted += ground.Receive(now + 30U, to_ground.View(), payload).reason == RejectReason::kNone ? 1U : 0U;
    rejected += train.Receive(now + 40U, forged.View(), payload).reason != RejectReason::kNone ? 1U : 0U;
    rejected += train.Receive(now + 40U, corrupt.View(), payload).reason != RejectReason::kNone ? 1U : 0U;
    rejected += train.Receive(now + 40U, garbage, payload).reason != RejectReason::kNone ? 1U : 0U;
    rejected += train.Receive(now + 40U, to_train.View(), payload).reason != RejectReason::kNone ? 1U : 0U;
  }
  const std::size_t allocations = railproof::testing::StopCountingAllocations();

  EXPECT_EQ(allocations, 0U);
  EXPECT_GE(accepted, 95U);  // all but the bootstrap telegram(s)
  EXPECT_EQ(rejected, 200U);
  // The counter itself works (otherwise the assertion above would be vacuous).
  railproof::testing::StartCountingAllocations();
  void* probe = ::operator new(sizeof(int));
  const std::size_t probe_allocations = railproof::testing::StopCountingAllocations();
  ::operator delete(probe);
  EXPECT_EQ(probe_allocations, 1U);
}

}  // namespace
}  // namespace railproof::tg
