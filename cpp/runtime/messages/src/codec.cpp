// Byte coding of the application messages (layouts and ranges: codec.hpp).
#include "railproof/messages/codec.hpp"

#include <algorithm>
#include <array>
#include <concepts>
#include <limits>
#include <type_traits>
#include <utility>

#include "railproof/core/units.hpp"

namespace railproof::messages {

namespace {

// The layout of a type: `fixed` bytes, then `entry` bytes per entry, the entry count being
// the byte at `count_at` (at most `max_entries`, else kTooManyEntries on `count_field`).
struct Layout {
  std::size_t fixed = 0;  // 0: no such type
  std::size_t entry = 0;  // 0: a fixed-length type
  std::size_t count_at = 0;
  std::size_t max_entries = 0;
  Field count_field = Field::kNone;
};

constexpr std::size_t kTypeOnlyBytes = 1;
constexpr std::size_t kPositionBytes = 50;
constexpr std::size_t kStopLimitFixedBytes = 24;
constexpr std::size_t kRestrictionBytes = 16;
constexpr std::size_t kCrossingIdsBytes = 9;
constexpr std::size_t kReportFixedBytes = 24;
constexpr std::size_t kRequesterBytes = 4;
constexpr std::size_t kCentrePositionBytes = 37;

// By type byte (0 and above 9: no type).
constexpr std::array<Layout, 10> kLayouts = {{
    {},
    {kPositionBytes},                                                                          // POSITION_REPORT
    {kTypeOnlyBytes},                                                                          // NO_POSITION
    {kStopLimitFixedBytes, kRestrictionBytes, 22, kWireRestrictionsMax, Field::kRestrictionCount},  // STOP_LIMIT
    {kTypeOnlyBytes},                                                                          // KEEP_ALIVE
    {kCrossingIdsBytes},                                                                       // CROSSING_REQUEST
    {kCrossingIdsBytes},                                                                       // CROSSING_WITHDRAWAL
    {kReportFixedBytes, kRequesterBytes, 23, kMaxReportRequesters, Field::kRequesterCount},    // CROSSING_REPORT
    {kCrossingIdsBytes},                                                                       // WITHDRAWAL_ACK
    {kCentrePositionBytes},                                                                    // CENTRE_POSITION_REPORT
}};
static_assert(kLayouts.size() == std::variant_size_v<Message>);

constexpr Layout LayoutOf(MessageType t) noexcept {
  const auto index = static_cast<std::size_t>(t);
  return index < kLayouts.size() ? kLayouts[index] : Layout{};
}

// Every message fits a telegram; the counts fit their byte; the wire's restrictions fit the
// telegram's.
static_assert(LayoutOf(MessageType::kStopLimit).fixed + kRestrictionBytes * kWireRestrictionsMax <= kPayloadCapacity,
              "a stop-limit telegram with the most restrictions must fit a telegram payload");
static_assert(LayoutOf(MessageType::kCrossingReport).fixed + kRequesterBytes * kMaxReportRequesters <= kPayloadCapacity,
              "a crossing report with the most requesters must fit a telegram payload");
static_assert(kPositionBytes <= kPayloadCapacity && kCentrePositionBytes <= kPayloadCapacity &&
              kCrossingIdsBytes <= kPayloadCapacity);
static_assert(kWireRestrictionsMax <= kTelegramRestrictionsMax && kMaxReportRequesters <= 255);
// The variant's index is the type byte.
static_assert(std::is_same_v<std::variant_alternative_t<1, Message>, PositionReport> &&
              std::is_same_v<std::variant_alternative_t<3, Message>, StopLimitTelegram> &&
              std::is_same_v<std::variant_alternative_t<6, Message>, CrossingWithdrawal> &&
              std::is_same_v<std::variant_alternative_t<9, Message>, CentrePositionReport> &&
              std::variant_size_v<Message> == 10);

// The writer and the reader share one list of the fields of each message (Fields below):
// the same calls write a field's value or read it back into the field.

// Big-endian writer into a Payload. Every layout fits (static_asserts above); a write past
// the capacity is dropped.
class Writer {
 public:
  explicit Writer(Payload& out) noexcept : out_(out) { out_.size = 0; }
  void U8(std::uint8_t v) noexcept {
    if (out_.size < out_.bytes.size()) {
      out_.bytes[out_.size] = v;
      ++out_.size;
    }
  }
  void U32(std::uint32_t v) noexcept {
    for (unsigned shift = 32; shift > 0;) {
      shift -= 8;
      U8(static_cast<std::uint8_t>(v >> shift));
    }
  }
  void U32(std::int64_t v) noexcept { U32(static_cast<std::uint32_t>(v)); }  // 0 .. 2^32 - 1 checked
  void I32(std::int64_t v) noexcept { U32(static_cast<std::uint32_t>(static_cast<std::int32_t>(v))); }  // FitsInt32
  void I64(std::int64_t v) noexcept {
    const auto u = static_cast<std::uint64_t>(v);
    U32(static_cast<std::uint32_t>(u >> 32U));
    U32(static_cast<std::uint32_t>(u));
  }
  template <typename N>
  void Count(N n) noexcept {
    U8(static_cast<std::uint8_t>(n));  // at most the layout's maximum, checked
  }
  template <typename E>
  void Enum(E v) noexcept {
    U8(static_cast<std::uint8_t>(v));
  }
  void Flag(bool v) noexcept { U8(static_cast<std::uint8_t>(v ? 1 : 0)); }

 private:
  Payload& out_;
};

// Big-endian reader; Decode checks the length before any field is read (a read past the end
// gives 0). It keeps the byte of the last flag read (a message has at most one) for Checks.
class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> in) noexcept : in_(in) {}
  std::uint8_t Byte() noexcept {
    if (pos_ >= in_.size()) {
      return 0;  // GCOVR_EXCL_LINE defensive: the length is checked first
    }
    const std::uint8_t v = in_[pos_];
    ++pos_;
    return v;
  }
  std::uint32_t Word() noexcept {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) {
      v = (v << 8U) | Byte();
    }
    return v;
  }
  void U32(std::uint32_t& v) noexcept { v = Word(); }
  void U32(std::int64_t& v) noexcept { v = Word(); }
  void I32(std::int64_t& v) noexcept { v = static_cast<std::int32_t>(Word()); }
  void I64(std::int64_t& v) noexcept {
    const std::uint64_t high = Word();
    v = static_cast<std::int64_t>((high << 32U) | Word());
  }
  template <typename N>
  void Count(N& n) noexcept {
    n = Byte();  // at most the layout's maximum: checked with the length
  }
  template <typename E>
  void Enum(E& v) noexcept {
    v = static_cast<E>(Byte());
  }
  void Flag(bool& v) noexcept {
    flag_byte_ = Byte();
    v = flag_byte_ != 0;
  }
  [[nodiscard]] std::uint8_t FlagByte() const noexcept { return flag_byte_; }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
  std::uint8_t flag_byte_ = 0;
};

// The first failed check of a message, in layout order. The decoder passes the flag byte it
// read, the encoder 0 or 1.
class Checks {
 public:
  void Require(bool ok, DecodeError error, Field field) noexcept {
    if (!ok && error_ == DecodeError::kNone) {
      error_ = error;
      field_ = field;
    }
  }
  void Range(std::int64_t v, std::int64_t lo, std::int64_t hi, Field field) noexcept {
    Require(v >= lo && v <= hi, DecodeError::kOutOfRange, field);
  }
  void Position(std::int64_t v, Field field) noexcept { Range(v, -core::kMaxPositionMm, core::kMaxPositionMm, field); }
  void Flag(std::uint8_t v, Field field) noexcept { Require(v <= 1, DecodeError::kBadFlag, field); }
  template <typename E>
  void Enum(E v, E last, Field field) noexcept {
    Require(static_cast<std::uint8_t>(v) <= static_cast<std::uint8_t>(last), DecodeError::kBadEnum, field);
  }
  [[nodiscard]] DecodeError Error() const noexcept { return error_; }
  [[nodiscard]] Field GetField() const noexcept { return field_; }

 private:
  DecodeError error_ = DecodeError::kNone;
  Field field_ = Field::kNone;
};

// ---- the messages: each one's checks (Check, in layout order) and fields (Fields) ----------------
// Fields lists a message's fields after the type byte in layout order, for the writer (R
// const) and the reader alike; Check takes the flag byte read (the encoder's 0 or 1).

template <typename R, typename M>
concept Is = std::same_as<std::remove_const_t<R>, M>;

// @implements REQ-MB-001
void Check(const PositionReport& r, std::uint8_t /*flag*/, Checks& c) noexcept {
  c.Range(r.offset_mm, 0, core::kMaxPositionMm, Field::kOffset);
  c.Range(r.length_mm, 1, core::kMaxTrainLengthMm, Field::kLength);
  c.Range(r.correction_mm, 0, core::kMaxPositionErrorMm, Field::kCorrection);
  c.Position(r.last_balise_mm, Field::kLastBalise);
  c.Range(r.speed_mm_s, 0, core::kMaxMeasuredSpeedMmS, Field::kSpeed);
  c.Enum(r.direction, Direction::kReverse, Field::kDirection);
}

template <typename Io, Is<PositionReport> R>
void Fields(Io& io, R& r) noexcept {
  io.U32(r.train_id);
  io.U32(r.front_block);
  io.I64(r.offset_mm);
  io.I64(r.length_mm);
  io.I64(r.correction_mm);
  io.I64(r.last_balise_mm);
  io.I64(r.speed_mm_s);
  io.Enum(r.direction);
}

bool RestrictionBefore(const SpeedRestriction& a, const SpeedRestriction& b) noexcept {
  return a.begin_mm < b.begin_mm || (a.begin_mm == b.begin_mm && a.id < b.id);
}

// @implements REQ-MB-024 REQ-MB-006 REQ-MB-015
void Check(const StopLimitTelegram& t, std::uint8_t truncated, Checks& c) noexcept {
  c.Position(t.limit_mm, Field::kLimit);
  c.Enum(t.kind, Obstruction::kEndOfTrack, Field::kKind);
  c.Require(t.restriction_count <= kTelegramRestrictionsMax, DecodeError::kTooManyEntries, Field::kRestrictionCount);
  c.Flag(truncated, Field::kTruncated);
  const std::size_t n = std::min<std::size_t>(t.restriction_count, kTelegramRestrictionsMax);
  for (std::size_t i = 0; i < n; ++i) {
    const SpeedRestriction& r = t.restrictions[i];
    c.Position(r.begin_mm, Field::kRestrictionBegin);
    c.Position(r.end_mm, Field::kRestrictionEnd);
    c.Require(r.begin_mm < r.end_mm, DecodeError::kEmptyRange, Field::kRestrictionEnd);
    c.Range(r.speed_mm_s, 1, core::kMaxLimitMmS, Field::kRestrictionSpeed);
    c.Require(i == 0 || RestrictionBefore(t.restrictions[i - 1], r), DecodeError::kUnsorted,
              Field::kRestrictionOrder);
  }
}

// The count and the flag as the wire has them: Encode writes a copy with at most
// kWireRestrictionsMax restrictions (the nearest), `truncated` set if any is left out.
template <typename Io, Is<StopLimitTelegram> T>
void Fields(Io& io, T& t) noexcept {
  io.U32(t.train_id);
  io.I64(t.limit_mm);
  io.Enum(t.kind);
  io.I64(t.issue_time_ms);
  io.Count(t.restriction_count);
  io.Flag(t.restrictions_truncated);
  for (std::size_t i = 0; i < t.restriction_count && i < kWireRestrictionsMax; ++i) {
    auto& r = t.restrictions[i];
    io.U32(r.id);
    io.I32(r.begin_mm);
    io.I32(r.end_mm);
    io.U32(r.speed_mm_s);
  }
}

bool FitsInt32(std::int64_t v) noexcept {
  return v >= std::numeric_limits<std::int32_t>::min() && v <= std::numeric_limits<std::int32_t>::max();
}

// The field of the first written restriction bound outside int32, kNone if there is none.
Field Unrepresentable(const StopLimitTelegram& t) noexcept {
  const std::size_t n = std::min<std::size_t>(t.restriction_count, kWireRestrictionsMax);
  for (std::size_t i = 0; i < n; ++i) {
    if (!FitsInt32(t.restrictions[i].begin_mm)) {
      return Field::kRestrictionBegin;
    }
    if (!FitsInt32(t.restrictions[i].end_mm)) {
      return Field::kRestrictionEnd;
    }
  }
  return Field::kNone;
}

// @implements REQ-LC-002 REQ-LC-004
template <typename Io, Is<CrossingRequest> R>
void Fields(Io& io, R& r) noexcept {
  io.U32(r.train_id);
  io.U32(r.crossing_id);
}

// @implements REQ-LC-004
template <typename Io, Is<CrossingWithdrawal> W>
void Fields(Io& io, W& w) noexcept {
  Fields(io, w.request);
}

// @implements REQ-LC-004 REQ-LC-007
template <typename Io, Is<WithdrawalAck> A>
void Fields(Io& io, A& a) noexcept {
  io.U32(a.crossing_id);
  io.U32(a.train_id);
}

// @implements REQ-LC-003 REQ-LC-006 REQ-LC-013
void Check(const CrossingReport& r, std::uint8_t clock_fault, Checks& c) noexcept {
  c.Enum(r.status, CrossingStatus::kFailed, Field::kStatus);
  c.Flag(clock_fault, Field::kClockFault);
  c.Require(r.requester_count <= kMaxReportRequesters, DecodeError::kTooManyEntries, Field::kRequesterCount);
}

template <typename Io, Is<CrossingReport> R>
void Fields(Io& io, R& r) noexcept {
  io.U32(r.crossing_id);
  io.Enum(r.status);
  io.I64(r.warning_start_ms);
  io.I64(r.issued_ms);
  io.Flag(r.clock_fault);
  io.Count(r.requester_count);
  for (std::size_t i = 0; i < r.requester_count && i < kMaxReportRequesters; ++i) {
    io.U32(r.requesters[i]);
  }
}

// @implements REQ-LC-010
void Check(const CentrePositionReport& p, std::uint8_t /*flag*/, Checks& c) noexcept {
  c.Position(p.front_mm, Field::kFront);
  c.Position(p.rear_mm, Field::kRear);
  c.Require(p.rear_mm <= p.front_mm, DecodeError::kEmptyRange, Field::kRear);
  c.Range(p.speed_mm_s, 0, core::kMaxMeasuredSpeedMmS, Field::kSpeed);
}

template <typename Io, Is<CentrePositionReport> P>
void Fields(Io& io, P& p) noexcept {
  io.U32(p.train_id);
  io.I64(p.time_ms);
  io.I64(p.front_mm);
  io.I64(p.rear_mm);
  io.I64(p.speed_mm_s);
}

// The types without fields after the type byte (std::monostate has no type byte at all), and
// those without a checked field.
template <typename Io, typename M>
  requires Is<M, std::monostate> || Is<M, NoPosition> || Is<M, KeepAlive>
void Fields(Io& /*io*/, M& /*m*/) noexcept {}
void Check(const std::monostate& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}
void Check(const NoPosition& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}
void Check(const KeepAlive& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}
void Check(const CrossingRequest& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}
void Check(const CrossingWithdrawal& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}
void Check(const WithdrawalAck& /*m*/, std::uint8_t /*flag*/, Checks& /*c*/) noexcept {}

// The flag byte the encoder checks: the message's flag, 0 for the types without one.
std::uint8_t FlagOf(const StopLimitTelegram& t) noexcept {
  return static_cast<std::uint8_t>(t.restrictions_truncated ? 1 : 0);
}
std::uint8_t FlagOf(const CrossingReport& r) noexcept { return static_cast<std::uint8_t>(r.clock_fault ? 1 : 0); }
template <typename M>
std::uint8_t FlagOf(const M& /*m*/) noexcept {
  return 0;
}

// Only the stop-limit telegram has a valid value its layout cannot hold.
template <typename M>
Field Unrepresentable(const M& /*m*/) noexcept {
  return Field::kNone;
}

// ---- dispatch ---------------------------------------------------------------------------------

Decoded Failure(DecodeError error, Field field = Field::kNone) noexcept {
  Decoded d;
  d.error = error;
  d.field = field;
  return d;
}

template <typename M>
Message ReadAs(Reader& in, Checks& c) noexcept {
  M m{};
  Fields(in, m);
  Check(m, in.FlagByte(), c);
  return m;
}

// The reader of every type, by its type byte: the alternative of Message with that index.
using ReadFunction = Message (*)(Reader&, Checks&) noexcept;
template <std::size_t... I>
constexpr std::array<ReadFunction, sizeof...(I)> Readers(std::index_sequence<I...> /*types*/) noexcept {
  return {&ReadAs<std::variant_alternative_t<I, Message>>...};
}
constexpr auto kReaders = Readers(std::make_index_sequence<std::variant_size_v<Message>>());

// The message as the wire holds it: a stop-limit telegram's nearest kWireRestrictionsMax
// restrictions, `truncated` set if any is left out; every other message as it is.
template <typename M>
const M& OnTheWire(const M& m, M& /*scratch*/) noexcept {
  return m;
}
const StopLimitTelegram& OnTheWire(const StopLimitTelegram& t, StopLimitTelegram& wire) noexcept {
  wire = t;
  wire.restriction_count = static_cast<std::uint32_t>(std::min<std::size_t>(t.restriction_count, kWireRestrictionsMax));
  wire.restrictions_truncated = t.restrictions_truncated || wire.restriction_count < t.restriction_count;
  return wire;
}

// The visitor of Encode: checks one message, then writes it after its type byte.
struct Writing {
  Checks& checks;
  Writer& writer;
  Field unrepresentable = Field::kNone;

  template <typename M>
  void operator()(const M& m) noexcept {
    Check(m, FlagOf(m), checks);
    if (checks.Error() != DecodeError::kNone) {
      return;
    }
    unrepresentable = Unrepresentable(m);
    if (unrepresentable == Field::kNone) {
      M scratch{};
      Fields(writer, OnTheWire(m, scratch));
    }
  }
};

}  // namespace

std::size_t PayloadSize(MessageType t, std::size_t n) noexcept {
  const Layout l = LayoutOf(t);
  return l.fixed + l.entry * n;
}

// @implements REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-003 REQ-LC-004 REQ-LC-007 REQ-LC-010
Decoded Decode(std::span<const std::uint8_t> payload) noexcept {
  if (payload.empty()) {
    return Failure(DecodeError::kEmpty);
  }
  const auto type = static_cast<MessageType>(payload[0]);
  const Layout l = LayoutOf(type);
  if (l.fixed == 0) {
    return Failure(DecodeError::kUnknownType);
  }
  if (payload.size() < l.fixed) {
    return Failure(DecodeError::kWrongLength);
  }
  std::size_t n = 0;
  if (l.entry != 0) {
    n = payload[l.count_at];
    if (n > l.max_entries) {
      return Failure(DecodeError::kTooManyEntries, l.count_field);
    }
  }
  if (payload.size() != l.fixed + l.entry * n) {
    return Failure(DecodeError::kWrongLength);
  }
  Reader in(payload.subspan(1));
  Checks checks;
  Message m = kReaders[static_cast<std::size_t>(type)](in, checks);  // 1 .. 9: LayoutOf knows it
  if (checks.Error() != DecodeError::kNone) {
    return Failure(checks.Error(), checks.GetField());
  }
  Decoded d;
  d.message = m;
  return d;
}

// @implements REQ-MB-001 REQ-MB-024 REQ-LC-002 REQ-LC-003 REQ-LC-004 REQ-LC-007 REQ-LC-010
Encoded Encode(const Message& message) noexcept {
  Encoded e;
  if (std::holds_alternative<std::monostate>(message)) {
    e.error = EncodeError::kNoMessage;
    return e;
  }
  Writer w(e.payload);
  w.U8(static_cast<std::uint8_t>(TypeOf(message)));
  Checks checks;
  Writing writing{checks, w};
  std::visit(writing, message);
  if (checks.Error() != DecodeError::kNone || writing.unrepresentable != Field::kNone) {
    e.error = checks.Error() != DecodeError::kNone ? EncodeError::kInvalidMessage : EncodeError::kNotRepresentable;
    e.invalid = checks.Error();
    e.field = checks.Error() != DecodeError::kNone ? checks.GetField() : writing.unrepresentable;
    e.payload = Payload{};
  }
  return e;
}

namespace {

// A bundle's own bytes: the type byte and the count; each entry adds its size byte.
constexpr std::size_t kBundleHeaderBytes = 2;
constexpr std::size_t kBundleEntryHeaderBytes = 1;
static_assert(kBundleMax <= 255 && kPayloadCapacity <= 255, "counts and entry sizes fit one byte");

DecodedBundle BundleFailure(DecodeError e, Field f, std::size_t entry) noexcept {
  DecodedBundle d;
  d.error = e;
  d.field = f;
  d.entry = entry;
  return d;
}

}  // namespace

std::size_t EncodedSize(const Message& m) noexcept { return Encode(m).payload.size; }

std::size_t BundleSize(std::span<const Message> messages) noexcept {
  if (messages.size() == 1) {
    return EncodedSize(messages[0]);
  }
  std::size_t total = kBundleHeaderBytes;
  for (const Message& m : messages) {
    const std::size_t n = EncodedSize(m);
    if (n == 0) {
      return 0;
    }
    total += kBundleEntryHeaderBytes + n;
  }
  return messages.empty() ? 0 : total;
}

bool AddIfFits(Bundle& bundle, const Message& m) noexcept {
  if (!bundle.Add(m)) {
    return false;
  }
  const std::size_t size = BundleSize(bundle.View());
  if (size == 0 || size > kPayloadCapacity) {
    --bundle.size;
    return false;
  }
  return true;
}

DecodedBundle DecodeBundle(std::span<const std::uint8_t> payload) noexcept {
  if (payload.empty() || payload[0] != kBundleType) {
    const Decoded one = Decode(payload);
    if (!one.Ok()) {
      return BundleFailure(one.error, one.field, 0);
    }
    DecodedBundle d;
    static_cast<void>(d.bundle.Add(one.message));  // an empty bundle has room
    return d;
  }
  if (payload.size() < kBundleHeaderBytes || payload.size() > kPayloadCapacity) {
    return BundleFailure(DecodeError::kWrongLength, Field::kNone, 0);  // no telegram carries more
  }
  const std::size_t n = payload[1];
  if (n < 2 || n > kBundleMax) {
    return BundleFailure(DecodeError::kTooManyEntries, Field::kBundleCount, 0);
  }
  DecodedBundle d;
  std::size_t at = kBundleHeaderBytes;
  for (std::size_t i = 0; i < n; ++i) {
    if (at >= payload.size() || payload.size() - at - kBundleEntryHeaderBytes < payload[at]) {
      return BundleFailure(DecodeError::kWrongLength, Field::kNone, i);
    }
    const std::size_t size = payload[at];
    const Decoded one = Decode(payload.subspan(at + kBundleEntryHeaderBytes, size));
    if (!one.Ok()) {
      return BundleFailure(one.error, one.field, i);
    }
    static_cast<void>(d.bundle.Add(one.message));  // i < n <= kBundleMax
    at += kBundleEntryHeaderBytes + size;
  }
  if (at != payload.size()) {
    return BundleFailure(DecodeError::kWrongLength, Field::kNone, n - 1);
  }
  return d;
}

Encoded EncodeBundle(std::span<const Message> messages) noexcept {
  if (messages.size() == 1) {
    return Encode(messages[0]);
  }
  Encoded out;
  if (messages.empty()) {
    out.error = EncodeError::kNoMessage;
    return out;
  }
  if (messages.size() > kBundleMax) {
    out.error = EncodeError::kTooLarge;
    return out;
  }
  Payload& p = out.payload;
  p.bytes[0] = kBundleType;
  p.bytes[1] = static_cast<std::uint8_t>(messages.size());
  p.size = kBundleHeaderBytes;
  for (const Message& m : messages) {
    Encoded one = Encode(m);
    if (!one.Ok()) {
      one.payload = Payload{};
      return one;
    }
    if (p.size + kBundleEntryHeaderBytes + one.payload.size > p.bytes.size()) {
      out.payload = Payload{};
      out.error = EncodeError::kTooLarge;
      return out;
    }
    p.bytes[p.size] = static_cast<std::uint8_t>(one.payload.size);
    std::copy_n(one.payload.bytes.begin(), one.payload.size, p.bytes.begin() + static_cast<std::ptrdiff_t>(p.size) + 1);
    p.size += kBundleEntryHeaderBytes + one.payload.size;
  }
  return out;
}

}  // namespace railproof::messages
