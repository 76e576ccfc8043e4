#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "pspslam/feature/brief_pattern.h"

namespace pspslam {
namespace {

TEST(BriefPattern, DeterministicForASeedAndDifferentAcrossSeeds) {
  const BriefPattern first = make_brief_pattern();
  const BriefPattern again = make_brief_pattern();
  const BriefPattern other = make_brief_pattern(kDefaultBriefSeed + 1);
  int differing_pairs = 0;
  for (int i = 0; i < kBriefPairs; ++i) {
    EXPECT_EQ(first[i].first_x, again[i].first_x);
    EXPECT_EQ(first[i].first_y, again[i].first_y);
    EXPECT_EQ(first[i].second_x, again[i].second_x);
    EXPECT_EQ(first[i].second_y, again[i].second_y);
    differing_pairs +=
        first[i].first_x != other[i].first_x || first[i].second_y != other[i].second_y;
  }
  EXPECT_GT(differing_pairs, 200);
}

TEST(BriefPattern, PointsInsidePatchDistinctAndGaussianSpread) {
  const BriefPattern pattern = make_brief_pattern();
  std::set<std::tuple<float, float, float, float>> pairs;
  double sum_squares = 0.0;
  for (const BriefPair& pair : pattern) {
    EXPECT_LE(std::hypot(pair.first_x, pair.first_y), kBriefPatternRadius);
    EXPECT_LE(std::hypot(pair.second_x, pair.second_y), kBriefPatternRadius);
    EXPECT_FALSE(pair.first_x == pair.second_x && pair.first_y == pair.second_y);
    EXPECT_EQ(pair.first_x, std::round(pair.first_x));
    EXPECT_TRUE(pairs.emplace(pair.first_x, pair.first_y, pair.second_x, pair.second_y).second);
    EXPECT_EQ(pairs.count({pair.second_x, pair.second_y, pair.first_x, pair.first_y}), 0u);
    sum_squares += pair.first_x * pair.first_x + pair.second_x * pair.second_x;
  }
  // G II: per-axis sigma 31/5 = 6.2 before truncation to the radius-15 disc (which trims it a
  // little): the sample standard deviation of x must be close to that.
  const double sigma_x = std::sqrt(sum_squares / (2.0 * kBriefPairs));
  EXPECT_GT(sigma_x, 5.0);
  EXPECT_LT(sigma_x, 6.6);
}

}  // namespace
}  // namespace pspslam
