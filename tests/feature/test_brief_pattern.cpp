#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>
#include <tuple>
#include <vector>

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

namespace pspslam {
namespace {

// Packs one bit per sample (bit = value(sample)) into 64-bit words.
template <typename BitFunction>
std::vector<std::uint64_t> pack_bits(int n_samples, BitFunction value) {
  std::vector<std::uint64_t> words((n_samples + 63) / 64, 0);
  for (int sample = 0; sample < n_samples; ++sample) {
    if (value(sample)) words[sample / 64] |= std::uint64_t{1} << (sample % 64);
  }
  return words;
}

TEST(SelectDecorrelatedPairs, PrefersBalancedAndSkipsDuplicatesAndBiasedTests) {
  constexpr int kSamples = 4096;
  std::mt19937 engine(5);
  std::vector<std::vector<std::uint64_t>> outcomes;
  std::vector<int> random_bits(kSamples);
  for (int& bit : random_bits) bit = static_cast<int>(engine() & 1);
  // 0: balanced random; 1: exact copy of 0; 2: inverse of 0 (correlation -1); 3: 90% ones;
  // 4: another balanced independent test; 5: constant.
  outcomes.push_back(pack_bits(kSamples, [&](int s) { return random_bits[s] != 0; }));
  outcomes.push_back(outcomes[0]);
  outcomes.push_back(pack_bits(kSamples, [&](int s) { return random_bits[s] == 0; }));
  outcomes.push_back(pack_bits(kSamples, [](int s) { return s % 10 != 0; }));
  std::mt19937 other(11);
  outcomes.push_back(pack_bits(kSamples, [&](int) { return (other() & 1) != 0; }));
  outcomes.push_back(pack_bits(kSamples, [](int) { return true; }));

  const std::vector<int> two = select_decorrelated_pairs(outcomes, kSamples, 2);
  ASSERT_EQ(two.size(), 2u);
  // One of the three copies of the same test, plus the independent one.
  EXPECT_TRUE(two[0] == 0 || two[0] == 1 || two[0] == 2) << two[0];
  EXPECT_EQ(two[1], 4);
  // Asking for more than the balanced, independent ones forces the biased and duplicate tests in
  // (never before them).
  const std::vector<int> four = select_decorrelated_pairs(outcomes, kSamples, 4);
  ASSERT_EQ(four.size(), 4u);
  EXPECT_EQ(four[0], two[0]);
  EXPECT_EQ(four[1], two[1]);
}

TEST(BriefPattern, LearnedPatternIsValid) {
  const BriefPattern pattern = make_learned_brief_pattern();
  std::set<std::tuple<float, float, float, float>> pairs;
  for (const BriefPair& pair : pattern) {
    EXPECT_LE(std::hypot(pair.first_x, pair.first_y), kBriefPatternRadius);
    EXPECT_LE(std::hypot(pair.second_x, pair.second_y), kBriefPatternRadius);
    EXPECT_FALSE(pair.first_x == pair.second_x && pair.first_y == pair.second_y);
    EXPECT_TRUE(pairs.emplace(pair.first_x, pair.first_y, pair.second_x, pair.second_y).second);
  }
  EXPECT_EQ(make_brief_candidates().size(),
            static_cast<std::size_t>(kBriefCandidateChunks) * kBriefPairs);
}

}  // namespace
}  // namespace pspslam
