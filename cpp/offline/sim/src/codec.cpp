#include "railproof/sim/codec.hpp"

#include <algorithm>

#include "railproof/tg/telegram.hpp"

namespace railproof::sim {

namespace {

class Writer {
 public:
  void U8(std::uint8_t v) { out_.push_back(v); }
  void U32(std::uint32_t v) {
    for (int s = 24; s >= 0; s -= 8) {
      out_.push_back(static_cast<std::uint8_t>(v >> static_cast<unsigned>(s)));
    }
  }
  void I64(std::int64_t v) {
    const auto u = static_cast<std::uint64_t>(v);
    for (int s = 56; s >= 0; s -= 8) {
      out_.push_back(static_cast<std::uint8_t>(u >> static_cast<unsigned>(s)));
    }
  }
  std::vector<std::uint8_t> Take() { return std::move(out_); }

 private:
  std::vector<std::uint8_t> out_;
};

class Reader {
 public:
  explicit Reader(std::span<const std::uint8_t> in) : in_(in) {}
  bool U8(std::uint8_t& v) {
    if (pos_ + 1 > in_.size()) {
      return false;
    }
    v = in_[pos_++];
    return true;
  }
  bool U32(std::uint32_t& v) {
    if (pos_ + 4 > in_.size()) {
      return false;
    }
    v = 0;
    for (int k = 0; k < 4; ++k) {
      v = (v << 8U) | in_[pos_++];
    }
    return true;
  }
  bool I64(std::int64_t& v) {
    if (pos_ + 8 > in_.size()) {
      return false;
    }
    std::uint64_t u = 0;
    for (int k = 0; k < 8; ++k) {
      u = (u << 8U) | in_[pos_++];
    }
    v = static_cast<std::int64_t>(u);
    return true;
  }
  [[nodiscard]] bool AtEnd() const { return pos_ == in_.size(); }

 private:
  std::span<const std::uint8_t> in_;
  std::size_t pos_ = 0;
};

// What a payload holds: its first byte is 1 before a message; the single byte 0 is the
// empty payload (no position, keep-alive); anything else is malformed.
enum class Content : std::uint8_t { kMessage, kEmpty, kMalformed };

Content Open(Reader& r) {
  std::uint8_t kind = 0;
  if (!r.U8(kind)) {
    return Content::kMalformed;
  }
  if (kind == 0 && r.AtEnd()) {
    return Content::kEmpty;
  }
  return kind == 1 ? Content::kMessage : Content::kMalformed;
}

// The message of a payload, read by `read(reader, message)` after the first byte: none for
// the empty payload, none and `malformed` if it is malformed (read fails, or bytes are left).
template <typename Message, typename Read>
std::optional<Message> Decode(std::span<const std::uint8_t> payload, bool& malformed, const Read& read) {
  Reader r(payload);
  const Content c = Open(r);
  malformed = c == Content::kMalformed;
  if (c != Content::kMessage) {
    return std::nullopt;
  }
  Message m{};
  if (!read(r, m) || !r.AtEnd()) {
    malformed = true;
    return std::nullopt;
  }
  return m;
}

}  // namespace

std::vector<std::uint8_t> EncodePosition(const messages::PositionReport& r) {
  Writer w;
  w.U8(1);
  w.U32(r.train_id);
  w.U32(r.front_block);
  w.I64(r.offset_mm);
  w.I64(r.length_mm);
  w.I64(r.correction_mm);
  w.I64(r.last_balise_mm);
  w.I64(r.speed_mm_s);
  w.U8(r.direction == mb::wayside::Direction::kNominal ? 0 : 1);
  return w.Take();
}

std::vector<std::uint8_t> EncodeNoPosition() { return {0}; }

std::optional<messages::PositionReport> DecodePosition(std::span<const std::uint8_t> payload, bool& malformed) {
  return Decode<messages::PositionReport>(payload, malformed, [](Reader& r, messages::PositionReport& rep) {
    std::uint8_t dir = 0;
    if (!r.U32(rep.train_id) || !r.U32(rep.front_block) || !r.I64(rep.offset_mm) || !r.I64(rep.length_mm) ||
        !r.I64(rep.correction_mm) || !r.I64(rep.last_balise_mm) || !r.I64(rep.speed_mm_s) || !r.U8(dir) || dir > 1) {
      return false;
    }
    rep.direction = dir == 0 ? mb::wayside::Direction::kNominal : mb::wayside::Direction::kReverse;
    return true;
  });
}

std::vector<std::uint8_t> EncodeStopLimit(const messages::StopLimitTelegram& t) {
  Writer w;
  w.U8(1);
  w.U32(t.train_id);
  w.I64(t.limit_mm);
  w.U8(static_cast<std::uint8_t>(t.kind));
  w.I64(t.issue_time_ms);
  const std::size_t n = std::min<std::size_t>({t.restriction_count, kControlRestrictionsMax, t.restrictions.size()});
  w.U8(static_cast<std::uint8_t>(n));
  w.U8(t.restrictions_truncated || n < t.restriction_count ? 1 : 0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& r = t.restrictions[i];
    w.U32(r.id);
    w.U32(static_cast<std::uint32_t>(static_cast<std::int32_t>(r.begin_mm)));
    w.U32(static_cast<std::uint32_t>(static_cast<std::int32_t>(r.end_mm)));
    w.U32(static_cast<std::uint32_t>(r.speed_mm_s));
  }
  auto out = w.Take();
  static_assert(24 + 16 * kControlRestrictionsMax <= tg::kPayloadMax, "stop-limit payload must fit a telegram");
  return out;
}

std::vector<std::uint8_t> EncodeKeepAlive() { return {0}; }

std::optional<messages::StopLimitTelegram> DecodeStopLimit(std::span<const std::uint8_t> payload, bool& malformed) {
  return Decode<messages::StopLimitTelegram>(payload, malformed, [](Reader& r, messages::StopLimitTelegram& t) {
    std::uint8_t obstruction = 0;
    std::uint8_t n = 0;
    std::uint8_t truncated = 0;
    if (!r.U32(t.train_id) || !r.I64(t.limit_mm) || !r.U8(obstruction) || !r.I64(t.issue_time_ms) || !r.U8(n) ||
        !r.U8(truncated) || n > kControlRestrictionsMax || obstruction > 8 || truncated > 1) {
      return false;
    }
    t.kind = static_cast<messages::Obstruction>(obstruction);
    t.restriction_count = n;
    t.restrictions_truncated = truncated != 0;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t id = 0;
      std::uint32_t b = 0;
      std::uint32_t e = 0;
      std::uint32_t s = 0;
      if (!r.U32(id) || !r.U32(b) || !r.U32(e) || !r.U32(s)) {
        return false;
      }
      t.restrictions[i] = messages::SpeedRestriction{id, static_cast<std::int32_t>(b), static_cast<std::int32_t>(e), s};
    }
    return true;
  });
}

}  // namespace railproof::sim
