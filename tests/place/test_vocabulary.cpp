#include <gtest/gtest.h>

#include <array>
#include <map>
#include <random>
#include <set>

#include "place_test_data.h"
#include "pspslam/core/error.h"
#include "pspslam/feature/hamming.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {
namespace {

using testing_place::flip_random_bits;
using testing_place::random_descriptors;

// `clusters` planted centres with `per_cluster` noisy copies each (`noise_bits` bits flipped):
// rows cluster * per_cluster .. (cluster + 1) * per_cluster - 1 belong to cluster `cluster`.
struct PlantedClusters {
  cv::Mat centres;
  cv::Mat descriptors;
};

PlantedClusters planted_clusters(int clusters, int per_cluster, int noise_bits,
                                 std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  PlantedClusters planted{random_descriptors(clusters, rng),
                          cv::Mat(clusters * per_cluster, kOrbDescriptorBytes, CV_8UC1)};
  for (int c = 0; c < clusters; ++c) {
    for (int i = 0; i < per_cluster; ++i) {
      cv::Mat row = planted.descriptors.row(c * per_cluster + i);
      planted.centres.row(c).copyTo(row);
      flip_random_bits(row.ptr<std::uint8_t>(), noise_bits, rng);
    }
  }
  return planted;
}

std::vector<cv::Mat> split_images(const cv::Mat& descriptors, int images) {
  std::vector<cv::Mat> out;
  const int per_image = descriptors.rows / images;
  for (int i = 0; i < images; ++i) {
    out.push_back(descriptors.rowRange(i * per_image, (i + 1) * per_image).clone());
  }
  return out;
}

// The word by exhaustive search at every level, written independently of Vocabulary::word.
WordId brute_force_word(const Vocabulary& vocabulary, const std::uint8_t* descriptor) {
  NodeId node = 0;
  while (vocabulary.child_count(node) > 0) {
    std::vector<std::pair<int, NodeId>> distances;
    for (int c = 0; c < vocabulary.child_count(node); ++c) {
      const NodeId child = vocabulary.first_child(node) + static_cast<NodeId>(c);
      distances.emplace_back(hamming_distance(descriptor, vocabulary.node_descriptor(child)),
                             child);
    }
    node = std::min_element(distances.begin(), distances.end())->second;
  }
  for (WordId w = 0; w < vocabulary.word_count(); ++w) {
    if (vocabulary.word_node(w) == node) return w;
  }
  ADD_FAILURE() << "leaf " << node << " is no word";
  return 0;
}

TEST(VocabularyTraining, RecoversPlantedClustersExactly) {
  // 8 random centres (pairwise ~128 bits apart) with 300 copies each, 12 of 256 bits flipped.
  const PlantedClusters planted = planted_clusters(8, 300, 12, 7);
  VocabularyParams params;
  params.branching = 8;
  params.levels = 1;
  const Vocabulary vocabulary =
      Vocabulary::train(planted.descriptors, split_images(planted.descriptors, 8), params);
  ASSERT_EQ(vocabulary.word_count(), 8u);
  ASSERT_EQ(vocabulary.node_count(), 9u);

  // Every planted cluster maps to a single word, a different one for each cluster.
  std::set<WordId> used;
  for (int c = 0; c < 8; ++c) {
    std::set<WordId> words;
    for (int i = 0; i < 300; ++i) {
      words.insert(vocabulary.word(planted.descriptors.ptr<std::uint8_t>(c * 300 + i)));
    }
    ASSERT_EQ(words.size(), 1u) << "cluster " << c;
    used.insert(*words.begin());
    // The per-bit majority of 300 copies with 12/256 bits flipped is the planted centre.
    EXPECT_EQ(hamming_distance(vocabulary.node_descriptor(vocabulary.word_node(*words.begin())),
                               planted.centres.ptr<std::uint8_t>(c)),
              0)
        << "cluster " << c;
  }
  EXPECT_EQ(used.size(), 8u);
}

TEST(VocabularyTraining, TwoLevelsSeparateClustersOfClusters) {
  // 4 super-clusters, each holding 4 sub-clusters 20 bits from their super centre.
  std::mt19937_64 rng(11);
  const cv::Mat supers = random_descriptors(4, rng);
  cv::Mat data(4 * 4 * 100, kOrbDescriptorBytes, CV_8UC1);
  std::vector<std::array<std::uint8_t, 32>> subs;
  for (int s = 0; s < 4; ++s) {
    for (int t = 0; t < 4; ++t) {
      std::array<std::uint8_t, 32> sub{};
      std::memcpy(sub.data(), supers.ptr<std::uint8_t>(s), 32);
      flip_random_bits(sub.data(), 20, rng);
      subs.push_back(sub);
      for (int i = 0; i < 100; ++i) {
        std::uint8_t* row = data.ptr<std::uint8_t>((s * 4 + t) * 100 + i);
        std::memcpy(row, sub.data(), 32);
        flip_random_bits(row, 4, rng);
      }
    }
  }
  VocabularyParams params;
  params.branching = 4;
  params.levels = 2;
  const Vocabulary vocabulary = Vocabulary::train(data, split_images(data, 16), params);
  ASSERT_EQ(vocabulary.word_count(), 16u);
  ASSERT_EQ(vocabulary.node_count(), 21u);
  std::set<WordId> used;
  for (int cluster = 0; cluster < 16; ++cluster) {
    std::set<WordId> words;
    for (int i = 0; i < 100; ++i)
      words.insert(vocabulary.word(data.ptr<std::uint8_t>(cluster * 100 + i)));
    ASSERT_EQ(words.size(), 1u) << "sub-cluster " << cluster;
    used.insert(*words.begin());
    EXPECT_EQ(hamming_distance(vocabulary.node_descriptor(vocabulary.word_node(*words.begin())),
                               subs[cluster].data()),
              0);
  }
  EXPECT_EQ(used.size(), 16u);
  // Each image holds exactly one sub-cluster: every word is in 1 of 16 images, idf = ln 16.
  for (WordId w = 0; w < 16; ++w) EXPECT_NEAR(vocabulary.word_weight(w), std::log(16.0), 1e-6);
}

TEST(VocabularyTraining, LookupMatchesBruteForceDescentAndIsDeterministic) {
  std::mt19937_64 rng(3);
  // Structured data (so the tree is deep and uneven) plus pure noise queries.
  const PlantedClusters planted = planted_clusters(60, 80, 30, 5);
  VocabularyParams params;
  params.branching = 6;
  params.levels = 4;
  params.seed = 42;
  const Vocabulary a =
      Vocabulary::train(planted.descriptors, split_images(planted.descriptors, 20), params);
  const Vocabulary b =
      Vocabulary::train(planted.descriptors, split_images(planted.descriptors, 20), params);
  ASSERT_EQ(a.node_count(), b.node_count());
  for (NodeId n = 0; n < a.node_count(); ++n) {
    ASSERT_EQ(std::memcmp(a.node_descriptor(n), b.node_descriptor(n), 32), 0) << "node " << n;
  }
  const cv::Mat queries = random_descriptors(500, rng);
  cv::Mat all;
  cv::vconcat(planted.descriptors, queries, all);
  for (int r = 0; r < all.rows; ++r) {
    const WordId w = a.word(all.ptr<std::uint8_t>(r));
    ASSERT_EQ(w, brute_force_word(a, all.ptr<std::uint8_t>(r))) << "row " << r;
    ASSERT_EQ(w, a.word(all.ptr<std::uint8_t>(r)));
    ASSERT_EQ(w, b.word(all.ptr<std::uint8_t>(r)));
    NodeId node = 0;
    ASSERT_EQ(a.word(all.ptr<std::uint8_t>(r), 2, &node), w);
    // The level-2 node is the grandparent-side ancestor of the word's leaf.
    NodeId ancestor = a.word_node(w);
    std::vector<NodeId> path{ancestor};
    while (ancestor != 0) {
      NodeId parent = 0;
      for (NodeId p = 0; p < a.node_count(); ++p) {
        if (a.child_count(p) > 0 && a.first_child(p) <= ancestor &&
            ancestor < a.first_child(p) + static_cast<NodeId>(a.child_count(p))) {
          parent = p;
          break;
        }
      }
      ancestor = parent;
      path.insert(path.begin(), ancestor);
    }
    const NodeId expected_node = path.size() > 2 ? path[2] : path.back();
    ASSERT_EQ(node, expected_node) << "row " << r;
  }
}

TEST(VocabularyTraining, TransformIsNormalisedTfIdfWithDirectIndex) {
  const PlantedClusters planted = planted_clusters(8, 300, 12, 7);
  VocabularyParams params;
  params.branching = 8;
  params.levels = 1;
  // Images: cluster c appears in images c and (c+1)%8 ... built so idf differs per word.
  std::vector<cv::Mat> images;
  for (int i = 0; i < 8; ++i) {
    cv::Mat image;
    cv::vconcat(planted.descriptors.rowRange(i * 300, i * 300 + 10),
                planted.descriptors.rowRange(0, 10), image);  // cluster 0 in every image
    images.push_back(image);
  }
  const Vocabulary vocabulary = Vocabulary::train(planted.descriptors, images, params);
  const WordId w0 = vocabulary.word(planted.descriptors.ptr<std::uint8_t>(0));
  const WordId w3 = vocabulary.word(planted.descriptors.ptr<std::uint8_t>(3 * 300));
  const WordId w5 = vocabulary.word(planted.descriptors.ptr<std::uint8_t>(5 * 300));
  EXPECT_FLOAT_EQ(vocabulary.word_weight(w0), 0.0f);  // in all 8 images: ln(8/8)
  EXPECT_NEAR(vocabulary.word_weight(w3), std::log(8.0), 1e-6);

  // 3 descriptors of cluster 3, 1 of cluster 5, 2 of cluster 0 (weight 0, dropped).
  cv::Mat query;
  cv::vconcat(std::vector<cv::Mat>{planted.descriptors.rowRange(900, 903),
                                   planted.descriptors.rowRange(1500, 1501),
                                   planted.descriptors.rowRange(0, 2)},
              query);
  BowVector bow;
  FeatureVector direct;
  vocabulary.transform(query, bow, direct, 1);
  ASSERT_EQ(bow.size(), 2u);
  std::map<WordId, float> weights;
  for (const BowEntry& e : bow.entries) weights[e.word] = e.weight;
  EXPECT_NEAR(weights[w3], 0.75, 1e-6);
  EXPECT_NEAR(weights[w5], 0.25, 1e-6);
  EXPECT_LT(bow.entries[0].word, bow.entries[1].word);
  // Direct index at level 1 (= the words here), features of cluster 3 are rows 0..2.
  ASSERT_EQ(direct.node_count(), 2u);
  for (std::size_t i = 0; i < direct.node_count(); ++i) {
    const auto f = direct.features(i);
    if (direct.nodes()[i] == vocabulary.word_node(w3)) {
      EXPECT_EQ(std::vector<int>(f.begin(), f.end()), (std::vector<int>{0, 1, 2}));
    } else {
      EXPECT_EQ(direct.nodes()[i], vocabulary.word_node(w5));
      EXPECT_EQ(std::vector<int>(f.begin(), f.end()), (std::vector<int>{3}));
    }
  }
  BowVector plain;
  vocabulary.transform(query, plain);
  ASSERT_EQ(plain.size(), bow.size());
  EXPECT_DOUBLE_EQ(bow_score(plain, bow), 1.0);
}

TEST(VocabularyTraining, InvalidParamsNameTheFlag) {
  VocabularyParams params;
  params.branching = 1;
  try {
    params.validate();
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "vocabulary: --k (branching) must be in 2..255, got 1");
  }
  params.branching = 10;
  params.levels = 0;
  try {
    params.validate();
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "vocabulary: --levels must be in 1..10, got 0");
  }
}

TEST(BowScore, IdenticalIsOneDisjointIsZeroPartialIsSharedMass) {
  BowVector a{{{1, 0.5f}, {2, 0.5f}}};
  BowVector b{{{2, 0.5f}, {3, 0.5f}}};
  BowVector c{{{7, 1.0f}}};
  EXPECT_DOUBLE_EQ(bow_score(a, a), 1.0);
  EXPECT_DOUBLE_EQ(bow_score(a, b), 0.5);  // 1 - 0.5 * (0.5 + 0 + 0.5)
  EXPECT_DOUBLE_EQ(bow_score(a, c), 0.0);
  EXPECT_DOUBLE_EQ(bow_score(a, BowVector{}), 0.0);
  // Unnormalised input is normalised: {2,2} is {0.5,0.5}.
  BowVector scaled{{{1, 2.0f}, {2, 2.0f}}};
  EXPECT_DOUBLE_EQ(bow_score(a, scaled), 1.0);
  BowVector skew{{{1, 0.9f}, {2, 0.1f}}};
  EXPECT_NEAR(bow_score(a, skew), 0.6, 1e-6);  // 1 - 0.5 * (0.4 + 0.4)
}

}  // namespace
}  // namespace pspslam
