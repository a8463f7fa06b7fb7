// The merged permitted-speed profile of the on-board unit (onboard_profile.hpp): the line's
// static limits and the held temporary restrictions as sorted, non-overlapping minimum pieces.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "railproof/units/onboard_profile.hpp"

namespace railproof::units {
namespace {

using Seg = core::RestrictionSegment;

std::vector<Seg> Merge(const std::vector<Seg>& line, const std::vector<messages::SpeedRestriction>& held) {
  std::vector<Seg> out(MergeCapacity(line.size(), held.size()));
  std::vector<std::int64_t> scratch(out.size());
  const MergeResult r = MergeRestrictions(line, held, out, scratch);
  EXPECT_TRUE(r.ok);
  out.resize(r.count);
  return out;
}

bool Same(const std::vector<Seg>& a, const std::vector<Seg>& b) {
  if (a.size() != b.size()) {
    return false;
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].begin_mm != b[i].begin_mm || a[i].end_mm != b[i].end_mm || a[i].limit_mm_s != b[i].limit_mm_s) {
      return false;
    }
  }
  return true;
}

TEST(OnboardProfile, TheLowerLimitGovernsEveryPiece) {
  const std::vector<Seg> line{{0, 1'000, 30'000}, {1'000, 3'000, 20'000}, {4'000, 6'000, 25'000}};
  // overlapping restrictions, out of order, one above the line limit, one across a gap
  const std::vector<messages::SpeedRestriction> held{
      {2, 2'500, 4'500, 10'000}, {1, 500, 1'500, 15'000}, {3, 800, 1'200, 5'000}, {4, 5'000, 5'500, 40'000}};
  const std::vector<Seg> want{{0, 500, 30'000},         {500, 800, 15'000},     {800, 1'000, 5'000},
                              {1'000, 1'200, 5'000},    {1'200, 1'500, 15'000}, {1'500, 2'500, 20'000},
                              {2'500, 3'000, 10'000},   {3'000, 4'000, 10'000}, {4'000, 4'500, 10'000},
                              {4'500, 5'000, 25'000},   {5'000, 5'500, 25'000}, {5'500, 6'000, 25'000}};
  EXPECT_TRUE(Same(Merge(line, held), want));
}

TEST(OnboardProfile, WithoutRestrictionsTheLineLimitsStay) {
  const std::vector<Seg> line{{0, 1'000, 30'000}, {2'000, 3'000, 20'000}};
  EXPECT_TRUE(Same(Merge(line, {}), line));
  EXPECT_TRUE(Merge({}, {}).empty());
  EXPECT_TRUE(Same(Merge({}, {{9, 10, 20, 1'000}}), {{10, 20, 1'000}}));
}

TEST(OnboardProfile, RefusesStorageBelowTheCapacity) {
  const std::vector<Seg> line{{0, 1'000, 30'000}};
  const std::vector<messages::SpeedRestriction> held{{1, 500, 1'500, 15'000}};
  std::array<Seg, 3> out{};
  std::array<std::int64_t, 4> scratch{};
  EXPECT_FALSE(MergeRestrictions(line, held, out, scratch).ok);
  std::array<Seg, 4> enough{};
  std::array<std::int64_t, 3> short_scratch{};
  EXPECT_FALSE(MergeRestrictions(line, held, enough, short_scratch).ok);
}

}  // namespace
}  // namespace railproof::units
