#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "pspslam/place/bow_vector.h"

namespace pspslam {

struct BowMatchOptions {
  int max_distance = 50;  // Hamming; ORB-SLAM2's TH_LOW for matches that seed a pose
  double ratio = 0.75;    // best < ratio * second best (within the node)
};

struct BowMatch {
  int query = -1;  // descriptor (keypoint) index in the query image
  int train = -1;  // descriptor index in the train image
  int distance = 0;
};

// Guided matching through the direct index (ORB-SLAM2 SearchByBoW): only descriptors that
// descended through the same vocabulary node are compared, which is ~node_count times fewer
// Hamming distances than brute force and keeps matches between similar-looking features.
// For every query descriptor q with query_usable[q] != 0 (an empty span = all usable), the
// nearest train descriptor t of the same node with train_usable[t] != 0 is taken if it passes
// max_distance and the ratio test. A train descriptor is matched at most once (the closest
// query wins). `matches` is overwritten, sorted by query index. No rotation check: callers with
// keypoints apply one (match/RotationHistogram).
void match_by_bow(const FeatureVector& query_features, const cv::Mat& query_descriptors,
                  std::span<const std::uint8_t> query_usable, const FeatureVector& train_features,
                  const cv::Mat& train_descriptors, std::span<const std::uint8_t> train_usable,
                  const BowMatchOptions& options, std::vector<BowMatch>& matches);

}  // namespace pspslam
