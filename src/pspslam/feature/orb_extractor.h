#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <vector>

#include "pspslam/feature/brief_pattern.h"
#include "pspslam/feature/hamming.h"
#include "pspslam/feature/keypoint_distribution.h"
#include "pspslam/feature/orb_config.h"

namespace pspslam {

// Keypoints and their descriptors, row i of `descriptors` describes keypoints[i].
struct OrbFeatures {
  // Level-0 pixel coordinates (not undistorted); octave = pyramid level, size = 31 * scale of the
  // level, angle in degrees [0, 360), response = FAST score.
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // keypoints.size() x kOrbDescriptorBytes, CV_8UC1
};

// ORB features as ORB-SLAM2 defines them: a scale pyramid, FAST corners detected per grid cell
// with a fallback threshold for cells that yield nothing, a quadtree that spreads each level's
// share of features over the image, intensity-centroid orientation and rotated 256-bit BRIEF on
// the Gaussian-smoothed level.
//
// Not thread-safe: one extractor per thread. It keeps its pyramid and scratch buffers between
// calls, so extracting frames of the same size does not reallocate images.
class OrbExtractor {
 public:
  // Throws pspslam::Error when the config is unusable (non-positive counts, scale <= 1,
  // thresholds outside 1..255 or min > initial).
  explicit OrbExtractor(const OrbConfig& config);
  // Same with another sampling pattern (pattern learning and experiments; the default is
  // make_learned_brief_pattern()).
  OrbExtractor(const OrbConfig& config, const BriefPattern& pattern);

  // gray: CV_8UC1. ignore_mask: empty, or CV_8UC1 of gray's size where non-zero pixels are
  // ignored (dynamic regions): no keypoint is returned whose level-0 position (rounded) falls on
  // one. `out` is overwritten: its keypoint vector keeps its capacity, and its descriptor matrix
  // is reused whenever the keypoint count is unchanged (the usual n_features) and no other
  // cv::Mat shares it (a kept shallow copy of an earlier result is never overwritten).
  // Throws pspslam::Error for a wrong image type or a mask of another size/type.
  void extract(const cv::Mat& gray, const cv::Mat& ignore_mask, OrbFeatures& out);

  int levels() const { return static_cast<int>(scale_factors_.size()); }
  const OrbConfig& config() const { return config_; }
  // scale_factors()[l] = scale_factor^l: level-0 coordinate = level coordinate * scale.
  const std::vector<float>& scale_factors() const { return scale_factors_; }
  const std::vector<float>& inv_scale_factors() const { return inv_scale_factors_; }
  // How many of config().n_features each level aims for: each level gets 1/scale_factor of the
  // previous level's share (217, 181, 151, ... for the defaults), summing to n_features.
  const std::vector<int>& features_per_level() const { return features_per_level_; }
  // What each level was allowed in the last extract(): features_per_level(), or, in a frame whose
  // mask left some levels short (OrbConfig::mask_compensation), their shortfall moved to others.
  const std::vector<int>& level_budget() const { return level_budget_; }
  // Pyramid level l of the last extracted image (a view into the extractor's buffer, valid
  // until the next extract()).
  const cv::Mat& level_image(int level) const { return pyramid_[level].image; }

 private:
  struct PyramidLevel {
    cv::Mat padded;          // level image plus a reflected border (descriptor patches at edges)
    cv::Mat image;           // view of padded without the border
    cv::Mat blurred_padded;  // padded, Gaussian-smoothed (outer 3 px unset): BRIEF runs on it
    cv::Mat blurred;         // view of blurred_padded without the border
    // Level -> level-0 pixel coordinates: cv::resize aligns pixel centres, so
    // x0 = (x + 0.5) * scale_x - 0.5 with scale_x = level-0 width / this width (not the nominal
    // scale factor: sizes are rounded). Plain x * scale would shift level-7 keypoints by ~1.3 px.
    float scale_x = 1.0f;
    float scale_y = 1.0f;
    cv::Point2f to_image(float x, float y) const {
      return {(x + 0.5f) * scale_x - 0.5f, (y + 0.5f) * scale_y - 0.5f};
    }
  };

  void build_pyramid(const cv::Mat& gray);
  // FAST candidates of one level that are not masked, into level_candidates_[level]; cells
  // without any corner at the initial threshold are searched again with the minimum threshold.
  void detect_candidates(int level, const cv::Mat& ignore_mask);
  // The whole level at the minimum threshold (unmasked corners only), replacing its candidates:
  // for a level that the mask left short of its share (OrbConfig::mask_compensation).
  void detect_candidates_at_min_threshold(int level, const cv::Mat& ignore_mask);
  bool is_ignored(const cv::Mat& ignore_mask, float level_x, float level_y,
                  const PyramidLevel& level) const;
  float orientation_degrees(const cv::Mat& image, const cv::Point2f& position) const;
  void describe(const cv::Mat& blurred, const cv::KeyPoint& keypoint,
                std::uint8_t* descriptor) const;

  OrbConfig config_;
  std::vector<float> scale_factors_;
  std::vector<float> inv_scale_factors_;
  std::vector<int> features_per_level_;
  // umax_[v]: half-width of the circular orientation patch at row offset v.
  std::array<int, 16> umax_{};
  BriefPattern pattern_;
  // pattern_ rotated to each of a fixed set of angles, as integer pixel offsets.
  struct RotatedPair {
    std::int8_t first_x = 0;
    std::int8_t first_y = 0;
    std::int8_t second_x = 0;
    std::int8_t second_y = 0;
  };
  std::vector<RotatedPair> rotated_pattern_;

  std::vector<PyramidLevel> pyramid_;
  std::vector<cv::KeyPoint> fast_keypoints_;
  std::vector<std::vector<cv::KeyPoint>> level_candidates_;  // per level, capacity reused
  std::vector<int> level_available_;
  std::vector<int> level_budget_;  // features_per_level_, or shared out by mask compensation
  std::vector<cv::KeyPoint> selected_;
  std::vector<int> cell_counts_;
  QuadtreeDistributor distributor_;
  cv::Mat blur_scratch_;
};

}  // namespace pspslam
