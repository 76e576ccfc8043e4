#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include "pspslam/io/association.h"

namespace pspslam {
namespace {

using Pairs = std::vector<std::pair<double, double>>;

Pairs associated_values(const std::vector<double>& first, const std::vector<double>& second,
                        double max_difference, double offset = 0.0) {
  Pairs pairs;
  for (const TimestampMatch& m : associate_timestamps(first, second, max_difference, offset)) {
    pairs.emplace_back(first[m.first], second[m.second]);
  }
  return pairs;
}

// associate.py written out literally (all pairs, sort tuples, greedy, sort): the reference.
Pairs reference_associate(const std::vector<double>& first, const std::vector<double>& second,
                          double max_difference, double offset) {
  std::vector<std::tuple<double, double, double>> candidates;
  for (const double a : first) {
    for (const double b : second) {
      if (std::abs(a - (b + offset)) < max_difference) {
        candidates.emplace_back(std::abs(a - (b + offset)), a, b);
      }
    }
  }
  std::sort(candidates.begin(), candidates.end());
  std::set<double> first_left(first.begin(), first.end()),
      second_left(second.begin(), second.end());
  Pairs pairs;
  for (const auto& [difference, a, b] : candidates) {
    if (first_left.count(a) && second_left.count(b)) {
      first_left.erase(a);
      second_left.erase(b);
      pairs.emplace_back(a, b);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

TEST(Association, GreedyByDifferenceNotNearestPerFrame) {
  // rgb 1.000's nearest depth is 1.010, but depth 1.010 is even closer to rgb 1.012, which takes
  // it first; rgb 1.000 then falls back to 0.985 (0.015 < 0.02). rgb 2.0 has nothing in range.
  const std::vector<double> rgb = {1.000, 1.012, 2.0};
  const std::vector<double> depth = {0.985, 1.010, 1.030};
  EXPECT_EQ(associated_values(rgb, depth, 0.02), (Pairs{{1.000, 0.985}, {1.012, 1.010}}));
}

TEST(Association, EachFrameUsedOnceAndStrictWindow) {
  // Two rgb frames compete for one depth frame: the closer wins, the other stays unmatched.
  EXPECT_EQ(associated_values({1.0, 1.004}, {1.003}, 0.02), (Pairs{{1.004, 1.003}}));
  // |a - b| must be strictly below max_difference (0.5 and 0.25 are exact in binary).
  EXPECT_TRUE(associated_values({1.0}, {1.5}, 0.5).empty());
  EXPECT_EQ(associated_values({1.0}, {1.25}, 0.5), (Pairs{{1.0, 1.25}}));
}

TEST(Association, OffsetIsAddedToSecondList) {
  EXPECT_EQ(associated_values({10.0, 11.0}, {9.0, 10.0}, 0.02, 1.0),
            (Pairs{{10.0, 9.0}, {11.0, 10.0}}));
  EXPECT_TRUE(associated_values({10.0, 11.0}, {9.0, 10.5}, 0.02, 0.0).empty());
}

TEST(Association, ResultSortedByFirstListEvenForUnsortedInput) {
  const std::vector<double> rgb = {3.0, 1.0, 2.0};
  const std::vector<double> depth = {2.005, 0.995, 3.01};
  const auto matches = associate_timestamps(rgb, depth, 0.02);
  ASSERT_EQ(matches.size(), 3u);
  EXPECT_EQ(matches[0].first, 1u);
  EXPECT_EQ(matches[0].second, 1u);
  EXPECT_EQ(matches[1].first, 2u);
  EXPECT_EQ(matches[2].first, 0u);
  EXPECT_EQ(matches[2].second, 2u);
}

TEST(Association, MatchesLiteralAssociatePyOnRandomStreams) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.012, 0.012);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<double> rgb, depth;
    for (int i = 0; i < 120; ++i) {
      rgb.push_back(100.0 + i / 30.0 + jitter(rng));
      if (i % 7 != 3) depth.push_back(100.0 + i / 30.0 + 0.01 + jitter(rng));
    }
    const double offset = trial % 2 == 0 ? 0.0 : 0.013;
    EXPECT_EQ(associated_values(rgb, depth, 0.02, offset),
              reference_associate(rgb, depth, 0.02, offset))
        << "trial " << trial;
  }
}

}  // namespace
}  // namespace pspslam
