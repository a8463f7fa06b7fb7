// Test line and helpers shared by the wayside unit tests (not a test file itself).
//
// The default test line: 2 km, 40 virtual blocks of 50 m, distinct margins per obstruction
// kind (so a test can tell which margin was applied), times from the parameters
// (tracking timeout 3000 ms, validity 3000 ms, cycle 500 ms, set-back 3000 mm).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "line_data.hpp"
#include "railproof/mb/wayside/ground.hpp"

namespace railproof::mb::wayside::test {

inline constexpr std::int64_t kLen = 2'000'000;
inline constexpr std::int64_t kBlock = 50'000;
inline constexpr std::int64_t kTrainLen = 100'000;
inline constexpr Margins kMargins{20'000, 21'000, 30'000, 22'000, 23'000, 50'000, 40'000, 10'000};
inline constexpr std::int64_t kEot = kLen - 10'000;  // END_OF_TRACK limit

struct TestLine : LineData {
  TestLine() {
    base.length_mm = kLen;
    base.margins = kMargins;
    for (std::int64_t x = 0; x <= kLen; x += kBlock) {
      blocks.push_back(x);
    }
  }

  // Points P10 on block 20 [1.0 km, 1.05 km); automatic main route 1 (normal) and
  // requested siding route 2 (reverse), both [1.0 km, 1.1 km).
  TestLine& WithJunction() {
    points.push_back(PointsConfig{10, Section{1'000'000, 1'050'000}});
    routes.push_back(RouteConfig{1, 1'000'000, 1'100'000, 0, false, true});
    routes.push_back(RouteConfig{2, 1'000'000, 1'100'000, 0, true, false});
    return *this;
  }
};

inline Capacity SmallCapacity() {
  Capacity c = DefaultCapacity();
  c.trains = 16;
  c.blocks = 64;
  c.routes = 8;
  c.points = 8;
  c.sections = 8;
  c.handovers = 8;
  c.possessions = 4;
  c.restrictions = 12;
  c.unequipped = 4;
  return c;
}

inline std::unique_ptr<Ground> MakeGround(const TestLine& line, const Capacity& cap = SmallCapacity()) {
  auto created = Ground::Create(line.Config(), cap);
  EXPECT_EQ(created.error, ConfigError::kNone) << ToString(created.error) << " entry " << created.entry;
  return std::move(created.ground);
}

inline RegisterStatus Register(Ground& g, std::uint32_t id, std::int64_t front, std::int64_t corr = 0,
                               InitialPosition initial = InitialPosition::kEntryBalise,
                               std::int64_t length = kTrainLen) {
  return g.RegisterTrain(TrainRegistration{id, length, front, corr, initial});
}

// A ground over `line` with the trains (id, front) registered at their entry balise, in order.
inline std::unique_ptr<Ground> MakeGround(const TestLine& line,
                                          std::initializer_list<std::pair<std::uint32_t, std::int64_t>> trains) {
  auto g = MakeGround(line);
  for (const auto& [id, front] : trains) {
    EXPECT_EQ(Register(*g, id, front), RegisterStatus::kRegistered) << "train " << id;
  }
  return g;
}

inline PositionReport MakeReport(const Ground& g, std::uint32_t id, std::int64_t front, std::int64_t corr = 0,
                                 std::int64_t length = kTrainLen) {
  const auto pos = g.LocateFront(front);
  EXPECT_TRUE(pos.has_value()) << "front " << front;
  const BlockPosition p = pos.value_or(BlockPosition{0, 0});
  return PositionReport{id, p.block, p.offset_mm, length, corr, 0, 0, Direction::kNominal};
}

inline ReportStatus Report(Ground& g, std::uint32_t id, std::int64_t front, std::int64_t corr = 0) {
  return g.OnReport(MakeReport(g, id, front, corr));
}

inline std::optional<std::int64_t> LimitOf(const Ground& g, std::uint32_t id) {
  const auto t = g.Train(id);
  return t.has_value() ? t->limit_mm : std::nullopt;
}

inline Obstruction KindOf(const Ground& g, std::uint32_t id) {
  const auto t = g.Train(id);
  return t.has_value() ? t->kind : Obstruction::kNone;
}

// A train's stop limit and what limits it, compared and printed together.
struct LimitAndKind {
  std::optional<std::int64_t> limit_mm;
  Obstruction kind = Obstruction::kNone;
  bool operator==(const LimitAndKind&) const = default;
};

inline void PrintTo(const LimitAndKind& l, std::ostream* os) {
  *os << (l.limit_mm ? std::to_string(*l.limit_mm) : std::string("no limit")) << " (" << ToString(l.kind) << ")";
}

inline LimitAndKind LimitAndKindOf(const Ground& g, std::uint32_t id) { return {LimitOf(g, id), KindOf(g, id)}; }

inline bool AbnormalOf(const Ground& g, std::uint32_t id) {
  const auto t = g.Train(id);
  return t.has_value() && t->abnormal;
}

}  // namespace railproof::mb::wayside::test
