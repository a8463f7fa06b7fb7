// Unit tests of the application codec (railproof/messages/codec.hpp): every type round trip
// at its bounds, the documented layout byte for byte, every rejection with its reason and
// field, every truncation, corrupted type bytes, the restriction truncation, no allocation.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "railproof/core/units.hpp"
#include "railproof/messages/codec.hpp"
#include "railproof/testing/alloc_counter.hpp"
#include "railproof/testing/enum_names.hpp"
#include "sample_messages.hpp"

namespace railproof::messages {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::BoundarySamples;

template <typename... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <typename... F>
Overloaded(F...) -> Overloaded<F...>;

// Every field of a message, as text (messages have no operator==).
std::string Describe(const Message& m) {
  std::ostringstream o;
  o << ToString(TypeOf(m));
  std::visit(Overloaded{
                 [](const std::monostate&) {},
                 [&](const PositionReport& r) {
                   o << ' ' << r.train_id << ' ' << r.front_block << ' ' << r.offset_mm << ' ' << r.length_mm << ' '
                     << r.correction_mm << ' ' << r.last_balise_mm << ' ' << r.speed_mm_s << ' '
                     << static_cast<int>(r.direction);
                 },
                 [](const NoPosition&) {},
                 [&](const StopLimitTelegram& t) {
                   o << ' ' << t.train_id << ' ' << t.limit_mm << ' ' << ToString(t.kind) << ' ' << t.issue_time_ms
                     << ' ' << t.restriction_count << ' ' << t.restrictions_truncated;
                   for (std::size_t i = 0; i < t.restriction_count && i < t.restrictions.size(); ++i) {
                     const SpeedRestriction& r = t.restrictions[i];
                     o << " [" << r.id << ' ' << r.begin_mm << ' ' << r.end_mm << ' ' << r.speed_mm_s << ']';
                   }
                 },
                 [](const KeepAlive&) {},
                 [&](const CrossingRequest& r) { o << ' ' << r.train_id << ' ' << r.crossing_id; },
                 [&](const CrossingWithdrawal& w) { o << ' ' << w.request.train_id << ' ' << w.request.crossing_id; },
                 [&](const CrossingReport& r) {
                   o << ' ' << r.crossing_id << ' ' << ToString(r.status) << ' ' << r.warning_start_ms << ' '
                     << r.issued_ms << ' ' << r.clock_fault << ' ' << r.requester_count;
                   for (std::size_t i = 0; i < r.requester_count && i < r.requesters.size(); ++i) {
                     o << ' ' << r.requesters[i];
                   }
                 },
                 [&](const WithdrawalAck& a) { o << ' ' << a.crossing_id << ' ' << a.train_id; },
                 [&](const CentrePositionReport& p) {
                   o << ' ' << p.train_id << ' ' << p.time_ms << ' ' << p.front_mm << ' ' << p.rear_mm << ' '
                     << p.speed_mm_s;
                 },
             },
             m);
  return o.str();
}

// The layout of codec.hpp written without any check (an independent writer of the documented
// bytes): the reference of the golden tests and the maker of invalid payloads. Counts are
// written as given, followed by as many entries as the message holds.
class Wire {
 public:
  Wire& Put(std::uint64_t v, int bytes) {
    for (int k = bytes - 1; k >= 0; --k) {
      out.push_back(static_cast<std::uint8_t>(v >> (8 * k)));
    }
    return *this;
  }
  Wire& S(std::int64_t v, int bytes) { return Put(static_cast<std::uint64_t>(v), bytes); }
  Bytes out;
};

Bytes Layout(const Message& m) {
  Wire w;
  w.Put(m.index(), 1);
  std::visit(Overloaded{
                 [](const std::monostate&) {},
                 [&](const PositionReport& r) {
                   w.Put(r.train_id, 4).Put(r.front_block, 4).S(r.offset_mm, 8).S(r.length_mm, 8);
                   w.S(r.correction_mm, 8).S(r.last_balise_mm, 8).S(r.speed_mm_s, 8);
                   w.Put(static_cast<std::uint8_t>(r.direction), 1);
                 },
                 [](const NoPosition&) {},
                 [&](const StopLimitTelegram& t) {
                   w.Put(t.train_id, 4).S(t.limit_mm, 8).Put(static_cast<std::uint8_t>(t.kind), 1);
                   w.S(t.issue_time_ms, 8).Put(t.restriction_count, 1).Put(t.restrictions_truncated ? 1U : 0U, 1);
                   for (std::size_t i = 0; i < t.restriction_count && i < t.restrictions.size(); ++i) {
                     const SpeedRestriction& r = t.restrictions[i];
                     w.Put(r.id, 4).S(r.begin_mm, 4).S(r.end_mm, 4).S(r.speed_mm_s, 4);
                   }
                 },
                 [](const KeepAlive&) {},
                 [&](const CrossingRequest& r) { w.Put(r.train_id, 4).Put(r.crossing_id, 4); },
                 [&](const CrossingWithdrawal& x) { w.Put(x.request.train_id, 4).Put(x.request.crossing_id, 4); },
                 [&](const CrossingReport& r) {
                   w.Put(r.crossing_id, 4).Put(static_cast<std::uint8_t>(r.status), 1).S(r.warning_start_ms, 8);
                   w.S(r.issued_ms, 8).Put(r.clock_fault ? 1U : 0U, 1).Put(r.requester_count, 1);
                   for (std::size_t i = 0; i < r.requester_count && i < r.requesters.size(); ++i) {
                     w.Put(r.requesters[i], 4);
                   }
                 },
                 [&](const WithdrawalAck& a) { w.Put(a.crossing_id, 4).Put(a.train_id, 4); },
                 [&](const CentrePositionReport& p) {
                   w.Put(p.train_id, 4).S(p.time_ms, 8).S(p.front_mm, 8).S(p.rear_mm, 8).S(p.speed_mm_s, 8);
                 },
             },
             m);
  return w.out;
}

Bytes ToBytes(const Payload& p) {
  const auto v = p.View();
  return Bytes(v.begin(), v.end());
}

// Entries of a message (restrictions, requesters), 0 for the fixed types.
std::size_t Entries(const Message& m) {
  if (const auto* t = std::get_if<StopLimitTelegram>(&m)) {
    return t->restriction_count;
  }
  if (const auto* r = std::get_if<CrossingReport>(&m)) {
    return r->requester_count;
  }
  return 0;
}

// ---- names and sizes -------------------------------------------------------------------------

TEST(MessagesCodec, EnumNames) {
  const std::array<const char*, 11> types = {"INVALID",          "POSITION_REPORT",     "NO_POSITION",
                                             "STOP_LIMIT",       "KEEP_ALIVE",          "CROSSING_REQUEST",
                                             "CROSSING_WITHDRAWAL", "CROSSING_REPORT",  "WITHDRAWAL_ACK",
                                             "CENTRE_POSITION_REPORT", "INVALID"};
  for (std::size_t i = 0; i < types.size(); ++i) {
    EXPECT_STREQ(ToString(static_cast<MessageType>(i)), types[i]) << "type byte " << i;
  }
  testing::ExpectEnumNames<DecodeError, 10>({"NONE", "EMPTY", "UNKNOWN_TYPE", "WRONG_LENGTH", "TOO_MANY_ENTRIES",
                                             "OUT_OF_RANGE", "BAD_ENUM", "BAD_FLAG", "EMPTY_RANGE", "UNSORTED"});
  testing::ExpectEnumNames<EncodeError, 5>(
      {"NONE", "NO_MESSAGE", "INVALID_MESSAGE", "NOT_REPRESENTABLE", "TOO_LARGE"});
  testing::ExpectEnumNames<Field, 21>({"none", "offset_mm", "length_mm", "correction_mm", "last_balise_mm",
                                       "speed_mm_s", "direction", "limit_mm", "kind", "restriction_count",
                                       "restrictions_truncated", "restriction.begin_mm", "restriction.end_mm",
                                       "restriction.speed_mm_s", "restriction order", "status", "clock_fault",
                                       "requester_count", "front_mm", "rear_mm", "bundle count"});
}

// The POSITION and CONTROL payloads keep the lengths of the line simulator's former coding (its
// channel draws its random numbers per byte); every message fits a telegram.
// @verifies REQ-MB-001 REQ-MB-024
TEST(MessagesCodec, PayloadLengths) {
  EXPECT_EQ(kPayloadCapacity, 128U);
  EXPECT_EQ(PayloadSize(MessageType::kPositionReport, 0), 50U);
  EXPECT_EQ(PayloadSize(MessageType::kNoPosition, 0), 1U);
  EXPECT_EQ(PayloadSize(MessageType::kKeepAlive, 0), 1U);
  for (std::size_t n = 0; n <= kWireRestrictionsMax; ++n) {
    EXPECT_EQ(PayloadSize(MessageType::kStopLimit, n), 24U + 16U * n);
  }
  EXPECT_EQ(PayloadSize(MessageType::kCrossingRequest, 0), 9U);
  EXPECT_EQ(PayloadSize(MessageType::kCrossingWithdrawal, 0), 9U);
  EXPECT_EQ(PayloadSize(MessageType::kWithdrawalAck, 0), 9U);
  EXPECT_EQ(PayloadSize(MessageType::kCrossingReport, 3), 36U);
  EXPECT_EQ(PayloadSize(MessageType::kCentrePositionReport, 0), 37U);
  EXPECT_EQ(PayloadSize(static_cast<MessageType>(0), 0), 0U);
  EXPECT_EQ(PayloadSize(static_cast<MessageType>(10), 0), 0U);
  EXPECT_LE(PayloadSize(MessageType::kStopLimit, kWireRestrictionsMax), kPayloadCapacity);
  EXPECT_LE(PayloadSize(MessageType::kCrossingReport, kMaxReportRequesters), kPayloadCapacity);
}

// ---- round trips and layout -----------------------------------------------------------------

// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-003 REQ-LC-004 REQ-LC-007 REQ-LC-010
TEST(MessagesCodec, EveryTypeRoundTripsAtItsBounds) {
  std::vector<bool> seen(10, false);
  for (const auto& s : BoundarySamples()) {
    SCOPED_TRACE(s.name);
    const Encoded e = Encode(s.message);
    ASSERT_TRUE(e.Ok()) << ToString(e.error) << " " << ToString(e.invalid) << " " << ToString(e.field);
    EXPECT_EQ(e.payload.size, PayloadSize(TypeOf(s.message), Entries(s.message)));
    EXPECT_EQ(e.payload.View()[0], static_cast<std::uint8_t>(TypeOf(s.message)));
    EXPECT_EQ(ToBytes(e.payload), Layout(s.message)) << "the bytes are not the documented layout";
    const Decoded d = Decode(e.payload.View());
    ASSERT_TRUE(d.Ok()) << ToString(d.error) << " " << ToString(d.field);
    EXPECT_EQ(Describe(d.message), Describe(s.message));
    EXPECT_EQ(ToBytes(Encode(d.message).payload), ToBytes(e.payload));
    seen[s.message.index()] = true;
  }
  EXPECT_EQ(std::count(seen.begin() + 1, seen.end(), true), 9) << "every type has a sample";
}

// The documented layout, byte for byte, of a position report and a stop-limit telegram.
// @verifies REQ-MB-001 REQ-MB-024
TEST(MessagesCodec, PositionAndStopLimitBytes) {
  const PositionReport r{0x01020304, 0x0A0B0C0D, 0x11, 0x123456, 0x22, -2, 0x7FFF, Direction::kReverse};
  const Bytes position = {1,                                               // type
                          0x01, 0x02, 0x03, 0x04,                          // train_id
                          0x0A, 0x0B, 0x0C, 0x0D,                          // front_block
                          0,    0,    0,    0,    0,    0,    0,    0x11,  // offset_mm
                          0,    0,    0,    0,    0,    0x12, 0x34, 0x56,  // length_mm
                          0,    0,    0,    0,    0,    0,    0,    0x22,  // correction_mm
                          0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFE,  // last_balise_mm
                          0,    0,    0,    0,    0,    0,    0x7F, 0xFF,  // speed_mm_s
                          1};                                              // direction
  EXPECT_EQ(ToBytes(Encode(r).payload), position);
  StopLimitTelegram t{};
  t.train_id = 7;
  t.limit_mm = -1;
  t.kind = Obstruction::kPossession;
  t.issue_time_ms = 0x0102;
  t.restriction_count = 1;
  t.restrictions[0] = SpeedRestriction{9, -16, 0x0100, 0x0203};
  const Bytes stop_limit = {3,                                               // type
                            0,    0,    0,    7,                             // train_id
                            0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF,  // limit_mm
                            6,                                               // kind
                            0,    0,    0,    0,    0,    0,    1,    2,     // issue_time_ms
                            1,    0,                                         // n, truncated
                            0,    0,    0,    9,                             // id
                            0xFF, 0xFF, 0xFF, 0xF0,                          // begin_mm
                            0,    0,    1,    0,                             // end_mm
                            0,    0,    2,    3};                            // speed_mm_s
  EXPECT_EQ(ToBytes(Encode(t).payload), stop_limit);
  EXPECT_EQ(ToBytes(Encode(NoPosition{}).payload), Bytes{2});
  EXPECT_EQ(ToBytes(Encode(KeepAlive{}).payload), Bytes{4});
}

// The payloads of the line simulator (the values of its former codec test).
// @verifies REQ-MB-001 REQ-MB-024
TEST(MessagesCodec, SimulatorPayloadsRoundTrip) {
  const PositionReport r{.train_id = 7,
                         .front_block = 12,
                         .offset_mm = 34'567,
                         .length_mm = 100'000,
                         .correction_mm = 321,
                         .last_balise_mm = 250'000,
                         .speed_mm_s = 27'777,
                         .direction = Direction::kNominal};
  const Encoded pe = Encode(r);
  const Decoded back = Decode(pe.payload.View());
  const auto* rb = std::get_if<PositionReport>(&back.message);
  ASSERT_NE(rb, nullptr);
  EXPECT_EQ(rb->offset_mm, 34'567);
  EXPECT_EQ(rb->speed_mm_s, 27'777);
  EXPECT_EQ(rb->front_block, 12U);
  EXPECT_TRUE(std::holds_alternative<NoPosition>(Decode(Encode(NoPosition{}).payload.View()).message));
  Bytes short_position = ToBytes(pe.payload);
  short_position.pop_back();
  EXPECT_EQ(Decode(short_position).error, DecodeError::kWrongLength);

  StopLimitTelegram t{};
  t.train_id = 7;
  t.limit_mm = 1'234'567;
  t.kind = Obstruction::kPossession;
  t.issue_time_ms = 99'500;
  t.restriction_count = 1;
  t.restrictions[0] = SpeedRestriction{3, 2'000'000, 2'500'000, 8'333};
  const Encoded te = Encode(t);
  EXPECT_EQ(te.payload.size, 40U);
  const Decoded tb = Decode(te.payload.View());
  const auto* tt = std::get_if<StopLimitTelegram>(&tb.message);
  ASSERT_NE(tt, nullptr);
  EXPECT_EQ(tt->limit_mm, 1'234'567);
  EXPECT_EQ(tt->kind, Obstruction::kPossession);
  EXPECT_EQ(tt->issue_time_ms, 99'500);
  ASSERT_EQ(tt->restriction_count, 1U);
  EXPECT_FALSE(tt->restrictions_truncated);
  EXPECT_EQ(tt->restrictions[0].end_mm, 2'500'000);
  EXPECT_EQ(tt->restrictions[0].speed_mm_s, 8'333);
  EXPECT_TRUE(std::holds_alternative<KeepAlive>(Decode(Encode(KeepAlive{}).payload.View()).message));
  Bytes long_stop_limit = ToBytes(te.payload);
  long_stop_limit.push_back(0);
  EXPECT_EQ(Decode(long_stop_limit).error, DecodeError::kWrongLength);
}

// ---- restriction truncation -------------------------------------------------------------------

// @verifies REQ-MB-024 REQ-MB-015
TEST(MessagesCodec, StopLimitCarriesTheNearestSixRestrictions) {
  for (const std::uint32_t count : {6U, 7U, 8U}) {
    SCOPED_TRACE(count);
    StopLimitTelegram t = test::StopLimitMax();
    t.restrictions_truncated = false;
    t.restriction_count = count;
    for (std::uint32_t i = 6; i < count; ++i) {
      t.restrictions[i] = SpeedRestriction{100 + i, test::kI32Max, test::kI32Max + 1 + i, 5'000};
    }
    const Encoded e = Encode(t);
    ASSERT_TRUE(e.Ok()) << ToString(e.invalid) << " " << ToString(e.field);
    EXPECT_EQ(e.payload.size, 24U + 16U * kWireRestrictionsMax);
    const Decoded d = Decode(e.payload.View());
    const auto* back = std::get_if<StopLimitTelegram>(&d.message);
    ASSERT_NE(back, nullptr);
    EXPECT_EQ(back->restriction_count, kWireRestrictionsMax);
    EXPECT_EQ(back->restrictions_truncated, count > kWireRestrictionsMax);
    for (std::size_t i = 0; i < kWireRestrictionsMax; ++i) {
      EXPECT_EQ(back->restrictions[i].id, t.restrictions[i].id);
    }
  }
  // the ground's flag is kept when nothing is left out here
  StopLimitTelegram flagged = test::StopLimitMin();
  flagged.restrictions_truncated = true;
  const Decoded d = Decode(Encode(flagged).payload.View());
  const auto* back = std::get_if<StopLimitTelegram>(&d.message);
  ASSERT_NE(back, nullptr);
  EXPECT_TRUE(back->restrictions_truncated);
}

// ---- rejections --------------------------------------------------------------------------------

// An invalid message: Decode of its layout gives `error` on `field`; Encode refuses it with
// the same reason (unless `encodes`: the wire's count is above the wire maximum, which the
// encoder truncates).
struct Invalid {
  std::string name;
  Message message;
  DecodeError error;
  Field field;
  bool encodes = false;
};

template <typename M, typename F>
Message With(M m, F change) {
  change(m);
  return m;
}

std::vector<Invalid> InvalidMessages() {
  using test::CentreMax;
  using test::PositionMin;
  using test::ReportMax;
  using test::StopLimitMax;
  using test::StopLimitMin;
  constexpr auto kOut = DecodeError::kOutOfRange;
  constexpr std::int64_t kPos = core::kMaxPositionMm;
  std::vector<Invalid> v = {
      {"offset negative", With(PositionMin(), [](auto& r) { r.offset_mm = -1; }), kOut, Field::kOffset},
      {"offset beyond", With(PositionMin(), [](auto& r) { r.offset_mm = kPos + 1; }), kOut, Field::kOffset},
      {"length zero", With(PositionMin(), [](auto& r) { r.length_mm = 0; }), kOut, Field::kLength},
      {"length negative", With(PositionMin(), [](auto& r) { r.length_mm = -1; }), kOut, Field::kLength},
      {"length beyond",
       With(PositionMin(), [](auto& r) { r.length_mm = core::kMaxTrainLengthMm + 1; }), kOut, Field::kLength},
      {"correction negative", With(PositionMin(), [](auto& r) { r.correction_mm = -1; }), kOut, Field::kCorrection},
      {"correction beyond",
       With(PositionMin(), [](auto& r) { r.correction_mm = core::kMaxPositionErrorMm + 1; }), kOut,
       Field::kCorrection},
      {"balise below", With(PositionMin(), [](auto& r) { r.last_balise_mm = -kPos - 1; }), kOut, Field::kLastBalise},
      {"balise beyond", With(PositionMin(), [](auto& r) { r.last_balise_mm = kPos + 1; }), kOut, Field::kLastBalise},
      {"speed negative", With(PositionMin(), [](auto& r) { r.speed_mm_s = -1; }), kOut, Field::kSpeed},
      {"speed beyond",
       With(PositionMin(), [](auto& r) { r.speed_mm_s = core::kMaxMeasuredSpeedMmS + 1; }), kOut, Field::kSpeed},
      {"direction 2", With(PositionMin(), [](auto& r) { r.direction = static_cast<Direction>(2); }),
       DecodeError::kBadEnum, Field::kDirection},
      {"first field in layout order",
       With(PositionMin(),
            [](auto& r) {
              r.speed_mm_s = -1;
              r.offset_mm = -1;
            }),
       kOut, Field::kOffset},
      {"limit below", With(StopLimitMin(), [](auto& t) { t.limit_mm = -kPos - 1; }), kOut, Field::kLimit},
      {"limit beyond", With(StopLimitMin(), [](auto& t) { t.limit_mm = kPos + 1; }), kOut, Field::kLimit},
      {"obstruction 9", With(StopLimitMin(), [](auto& t) { t.kind = static_cast<Obstruction>(9); }),
       DecodeError::kBadEnum, Field::kKind},
      {"obstruction 255", With(StopLimitMin(), [](auto& t) { t.kind = static_cast<Obstruction>(255); }),
       DecodeError::kBadEnum, Field::kKind},
      {"7 restrictions on the wire",
       With(StopLimitMax(),
            [](auto& t) {
              t.restriction_count = 7;
              t.restrictions[6] = SpeedRestriction{3, test::kI32Max - 1, test::kI32Max, 1'000};
            }),
       DecodeError::kTooManyEntries, Field::kRestrictionCount, true},
      {"9 restrictions", With(StopLimitMax(), [](auto& t) { t.restriction_count = 9; }),
       DecodeError::kTooManyEntries, Field::kRestrictionCount},
      {"restriction empty",
       With(StopLimitMax(), [](auto& t) { t.restrictions[4].end_mm = t.restrictions[4].begin_mm; }),
       DecodeError::kEmptyRange, Field::kRestrictionEnd},
      {"restriction reversed", With(StopLimitMax(), [](auto& t) { t.restrictions[4].end_mm = 1'999'999; }),
       DecodeError::kEmptyRange, Field::kRestrictionEnd},
      {"restriction speed zero", With(StopLimitMax(), [](auto& t) { t.restrictions[2].speed_mm_s = 0; }), kOut,
       Field::kRestrictionSpeed},
      {"restriction speed beyond",
       With(StopLimitMax(), [](auto& t) { t.restrictions[2].speed_mm_s = core::kMaxLimitMmS + 1; }), kOut,
       Field::kRestrictionSpeed},
      {"restriction speed 2^32-1", With(StopLimitMax(), [](auto& t) { t.restrictions[5].speed_mm_s = 0xFFFFFFFF; }),
       kOut, Field::kRestrictionSpeed},
      {"restrictions unsorted", With(StopLimitMax(), [](auto& t) { std::swap(t.restrictions[0], t.restrictions[1]); }),
       DecodeError::kUnsorted, Field::kRestrictionOrder},
      {"same begin, ids unsorted",
       With(StopLimitMax(), [](auto& t) { std::swap(t.restrictions[2].id, t.restrictions[3].id); }),
       DecodeError::kUnsorted, Field::kRestrictionOrder},
      {"restriction twice", With(StopLimitMax(), [](auto& t) { t.restrictions[3] = t.restrictions[2]; }),
       DecodeError::kUnsorted, Field::kRestrictionOrder},
      {"status 4", With(ReportMax(), [](auto& r) { r.status = static_cast<CrossingStatus>(4); }),
       DecodeError::kBadEnum, Field::kStatus},
      {"17 requesters", With(ReportMax(), [](auto& r) { r.requester_count = kMaxReportRequesters + 1; }),
       DecodeError::kTooManyEntries, Field::kRequesterCount},
      {"front below", With(CentreMax(), [](auto& p) { p.front_mm = -kPos - 1; }), kOut, Field::kFront},
      {"front beyond", With(CentreMax(), [](auto& p) { p.front_mm = kPos + 1; }), kOut, Field::kFront},
      {"rear below", With(CentreMax(), [](auto& p) { p.rear_mm = -kPos - 1; }), kOut, Field::kRear},
      {"rear beyond",
       With(CentreMax(),
            [](auto& p) {
              p.rear_mm = kPos + 1;
              p.front_mm = kPos;
            }),
       kOut, Field::kRear},
      {"rear ahead of front",
       With(CentreMax(),
            [](auto& p) {
              p.front_mm = 0;
              p.rear_mm = 1;
            }),
       DecodeError::kEmptyRange, Field::kRear},
      {"centre speed negative", With(CentreMax(), [](auto& p) { p.speed_mm_s = -1; }), kOut, Field::kSpeed},
      {"centre speed beyond",
       With(CentreMax(), [](auto& p) { p.speed_mm_s = core::kMaxMeasuredSpeedMmS + 1; }), kOut, Field::kSpeed},
  };
  return v;
}

// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-003 REQ-LC-006 REQ-LC-010
TEST(MessagesCodec, EveryInvalidFieldIsRejectedWithItsReason) {
  for (const Invalid& c : InvalidMessages()) {
    SCOPED_TRACE(c.name);
    const Decoded d = Decode(Layout(c.message));
    EXPECT_EQ(d.error, c.error) << ToString(d.error);
    EXPECT_EQ(d.field, c.field) << ToString(d.field);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(d.message)) << "a rejection holds no message";
    const Encoded e = Encode(c.message);
    if (c.encodes) {
      EXPECT_TRUE(e.Ok());
      continue;
    }
    EXPECT_EQ(e.error, EncodeError::kInvalidMessage);
    EXPECT_EQ(e.invalid, c.error) << ToString(e.invalid);
    EXPECT_EQ(e.field, c.field) << ToString(e.field);
    EXPECT_EQ(e.payload.size, 0U);
  }
}

// Flag bytes other than 0 and 1 (a bool cannot hold them: the bytes are set directly).
// @verifies REQ-MB-024 REQ-LC-013
TEST(MessagesCodec, FlagBytesOtherThanZeroOrOneAreRejected) {
  for (const std::uint8_t flag : std::initializer_list<std::uint8_t>{2, 0x80, 0xFF}) {
    Bytes stop_limit = Layout(test::StopLimitMin());
    stop_limit[23] = flag;
    const Decoded s = Decode(stop_limit);
    EXPECT_EQ(s.error, DecodeError::kBadFlag);
    EXPECT_EQ(s.field, Field::kTruncated);
    Bytes report = Layout(test::ReportMin());
    report[22] = flag;
    const Decoded r = Decode(report);
    EXPECT_EQ(r.error, DecodeError::kBadFlag);
    EXPECT_EQ(r.field, Field::kClockFault);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(r.message));
  }
}

// Valid values the layout cannot hold are refused, never cut.
// @verifies REQ-MB-024
TEST(MessagesCodec, EncodeRefusesWhatTheLayoutCannotHold) {
  struct Case {
    std::int64_t begin;
    std::int64_t end;
    EncodeError error;
    Field field;
  };
  const Case cases[] = {
      {test::kI32Max + 1, test::kI32Max + 2, EncodeError::kNotRepresentable, Field::kRestrictionBegin},
      {test::kI32Min - 1, 0, EncodeError::kNotRepresentable, Field::kRestrictionBegin},
      {0, test::kI32Max + 1, EncodeError::kNotRepresentable, Field::kRestrictionEnd},
      {0, core::kMaxPositionMm + 1, EncodeError::kInvalidMessage, Field::kRestrictionEnd},
      {-core::kMaxPositionMm - 1, 0, EncodeError::kInvalidMessage, Field::kRestrictionBegin},
  };
  for (const Case& c : cases) {
    StopLimitTelegram t = test::StopLimitMin();
    t.restriction_count = 1;
    t.restrictions[0] = SpeedRestriction{1, c.begin, c.end, 1'000};
    const Encoded e = Encode(t);
    EXPECT_EQ(e.error, c.error) << c.begin << " " << c.end;
    EXPECT_EQ(e.field, c.field) << c.begin << " " << c.end;
    EXPECT_EQ(e.payload.size, 0U);
  }
  // a restriction beyond the wire's six is not written, so its bounds need not fit int32
  StopLimitTelegram t = test::StopLimitMax();
  t.restriction_count = 7;
  t.restrictions[6] = SpeedRestriction{9, core::kMaxPositionMm - 1, core::kMaxPositionMm, 1'000};
  EXPECT_TRUE(Encode(t).Ok());
  const Encoded none = Encode(Message{});
  EXPECT_EQ(none.error, EncodeError::kNoMessage);
  EXPECT_EQ(none.payload.size, 0U);
}

// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-004 REQ-LC-007 REQ-LC-010
TEST(MessagesCodec, EmptyUnknownTypeAndWrongLength) {
  EXPECT_EQ(Decode(Bytes{}).error, DecodeError::kEmpty);
  for (const std::uint8_t type : std::initializer_list<std::uint8_t>{0, 10, 0x7F, 0xFF}) {
    EXPECT_EQ(Decode(Bytes{type}).error, DecodeError::kUnknownType);
    Bytes long_payload(50, 0);
    long_payload[0] = type;
    EXPECT_EQ(Decode(long_payload).error, DecodeError::kUnknownType);
  }
  Bytes two_announced = Layout(With(test::StopLimitMax(), [](auto& t) { t.restriction_count = 1; }));
  two_announced[22] = 2;  // one restriction follows
  EXPECT_EQ(Decode(two_announced).error, DecodeError::kWrongLength);
  Bytes one_requester = Layout(test::ReportMax());
  one_requester[23] = 15;  // sixteen follow
  EXPECT_EQ(Decode(one_requester).error, DecodeError::kWrongLength);
}

// Every cut of every message is rejected: kEmpty for no byte, kWrongLength otherwise; so is
// one byte more.
// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-004 REQ-LC-007 REQ-LC-010
TEST(MessagesCodec, EveryTruncationIsRejected) {
  std::size_t cuts = 0;
  for (const auto& s : BoundarySamples()) {
    SCOPED_TRACE(s.name);
    const Bytes whole = ToBytes(Encode(s.message).payload);
    for (std::size_t len = 0; len < whole.size(); ++len) {
      const Decoded d = Decode(std::span<const std::uint8_t>(whole).first(len));
      EXPECT_EQ(d.error, len == 0 ? DecodeError::kEmpty : DecodeError::kWrongLength) << "length " << len;
      EXPECT_TRUE(std::holds_alternative<std::monostate>(d.message));
      ++cuts;
    }
    Bytes longer = whole;
    longer.push_back(0);
    EXPECT_EQ(Decode(longer).error, DecodeError::kWrongLength);
  }
  EXPECT_GT(cuts, 400U);
}

// Nothing beyond the end of a payload is read: a cut that ends before the entry count of a
// list message is rejected for its length, whatever byte lies beyond the cut (here a count
// above the maximum, which a read past the end would report as kTooManyEntries).
// @verifies REQ-MB-024 REQ-LC-003
TEST(MessagesCodec, NoByteBeyondTheCutIsRead) {
  struct ListMessage {
    const char* name;
    Bytes whole;
    std::size_t count_at;  // offset of the entry count (codec.hpp layouts)
  };
  const std::array<ListMessage, 2> lists{{
      {"stop limit", ToBytes(Encode(test::StopLimitMax()).payload), 22},
      {"crossing report", ToBytes(Encode(test::ReportMax()).payload), 23},
  }};
  for (const ListMessage& m : lists) {
    SCOPED_TRACE(m.name);
    ASSERT_GT(m.whole.size(), m.count_at);
    Bytes beyond = m.whole;
    beyond[m.count_at] = 0xFF;
    for (std::size_t len = 1; len <= m.count_at; ++len) {
      EXPECT_EQ(Decode(std::span<const std::uint8_t>(beyond).first(len)).error, DecodeError::kWrongLength)
          << "length " << len;
    }
    EXPECT_EQ(Decode(beyond).error, DecodeError::kTooManyEntries);  // the count read where it is
  }
}

// A corrupted type byte never yields a message of the sent type: a value outside 1..9 is
// kUnknownType; another type is decoded only if the length is that type's (then it is that
// type's message: request, withdrawal and acknowledgement, no-position and keep-alive, share
// their lengths; the telegram layer's integrity checks and the direction tell them apart).
// @verifies REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-004
TEST(MessagesCodec, CorruptedTypeByte) {
  for (const auto& s : BoundarySamples()) {
    SCOPED_TRACE(s.name);
    const Bytes whole = ToBytes(Encode(s.message).payload);
    for (unsigned v = 0; v < 256; ++v) {
      if (v == static_cast<unsigned>(whole[0])) {
        continue;
      }
      Bytes bad = whole;
      bad[0] = static_cast<std::uint8_t>(v);
      const Decoded d = Decode(bad);
      if (v == 0 || v > 9) {
        EXPECT_EQ(d.error, DecodeError::kUnknownType) << v;
      } else if (d.Ok()) {
        EXPECT_EQ(static_cast<unsigned>(TypeOf(d.message)), v);
        EXPECT_EQ(ToBytes(Encode(d.message).payload), bad);
      } else {
        EXPECT_TRUE(std::holds_alternative<std::monostate>(d.message));
      }
    }
  }
}

// ---- bundles -------------------------------------------------------------------------------------

// A position report with two crossing requests, as the on-board unit sends them in one telegram.
std::vector<Message> UplinkBundle() {
  return {Message{test::PositionMax()}, Message{CrossingRequest{7, 3}}, Message{CrossingWithdrawal{{7, 4}}}};
}

// @verifies REQ-MB-001 REQ-LC-002 REQ-LC-004
TEST(MessagesCodec, BundleRoundTripsWithItsDocumentedLayout) {
  const std::vector<Message> msgs = UplinkBundle();
  const Encoded e = EncodeBundle(msgs);
  ASSERT_TRUE(e.Ok()) << ToString(e.error);
  Bytes expected = {kBundleType, 3};
  for (const Message& m : msgs) {
    const Bytes one = Layout(m);
    expected.push_back(static_cast<std::uint8_t>(one.size()));
    expected.insert(expected.end(), one.begin(), one.end());
  }
  EXPECT_EQ(ToBytes(e.payload), expected);
  EXPECT_EQ(BundleSize(msgs), e.payload.size);
  EXPECT_EQ(e.payload.size, 2U + 51U + 10U + 10U);
  const DecodedBundle d = DecodeBundle(e.payload.View());
  ASSERT_TRUE(d.Ok()) << ToString(d.error) << " entry " << d.entry;
  ASSERT_EQ(d.bundle.size, msgs.size());
  for (std::size_t i = 0; i < msgs.size(); ++i) {
    EXPECT_EQ(Describe(d.bundle.View()[i]), Describe(msgs[i])) << "entry " << i;
  }
}

// One message is its plain payload both ways, so a unit reads single-message telegrams too.
TEST(MessagesCodec, BundleOfOneIsThePlainPayload) {
  for (const auto& s : BoundarySamples()) {
    SCOPED_TRACE(s.name);
    const std::array<Message, 1> one = {s.message};
    EXPECT_EQ(ToBytes(EncodeBundle(one).payload), ToBytes(Encode(s.message).payload));
    EXPECT_EQ(BundleSize(one), EncodedSize(s.message));
    const DecodedBundle d = DecodeBundle(Encode(s.message).payload.View());
    ASSERT_TRUE(d.Ok());
    ASSERT_EQ(d.bundle.size, 1U);
    EXPECT_EQ(Describe(d.bundle.View()[0]), Describe(s.message));
  }
  EXPECT_EQ(Decode(EncodeBundle(UplinkBundle()).payload.View()).error, DecodeError::kUnknownType)
      << "a single-message reader does not take a bundle for a message";
}

TEST(MessagesCodec, BundleEncodeRefusals) {
  EXPECT_EQ(EncodeBundle({}).error, EncodeError::kNoMessage);
  EXPECT_EQ(BundleSize({}), 0U);
  const std::vector<Message> nine(kBundleMax + 1, Message{KeepAlive{}});
  EXPECT_EQ(EncodeBundle(nine).error, EncodeError::kTooLarge);
  const std::vector<Message> eight(kBundleMax, Message{KeepAlive{}});
  EXPECT_TRUE(EncodeBundle(eight).Ok());
  // a full stop-limit telegram (120 bytes) leaves no room for a position report
  const std::vector<Message> big = {Message{test::StopLimitMax()}, Message{test::PositionMax()}};
  EXPECT_GT(BundleSize(big), kPayloadCapacity);
  const Encoded too_large = EncodeBundle(big);
  EXPECT_EQ(too_large.error, EncodeError::kTooLarge);
  EXPECT_EQ(too_large.payload.size, 0U);
  // a refused message refuses the bundle with its own reason
  PositionReport bad = test::PositionMax();
  bad.length_mm = 0;
  const std::vector<Message> with_bad = {Message{KeepAlive{}}, Message{bad}};
  const Encoded refused = EncodeBundle(with_bad);
  EXPECT_EQ(refused.error, EncodeError::kInvalidMessage);
  EXPECT_EQ(refused.field, Field::kLength);
  EXPECT_EQ(refused.payload.size, 0U);
  EXPECT_EQ(BundleSize(with_bad), 0U);
}

// A sender fills a bundle in priority order: what does not fit is refused and changes nothing.
TEST(MessagesCodec, AddIfFitsKeepsTheBundleWithinOnePayload) {
  Bundle b;
  ASSERT_TRUE(AddIfFits(b, Message{test::StopLimitMax()}));  // 120 bytes alone
  EXPECT_FALSE(AddIfFits(b, Message{test::PositionMax()}));  // 2 + 121 + 51 > 128
  EXPECT_EQ(b.size, 1U);
  EXPECT_TRUE(EncodeBundle(b.View()).Ok());
  Bundle small;
  std::size_t n = 0;
  while (AddIfFits(small, Message{CrossingRequest{7, static_cast<std::uint32_t>(n)}})) {
    ++n;
  }
  EXPECT_EQ(n, kBundleMax) << "eight 9-byte requests fit 2 + 8 x 10 bytes";
  EXPECT_TRUE(EncodeBundle(small.View()).Ok());
  PositionReport bad = test::PositionMax();
  bad.length_mm = 0;
  Bundle refused;
  EXPECT_FALSE(AddIfFits(refused, Message{bad})) << "a message the codec refuses is not added";
  EXPECT_EQ(refused.size, 0U);
}

TEST(MessagesCodec, BundleDecodeRejections) {
  const Bytes good = ToBytes(EncodeBundle(UplinkBundle()).payload);
  const auto decode = [](const Bytes& b) { return DecodeBundle(b); };
  EXPECT_EQ(decode({}).error, DecodeError::kEmpty);
  EXPECT_EQ(decode({kBundleType}).error, DecodeError::kWrongLength);
  for (const std::uint8_t n : std::array<std::uint8_t, 4>{0, 1, 9, 255}) {
    Bytes b = good;
    b[1] = n;
    const DecodedBundle d = decode(b);
    EXPECT_EQ(d.error, DecodeError::kTooManyEntries) << "n = " << int{n};
    EXPECT_EQ(d.field, Field::kBundleCount);
  }
  // every cut is rejected, naming the entry it falls in; nothing is returned
  for (std::size_t cut = 2; cut < good.size(); ++cut) {
    const DecodedBundle d = decode(Bytes(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(cut)));
    EXPECT_FALSE(d.Ok()) << "cut at " << cut;
    EXPECT_EQ(d.bundle.size, 0U);
  }
  Bytes trailing = good;
  trailing.push_back(0);
  EXPECT_EQ(decode(trailing).error, DecodeError::kWrongLength);
  // well-formed entries, but more bytes than a telegram carries (EncodeBundle refuses it)
  Bytes oversized = {kBundleType, 3};
  for (int i = 0; i < 3; ++i) {
    const Bytes report = Layout(Message{test::PositionMax()});
    oversized.push_back(static_cast<std::uint8_t>(report.size()));
    oversized.insert(oversized.end(), report.begin(), report.end());
  }
  ASSERT_GT(oversized.size(), kPayloadCapacity);
  EXPECT_EQ(decode(oversized).error, DecodeError::kWrongLength);
  // an entry's own error, with its index: the second entry's type byte corrupted
  Bytes bad_entry = good;
  bad_entry[2 + 51 + 1] = 42;
  const DecodedBundle d = decode(bad_entry);
  EXPECT_EQ(d.error, DecodeError::kUnknownType);
  EXPECT_EQ(d.entry, 1U);
  // a field error inside an entry keeps its field
  Bytes bad_direction = good;
  bad_direction[2 + 50] = 2;  // the report's direction byte
  const DecodedBundle dd = decode(bad_direction);
  EXPECT_EQ(dd.error, DecodeError::kBadEnum);
  EXPECT_EQ(dd.field, Field::kDirection);
  EXPECT_EQ(dd.entry, 0U);
  // no bundle inside a bundle
  Bytes nested = {kBundleType, 2, static_cast<std::uint8_t>(good.size())};
  nested.insert(nested.end(), good.begin(), good.end());
  nested.insert(nested.end(), {1, static_cast<std::uint8_t>(MessageType::kKeepAlive)});
  const DecodedBundle dn = decode(nested);
  EXPECT_EQ(dn.error, DecodeError::kUnknownType);
  EXPECT_EQ(dn.entry, 0U);
}

// ---- no heap ------------------------------------------------------------------------------------

// @verifies REQ-MB-021
TEST(MessagesCodec, NoAllocation) {
  const std::vector<test::Sample> samples = BoundarySamples();
  const std::vector<Invalid> invalid = InvalidMessages();
  std::vector<Bytes> invalid_bytes;
  for (const Invalid& c : invalid) {
    invalid_bytes.push_back(Layout(c.message));
  }
  const std::vector<Message> uplink = UplinkBundle();
  std::size_t ok = 0;
  railproof::testing::StartCountingAllocations();
  for (const auto& s : samples) {
    const Encoded e = Encode(s.message);
    ok += Decode(e.payload.View()).Ok() ? 1U : 0U;
  }
  for (std::size_t i = 0; i < invalid.size(); ++i) {
    ok += Encode(invalid[i].message).Ok() ? 1U : 0U;
    ok += Decode(invalid_bytes[i]).Ok() ? 1U : 0U;
  }
  ok += DecodeBundle(EncodeBundle(uplink).payload.View()).Ok() ? 1U : 0U;
  EXPECT_EQ(railproof::testing::StopCountingAllocations(), 0U);
  EXPECT_EQ(ok, samples.size() + 2U);  // the samples, the 7 restrictions the encoder truncates, the bundle
  // the counter sees a copy of the samples (otherwise the zero above would say nothing)
  railproof::testing::StartCountingAllocations();
  const std::vector<test::Sample> copy = samples;
  EXPECT_GT(railproof::testing::StopCountingAllocations(), 0U);
  EXPECT_EQ(copy.size(), samples.size());
}

}  // namespace
}  // namespace railproof::messages
