// Regenerates the learned BRIEF pattern (kLearnedPairIndices in brief_pattern.cpp). Disabled: it
// is a tool, not a check. Run with
//   test_feature --gtest_also_run_disabled_tests --gtest_filter='*LearnBriefPattern*'
// and paste the printed table.
#include <gtest/gtest.h>

#include <cstdio>
#include <vector>

#include "feature_test_images.h"
#include "pspslam/feature/brief_pattern.h"
#include "pspslam/feature/orb_extractor.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

TEST(BriefPatternLearning, DISABLED_LearnBriefPattern) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  // Training keypoints: every 8th frame of the clip (empty room and people), as the extractor
  // finds and orients them. The keypoints do not depend on the pattern, so evaluating the pool
  // 256 candidates at a time with extractors that differ only in their pattern lines them up.
  std::vector<cv::Mat> images;
  for (int frame = 0; frame < 400; frame += 8)
    images.push_back(testing::load_bonn_gray_frame(shared, frame));

  const std::vector<BriefPair> candidates = make_brief_candidates();
  std::vector<std::vector<std::uint64_t>> outcomes(candidates.size());
  int n_samples = 0;
  for (int chunk = 0; chunk < kBriefCandidateChunks; ++chunk) {
    BriefPattern pattern{};
    for (int i = 0; i < kBriefPairs; ++i) pattern[i] = candidates[chunk * kBriefPairs + i];
    OrbExtractor extractor(OrbConfig{}, pattern);
    OrbFeatures features;
    int sample = 0;
    for (const cv::Mat& image : images) {
      extractor.extract(image, cv::Mat(), features);
      for (int row = 0; row < features.descriptors.rows; ++row, ++sample) {
        const std::uint8_t* descriptor = features.descriptors.ptr<std::uint8_t>(row);
        for (int bit = 0; bit < kBriefPairs; ++bit) {
          std::vector<std::uint64_t>& bits = outcomes[chunk * kBriefPairs + bit];
          if (sample % 64 == 0) bits.push_back(0);
          if ((descriptor[bit / 8] >> (bit % 8)) & 1)
            bits.back() |= std::uint64_t{1} << (sample % 64);
        }
      }
    }
    n_samples = sample;
  }
  const std::vector<int> selected = select_decorrelated_pairs(outcomes, n_samples, kBriefPairs);
  ASSERT_EQ(static_cast<int>(selected.size()), kBriefPairs);
  std::printf("// %d training keypoints from %zu frames\n", n_samples, images.size());
  for (int i = 0; i < kBriefPairs; ++i) {
    std::printf("%d,%s", selected[i], i % 16 == 15 ? "\n" : " ");
  }
}

}  // namespace
}  // namespace pspslam
