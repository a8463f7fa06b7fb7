// Unit tests of the on-board stop-limit reception (spec/design/mb.md §4), set-back
// supervision and speed-restriction store, at millisecond / millimetre resolution.
//
// Kills the seeded faults FAULT_MB_ACCEPT_NOT_NEWER and FAULT_MB_VALIDITY_FROM_RECEPTION
// (the unit_fault_<F> ctest entries run these tests against the schemata variant).
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <vector>

#include "railproof/testing/alloc_counter.hpp"
#include "railproof/generated/mb_params.hpp"
#include "railproof/mb/onboard/authority.hpp"

namespace railproof::mb::onboard {
namespace {

constexpr AuthorityConfig kConfig{3000, 3000};

// @verifies REQ-MB-009
TEST(OnboardAuthority, DefaultsComeFromTheParameters) {
  const AuthorityConfig c = DefaultAuthorityConfig();
  EXPECT_EQ(c.validity_ms, params::mb::authority_validity_ms);
  EXPECT_EQ(c.max_age_ms, params::mb::authority_max_age_ms);
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, NoAuthorityBeforeTheFirstTelegram) {
  const AuthorityReceiver rx(kConfig);
  EXPECT_TRUE(rx.Valid());
  EXPECT_FALSE(rx.Limit().has_value());
  EXPECT_FALSE(rx.IssueTime().has_value());
  EXPECT_FALSE(rx.Usable(0));
  EXPECT_TRUE(rx.StandstillDemanded(0));
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, ValidityCountedFromIssueNotReception) {
  AuthorityReceiver rx(kConfig);
  ASSERT_EQ(rx.Receive(1'000'000, 1000, 2000), Verdict::kAccept);  // age 1000
  EXPECT_EQ(rx.Limit(), 1'000'000);
  EXPECT_EQ(rx.IssueTime(), 1000);
  EXPECT_TRUE(rx.Usable(2000));
  EXPECT_TRUE(rx.Usable(4000));   // 4000 - 1000 == validity
  EXPECT_FALSE(rx.Usable(4001));  // not 5000 (reception + validity)
  EXPECT_TRUE(rx.StandstillDemanded(4001));
  EXPECT_EQ(rx.Limit(), 1'000'000);  // kept for display, but no authority
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, MaximumAgeIsInclusive) {
  AuthorityReceiver rx(kConfig);
  EXPECT_EQ(rx.Receive(500'000, 2000, 5001), Verdict::kTooOld);  // age 3001
  EXPECT_FALSE(rx.Limit().has_value());
  EXPECT_EQ(rx.Receive(500'000, 2000, 5000), Verdict::kAccept);  // age 3000
  EXPECT_TRUE(rx.Usable(5000));
  EXPECT_FALSE(rx.Usable(5001));
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, OnlyANewerTelegramSupersedesAUsableAuthority) {
  AuthorityReceiver rx(kConfig);
  ASSERT_EQ(rx.Receive(1'000'000, 1000, 1100), Verdict::kAccept);
  // the same issue time (a repeated or duplicated telegram) with a longer limit
  EXPECT_EQ(rx.Receive(2'000'000, 1000, 1600), Verdict::kNotNewer);
  // an older, delayed telegram with a longer limit never extends the authority
  EXPECT_EQ(rx.Receive(2'000'000, 500, 1600), Verdict::kNotNewer);
  EXPECT_EQ(rx.Limit(), 1'000'000);
  EXPECT_EQ(rx.IssueTime(), 1000);
  // a newer one is taken even if shorter: the ground's newest decision wins
  EXPECT_EQ(rx.Receive(400'000, 1500, 1600), Verdict::kAccept);
  EXPECT_EQ(rx.Limit(), 400'000);
  EXPECT_EQ(rx.Receive(1'000'000, 1000, 1700), Verdict::kNotNewer);
  EXPECT_EQ(rx.Limit(), 400'000);
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, AnyFreshTelegramIsTakenOnceTheAuthorityIsUnusable) {
  AuthorityReceiver rx(AuthorityConfig{3000, 5000});
  ASSERT_EQ(rx.Receive(1'000'000, 1000, 1000), Verdict::kAccept);
  ASSERT_FALSE(rx.Usable(4500));
  // older than the current one but within the maximum age: the current one is unusable
  EXPECT_EQ(rx.Receive(700'000, 800, 4500), Verdict::kAccept);
  EXPECT_EQ(rx.Limit(), 700'000);
  EXPECT_FALSE(rx.Usable(4500));  // 4500 - 800 > validity: still standstill
}

// @verifies REQ-MB-009
TEST(OnboardAuthority, RefusesFutureIssueAndInvalidConfig) {
  AuthorityReceiver rx(kConfig);
  EXPECT_EQ(rx.Receive(1'000'000, 2001, 2000), Verdict::kFutureIssue);
  EXPECT_FALSE(rx.Limit().has_value());
  AuthorityReceiver bad(AuthorityConfig{0, 3000});
  EXPECT_FALSE(bad.Valid());
  EXPECT_EQ(bad.Receive(1'000'000, 1000, 1000), Verdict::kTooOld);
  EXPECT_FALSE(bad.Usable(1000));
}

// @verifies REQ-MB-009
// @verifies REQ-MB-021
TEST(OnboardAuthority, NoAllocation) {
  railproof::testing::StartCountingAllocations();
  AuthorityReceiver rx(kConfig);
  SetBackSupervisor sb;
  const std::array<Section, 1> sections{{{500'000, 600'000}}};
  (void)sb.Init(sections, 3000, 550'000);
  SpeedRestrictionStore store;
  const std::array<SpeedRestriction, 1> received{{{1, 600'000, 700'000, 8'333}}};
  for (std::int64_t now = 0; now < 10'000; now += 500) {
    (void)rx.Receive(now * 10, now, now + 100);
    (void)rx.Usable(now + 200);
    (void)sb.Update(550'000 + now);
    (void)store.Update(received, 550'000 + now, 100'000);
    (void)store.ApplicableSpeed(550'000 + now, 100'000);
  }
  EXPECT_EQ(railproof::testing::StopCountingAllocations(), 0U);
}

// ---- set-back (REQ-MB-005) ---------------------------------------------------------------

// @verifies REQ-MB-005
TEST(OnboardSetBack, OnlyInsideASectionAndBoundedByTheFurthestFront) {
  SetBackSupervisor sb;
  const std::array<Section, 2> sections{{{500'000, 600'000}, {900'000, 950'000}}};
  ASSERT_EQ(sb.Init(sections, 3000, 550'000), SetBackConfigError::kNone);
  EXPECT_EQ(sb.SetBackLimit(), 547'000);
  EXPECT_EQ(sb.Update(549'000), SetBackVerdict::kOk);
  EXPECT_EQ(sb.Update(546'000), SetBackVerdict::kTooFar);
  EXPECT_EQ(sb.Front(), 549'000);  // refused: no change
  EXPECT_EQ(sb.Update(547'000), SetBackVerdict::kOk);
  EXPECT_EQ(sb.Update(548'000), SetBackVerdict::kOk);
  EXPECT_EQ(sb.Update(546'999), SetBackVerdict::kTooFar);  // no adding up
  EXPECT_EQ(sb.FurthestFront(), 550'000);
  EXPECT_EQ(sb.Update(700'000), SetBackVerdict::kOk);
  EXPECT_EQ(sb.Update(699'999), SetBackVerdict::kOutsideSection);
  EXPECT_EQ(sb.SetBackLimit(), 700'000);
  // front == section end is inside; a furthest front beyond the end is not
  ASSERT_EQ(sb.Init(sections, 3000, 950'000), SetBackConfigError::kNone);
  EXPECT_EQ(sb.Update(949'000), SetBackVerdict::kOk);
  ASSERT_EQ(sb.Init(sections, 3000, 950'001), SetBackConfigError::kNone);
  EXPECT_EQ(sb.Update(950'000), SetBackVerdict::kOutsideSection);
  // front == section begin is outside; the limit keeps the front inside
  ASSERT_EQ(sb.Init(sections, 3000, 502'000), SetBackConfigError::kNone);
  EXPECT_EQ(sb.SetBackLimit(), 500'001);
  EXPECT_EQ(sb.Update(500'000), SetBackVerdict::kOutsideSection);
  EXPECT_EQ(sb.Update(500'001), SetBackVerdict::kOk);
}

// @verifies REQ-MB-005
TEST(OnboardSetBack, RejectsBadConfiguration) {
  SetBackSupervisor sb;
  const std::array<Section, 2> overlapping{{{500'000, 600'000}, {599'999, 700'000}}};
  EXPECT_EQ(sb.Init(overlapping, 3000, 0), SetBackConfigError::kSectionInvalid);
  const std::array<Section, 1> empty{{{500'000, 500'000}}};
  EXPECT_EQ(sb.Init(empty, 3000, 0), SetBackConfigError::kSectionInvalid);
  const std::array<Section, 1> one{{{500'000, 600'000}}};
  EXPECT_EQ(sb.Init(one, -1, 0), SetBackConfigError::kSetBackMaxInvalid);
  std::vector<Section> many;
  for (std::int64_t i = 0; i <= static_cast<std::int64_t>(kSetBackSectionsMax); ++i) {
    many.push_back(Section{i * 10, i * 10 + 5});
  }
  EXPECT_EQ(sb.Init(many, 3000, 0), SetBackConfigError::kTooManySections);
  // a refused configuration allows no set-back at all
  EXPECT_EQ(sb.Update(-1), SetBackVerdict::kOutsideSection);
}

// ---- speed restrictions (REQ-MB-015) -------------------------------------------------------

// @verifies REQ-MB-015
TEST(OnboardRestrictions, AppliesFromFrontEntryUntilTheRearHasLeft) {
  SpeedRestrictionStore store;
  const std::array<SpeedRestriction, 2> received{{{2, 600'000, 700'000, 8'333}, {1, 650'000, 660'000, 5'000}}};
  ASSERT_EQ(store.Update(received, 500'000, 100'000), StoreStatus::kOk);
  ASSERT_EQ(store.Held().size(), 2U);
  EXPECT_EQ(store.Held()[0].id, 2U);  // ascending begin
  EXPECT_FALSE(store.ApplicableSpeed(600'000, 100'000).has_value());  // front == begin: not yet in
  EXPECT_EQ(store.ApplicableSpeed(600'001, 100'000), 8'333);
  EXPECT_EQ(store.ApplicableSpeed(655'000, 100'000), 5'000);           // the lowest applies
  EXPECT_EQ(store.ApplicableSpeed(799'999, 100'000), 8'333);           // rear 699999 still inside
  EXPECT_FALSE(store.ApplicableSpeed(800'000, 100'000).has_value());   // rear == end: left
  store.Advance(765'000, 100'000);  // rear 665000: the short one is left behind
  ASSERT_EQ(store.Held().size(), 1U);
  EXPECT_EQ(store.Held()[0].id, 2U);
  store.Advance(800'000, 100'000);
  EXPECT_TRUE(store.Held().empty());
}

// @verifies REQ-MB-015
TEST(OnboardRestrictions, KeptWhileUnderTheTrainWhenNoLongerSent) {
  SpeedRestrictionStore store;
  const std::array<SpeedRestriction, 1> received{{{1, 600'000, 700'000, 8'333}}};
  ASSERT_EQ(store.Update(received, 650'000, 100'000), StoreStatus::kOk);
  ASSERT_EQ(store.Update({}, 650'000, 100'000), StoreStatus::kOk);  // cancelled on the ground
  ASSERT_EQ(store.Held().size(), 1U);                               // still under the train
  EXPECT_EQ(store.ApplicableSpeed(650'000, 100'000), 8'333);
  ASSERT_EQ(store.Update({}, 800'000, 100'000), StoreStatus::kOk);
  EXPECT_TRUE(store.Held().empty());
  // a restriction not yet reached and no longer sent is dropped at once
  ASSERT_EQ(store.Update(received, 400'000, 100'000), StoreStatus::kOk);
  ASSERT_EQ(store.Update({}, 400'000, 100'000), StoreStatus::kOk);
  EXPECT_TRUE(store.Held().empty());
  // one already left is not taken
  ASSERT_EQ(store.Update(received, 900'000, 100'000), StoreStatus::kOk);
  EXPECT_TRUE(store.Held().empty());
}

// @verifies REQ-MB-015
TEST(OnboardRestrictions, TruncatesBeyondTheStoreCapacity) {
  SpeedRestrictionStore store;
  std::vector<SpeedRestriction> received;
  for (std::uint32_t i = 0; i <= kStoredRestrictionsMax; ++i) {
    const std::int64_t begin = 1'000'000 + static_cast<std::int64_t>(i) * 100'000;
    received.push_back(SpeedRestriction{i + 1, begin, begin + 50'000, 10'000});
  }
  EXPECT_EQ(store.Update(received, 500'000, 100'000), StoreStatus::kTruncated);
  EXPECT_EQ(store.Held().size(), kStoredRestrictionsMax);
  EXPECT_EQ(store.Held().back().id, kStoredRestrictionsMax);  // the furthest was dropped
}

}  // namespace
}  // namespace railproof::mb::onboard
