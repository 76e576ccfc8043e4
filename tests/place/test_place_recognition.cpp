// Place recognition with the shipped vocabulary on synthetic frames of one room: the camera of
// a `loop` sequence walks round the room and ends 8% of a turn past its start, so the last
// frames revisit the first viewpoints (300 frames: one turn = 300 / 1.08 = 277.8 frames).
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <opencv2/imgproc.hpp>
#include <random>

#include "place_test_data.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/place/keyframe_database.h"
#include "pspslam/place/vocabulary.h"
#include "pspslam/synth/scene.h"

namespace pspslam {
namespace {

std::filesystem::path shipped_vocabulary() {
  return source_dir() / "models" / "vocabulary" / "orb_k10_l5.pspvoc";
}

class LoopPlaceRecognition : public ::testing::Test {
 protected:
  static constexpr size_t kFrames = 300;
  static constexpr size_t kKeyframeStep = 10;
  static constexpr size_t kLastKeyframe = 250;

  static void SetUpTestSuite() {
    vocabulary_ = std::make_unique<Vocabulary>(Vocabulary::load(shipped_vocabulary()));
    SynthOptions options;
    options.frames = kFrames;
    options.trajectory = SynthTrajectory::kLoop;
    options.seed = 1;
    options.threads = 2;
    const SyntheticScene scene(options);
    OrbExtractor extractor{OrbConfig{}};
    OrbFeatures features;
    SynthFrame frame;
    cv::Mat gray;
    bows_ = std::make_unique<std::map<size_t, BowVector>>();
    std::vector<size_t> indices;
    for (size_t i = 0; i <= kLastKeyframe; i += kKeyframeStep) indices.push_back(i);
    indices.push_back(285);
    indices.push_back(290);
    for (const size_t i : indices) {
      scene.render(i, frame, options.threads);
      cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
      extractor.extract(gray, cv::Mat(), features);
      vocabulary_->transform(features.descriptors, (*bows_)[i]);
    }
  }
  static void TearDownTestSuite() {
    vocabulary_.reset();
    bows_.reset();
  }

  // Keyframes along the path: covisible = the two keyframes before and after.
  static std::vector<KeyFrameId> neighbours(KeyFrameId id) {
    std::vector<KeyFrameId> out;
    for (const long offset : {-10L, 10L, -20L, 20L}) {
      const long n = static_cast<long>(id) + offset;
      if (n >= 0 && n <= static_cast<long>(kLastKeyframe))
        out.push_back(static_cast<KeyFrameId>(n));
    }
    return out;
  }

  static void add_keyframes(KeyFrameDatabase& db) {
    for (size_t i = 0; i <= kLastKeyframe; i += kKeyframeStep) db.add(i, bows_->at(i));
  }

  // Shared by the suite's tests (rendering is the slow part); gtest suite state is static.
  static std::unique_ptr<Vocabulary> vocabulary_;
  static std::unique_ptr<std::map<size_t, BowVector>> bows_;
};

std::unique_ptr<Vocabulary> LoopPlaceRecognition::vocabulary_;
std::unique_ptr<std::map<size_t, BowVector>> LoopPlaceRecognition::bows_;

TEST_F(LoopPlaceRecognition, SameImageScoresOneUnrelatedScoresLow) {
  EXPECT_NEAR(bow_score(bows_->at(0), bows_->at(0)), 1.0, 1e-9);
  std::mt19937_64 rng(5);
  BowVector noise;
  vocabulary_->transform(testing_place::random_descriptors(1000, rng), noise);
  const double unrelated = bow_score(bows_->at(0), noise);
  std::cout << "score(frame 0, random descriptors) = " << unrelated << "\n";
  EXPECT_LT(unrelated, 0.05);
  // The BoW vector of a 1000-feature frame holds hundreds of words.
  EXPECT_GT(bows_->at(0).size(), 300u);
}

TEST_F(LoopPlaceRecognition, RevisitScoresHigherThanDistantViewpoints) {
  // Frame 290 looks where frame 290 - 277.8 = 12.2 looked; keyframe 140 looks the other way.
  const BowVector& revisit = bows_->at(290);
  const double near = bow_score(revisit, bows_->at(10));
  const double far = bow_score(revisit, bows_->at(140));
  std::cout << "score(290, 10) = " << near << ", score(290, 140) = " << far << "\n";
  EXPECT_GT(near, 2.0 * far);
  for (size_t i = 50; i <= 230; i += kKeyframeStep) {
    EXPECT_GT(near, bow_score(revisit, bows_->at(i))) << "keyframe " << i;
  }
}

TEST_F(LoopPlaceRecognition, DatabaseReturnsTheRevisitedKeyframeFirst) {
  KeyFrameDatabase db(vocabulary_->word_count());
  add_keyframes(db);
  for (const size_t query : {285u, 290u}) {
    const std::vector<PlaceCandidate> candidates = db.query(bows_->at(query), neighbours);
    ASSERT_FALSE(candidates.empty());
    std::cout << "query " << query << ":";
    for (const PlaceCandidate& c : candidates) {
      std::cout << " " << c.id << " (" << c.score << ", group " << c.group_score << ")";
    }
    std::cout << "\n";
    // Frame 285 revisits 7.2, 290 revisits 12.2: keyframe 10 is the nearest keyframe of both.
    EXPECT_EQ(candidates.front().id, 10u) << "query " << query;
    for (const PlaceCandidate& c : candidates) EXPECT_LE(c.id, 30u) << "query " << query;
  }
}

TEST_F(LoopPlaceRecognition, ErasedKeyframeIsNeverReturned) {
  KeyFrameDatabase db(vocabulary_->word_count());
  add_keyframes(db);
  ASSERT_TRUE(db.erase(10));
  const std::vector<PlaceCandidate> candidates = db.query(bows_->at(290), neighbours);
  ASSERT_FALSE(candidates.empty());
  for (const PlaceCandidate& c : candidates) EXPECT_NE(c.id, 10u);
  // The neighbours of the erased keyframe take its place.
  EXPECT_TRUE(candidates.front().id == 0u || candidates.front().id == 20u) << candidates.front().id;
}

// The direct index narrows matching to descriptors under the same node (ORB-SLAM2's
// SearchByBoW): how many good brute-force matches between two nearby frames survive that, per
// level. Most survive at level 1 (10 nodes), fewer at level 2 (100 nodes): the price of a
// ~100x smaller search, which ORB-SLAM2 pays for relocalisation and loop closing.
TEST(DirectIndex, KeepsMostGoodMatchesBetweenNearbyFrames) {
  const Vocabulary vocabulary = Vocabulary::load(shipped_vocabulary());
  SynthOptions options;
  options.frames = 30;
  options.seed = 1;
  options.threads = 2;
  const SyntheticScene scene(options);
  OrbExtractor extractor{OrbConfig{}};
  std::array<cv::Mat, 2> descriptors;
  cv::Mat gray;
  for (int f = 0; f < 2; ++f) {
    const SynthFrame frame = scene.render(static_cast<size_t>(f * 5));
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    OrbFeatures features;
    extractor.extract(gray, cv::Mat(), features);
    descriptors[f] = features.descriptors;
  }
  // Good brute-force matches: ORB-SLAM2's TH_LOW (50) and a strict ratio test.
  const cv::Mat& a = descriptors[0];
  const cv::Mat& b = descriptors[1];
  std::vector<std::pair<int, int>> good;
  for (int i = 0; i < a.rows; ++i) {
    int best = 256;
    int second = 256;
    int best_j = -1;
    for (int j = 0; j < b.rows; ++j) {
      const int d = hamming_distance(a.ptr<std::uint8_t>(i), b.ptr<std::uint8_t>(j));
      if (d < best) {
        second = best;
        best = d;
        best_j = j;
      } else if (d < second) {
        second = d;
      }
    }
    if (best <= 50 && best < 0.7 * second) good.emplace_back(i, best_j);
  }
  ASSERT_GT(good.size(), 200u);

  std::array<double, 3> kept{};
  for (const int level : {1, 2}) {
    std::array<std::vector<NodeId>, 2> node_of;
    for (int f = 0; f < 2; ++f) {
      BowVector bow;
      FeatureVector direct;
      vocabulary.transform(descriptors[f], bow, direct, level);
      node_of[f].assign(static_cast<size_t>(descriptors[f].rows), 0);
      for (size_t n = 0; n < direct.node_count(); ++n) {
        for (const int feature : direct.features(n)) node_of[f][feature] = direct.nodes()[n];
      }
    }
    int same = 0;
    for (const auto& [i, j] : good) same += node_of[0][i] == node_of[1][j] ? 1 : 0;
    kept[level] = static_cast<double>(same) / static_cast<double>(good.size());
    std::cout << "level " << level << ": " << same << " of " << good.size()
              << " good matches share their node\n";
  }
  EXPECT_GT(kept[1], 0.75);
  EXPECT_GT(kept[2], 0.55);
  EXPECT_GT(kept[1], kept[2]);
}

}  // namespace
}  // namespace pspslam
