// The slice views' colour range (editor/legend_range.h): fitted to the values shown, held
// through a stroke so unpainted voxels keep their colours, refitted when it ends.
#include "editor/legend_range.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sslpv {
namespace {

TEST(LegendRange, HeldThroughAStrokeThenRefittedOnRelease) {
  LegendRange range;
  EXPECT_EQ(range.fit("sigma_t", 1.0, 2.0), std::make_pair(1.0, 2.0)) << "fitted while not held";
  range.hold(true);
  // Dabs push the values beyond the range: it stays where the stroke found it.
  EXPECT_EQ(range.fit("sigma_t", 1.0, 3.0), std::make_pair(1.0, 2.0));
  EXPECT_EQ(range.fit("sigma_t", 0.5, 4.0), std::make_pair(1.0, 2.0));
  // Another channel's values mean nothing on the held scale.
  EXPECT_EQ(range.fit("g", -0.2, 0.6), std::make_pair(-0.2, 0.6));
  EXPECT_EQ(range.fit("g", -0.9, 0.9), std::make_pair(-0.2, 0.6));
  range.hold(false);
  EXPECT_EQ(range.fit("g", -0.9, 0.9), std::make_pair(-0.9, 0.9)) << "released: refitted once";
}

TEST(LegendRange, AUniformSliceGetsAVisibleRange) {
  LegendRange range;
  const auto [lo, hi] = range.fit("sigma_t", 2.0, 2.0);
  EXPECT_LT(lo, 2.0);
  EXPECT_GT(hi, 2.0);
  // A held range that started uniform stays the padded one.
  range.hold(true);
  EXPECT_EQ(range.fit("sigma_t", 2.0, 3.0), std::make_pair(lo, hi));
}

TEST(LegendRange, LockedRangeIgnoresValuesChannelsAndHoldsUntilUnlocked) {
  LegendRange range;
  range.fit("sigma_t", 1.0, 2.0);
  EXPECT_FALSE(range.lock(2.0, 1.0)) << "an empty range is refused";
  EXPECT_FALSE(range.lock(0.0, std::nan("")));
  EXPECT_FALSE(range.locked());
  ASSERT_TRUE(range.lock(0.5, 3.0));
  EXPECT_EQ(range.fit("sigma_t", 1.0, 9.0), std::make_pair(0.5, 3.0)) << "a stroke's values do not refit it";
  EXPECT_EQ(range.fit("g", -0.2, 0.6), std::make_pair(0.5, 3.0)) << "nor another channel";
  EXPECT_EQ(range.current(), std::make_optional(std::make_pair(0.5, 3.0)));
  range.unlock();
  EXPECT_EQ(range.fit("sigma_t", 1.0, 9.0), std::make_pair(1.0, 9.0)) << "unlocked: fitted again";
}

}  // namespace
}  // namespace sslpv
