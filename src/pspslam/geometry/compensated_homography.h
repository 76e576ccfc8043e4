#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace pspslam {

class YamlSection;

// Parameters of the optimal error-compensation homography (paper III.B, eq. 10-11).
struct HomographyParams {
  // A match is an inlier when its transfer error ||x' - pi(H x)|| is below this (pixels).
  double inlier_threshold_px = 2.0;
  int max_ransac_iterations = 1000;
  // RANSAC stops early once an all-inlier 4-point sample has been drawn with this probability.
  double ransac_confidence = 0.999;
  int lm_max_iterations = 30;
  std::uint64_t random_seed = 7;

  // Reads the optional keys of a `homography:` section; unknown keys and out-of-range values
  // raise pspslam::Error naming the key.
  static HomographyParams from_yaml(YamlSection& section);
  bool operator==(const HomographyParams&) const = default;
};

struct CompensatedHomography {
  bool valid = false;
  // Refined homography mapping previous-frame pixels to current-frame pixels (h33 = 1).
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  // Best RANSAC minimal-sample model, kept to report what the refinement gained.
  Eigen::Matrix3d H_ransac = Eigen::Matrix3d::Identity();
  // Inlier flags under the refined H (1 = inlier), one per match.
  std::vector<std::uint8_t> inliers;
  int inlier_count = 0;
  int ransac_inlier_count = 0;
  int ransac_iterations = 0;
  int lm_iterations = 0;
  // RMS transfer error (pixels) over the RANSAC inlier set, before (RANSAC only) and after the
  // Levenberg-Marquardt refinement of eq. 11: both are measured on the same matches.
  double rms_before_px = 0.0;
  double rms_after_px = 0.0;
};

// pi(H x): transfers a previous-frame pixel into the current frame.
inline Eigen::Vector2d transfer_point(const Eigen::Matrix3d& H, const Eigen::Vector2d& x) {
  const Eigen::Vector3d p = H * x.homogeneous();
  return p.hnormalized();
}

// RANSAC over 4-point minimal sets (normalised DLT, MSAC scoring), then Levenberg-Marquardt over
// the inliers minimising eq. 11, sum_i ||x'_i - pi(H x_i)||^2 with 8 DOF (h33 = 1).
// `previous[i]` and `current[i]` are one match. Fewer than 4 matches or no model: valid = false.
CompensatedHomography estimate_compensated_homography(std::span<const Eigen::Vector2d> previous,
                                                      std::span<const Eigen::Vector2d> current,
                                                      const HomographyParams& params);
CompensatedHomography estimate_compensated_homography(std::span<const cv::Point2f> previous,
                                                      std::span<const cv::Point2f> current,
                                                      const HomographyParams& params);

// Projects previous-frame keypoints into the current frame (the camera-motion compensation frame).
void transfer_points(const Eigen::Matrix3d& H, std::span<const Eigen::Vector2d> previous,
                     std::vector<Eigen::Vector2d>& projected);

// Warps a previous image into the current frame. Label/mask maps must use nearest-neighbour
// (`is_label_map`) so that no invented label values appear at region borders.
cv::Mat warp_to_current(const cv::Mat& previous_image, const Eigen::Matrix3d& H,
                        cv::Size current_size, bool is_label_map);

}  // namespace pspslam
