#include <gtest/gtest.h>

#include <random>
#include <set>

#include "place_test_data.h"
#include "pspslam/place/bow_matching.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {
namespace {

// Query = random descriptors; train = the same descriptors with a few bits flipped, in reverse
// order, plus unrelated ones. Guided matching must pair them correctly and one-to-one.
TEST(BowMatching, PairsPerturbedCopiesThroughTheDirectIndex) {
  const Vocabulary vocabulary = Vocabulary::load(default_vocabulary_path());
  std::mt19937_64 rng(7);
  const int n = 400;
  const cv::Mat query = testing_place::random_descriptors(n, rng);
  cv::Mat train(n + 200, 32, CV_8UC1);
  for (int i = 0; i < n; ++i) {
    query.row(i).copyTo(train.row(n - 1 - i));
    testing_place::flip_random_bits(train.ptr<std::uint8_t>(n - 1 - i), 4, rng);
  }
  testing_place::random_descriptors(200, rng).copyTo(train.rowRange(n, n + 200));

  BowVector query_bow, train_bow;
  FeatureVector query_features, train_features;
  const int level = PlaceRecognition::kDirectIndexLevel;
  vocabulary.transform(query, query_bow, query_features, level);
  vocabulary.transform(train, train_bow, train_features, level);

  std::vector<BowMatch> matches;
  match_by_bow(query_features, query, {}, train_features, train, {}, BowMatchOptions{}, matches);
  int correct = 0;
  std::set<int> trains;
  for (const BowMatch& m : matches) {
    correct += m.train == n - 1 - m.query ? 1 : 0;
    EXPECT_TRUE(trains.insert(m.train).second) << "train " << m.train << " matched twice";
    EXPECT_LE(m.distance, 50);
  }
  // Uniformly random descriptors sit almost equidistant from the tree's centroids, so 4 flipped
  // bits move ~1/3 of them to another depth-2 node (real ORB descriptors of nearby frames keep
  // most: DirectIndex test). Unrelated random descriptors never come within 50 bits.
  EXPECT_GE(correct, 0.5 * n) << matches.size() << " matches";
  EXPECT_EQ(correct, static_cast<int>(matches.size()));

  // Unusable query descriptors are never matched.
  std::vector<std::uint8_t> usable(n, 0);
  for (int i = 0; i < n; i += 2) usable[i] = 1;
  match_by_bow(query_features, query, usable, train_features, train, {}, BowMatchOptions{},
               matches);
  for (const BowMatch& m : matches) EXPECT_EQ(m.query % 2, 0) << "query " << m.query;
  EXPECT_GE(matches.size(), static_cast<size_t>(0.25 * n));
}

}  // namespace
}  // namespace pspslam
