#pragma once

// Two-view map initialisation of a monocular camera (ORB-SLAM, Mur-Artal et al. 2015, section
// IV): a homography and a fundamental matrix are fitted in RANSAC to the same minimal sets, each
// scored by its symmetric transfer error, and the model is chosen by R_H = S_H / (S_H + S_F):
// a planar scene (or pure rotation) is explained by H, a general one by F. The chosen model is
// decomposed into its motion hypotheses; the one that triangulates the most points in front of
// both cameras, with parallax and a small reprojection error, wins if it is clearly better than
// the others. The translation has unit norm: the scale of a monocular map is arbitrary.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

struct TwoViewOptions {
  double sigma = 1.0;    // keypoint noise, pixels (ORB-SLAM: 1 at the finest level)
  int iterations = 200;  // RANSAC iterations, the same 8-point sets for both models
  double min_parallax_deg = 1.0;
  int min_triangulated = 50;
  // H is chosen when R_H = S_H / (S_H + S_F) exceeds this (ORB-SLAM: 0.40 to 0.45).
  double homography_ratio = 0.45;
  // The best motion hypothesis must triangulate this share of the model's inliers ...
  double min_good_ratio = 0.9;
  // ... and the second best fewer than this share of the best (otherwise it is ambiguous).
  double max_second_ratio_fundamental = 0.7;
  double max_second_ratio_homography = 0.75;
  std::uint64_t seed = 0;
  bool parallel = true;  // fit H and F on two threads
};

enum class TwoViewModel { none, homography, fundamental };
const char* to_string(TwoViewModel model);

struct TwoViewResult {
  bool success = false;
  TwoViewModel model = TwoViewModel::none;  // the model chosen (also when its decomposition fails)
  double score_homography = 0.0;
  double score_fundamental = 0.0;
  double homography_ratio = 0.0;           // R_H
  Pose T_second_first = Pose::Identity();  // |t| = 1
  // Per correspondence: the triangulated point in the first camera's frame, valid where
  // `triangulated` is set (inlier of the model, in front of both cameras, parallax, reprojects).
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint8_t> triangulated;
  int num_triangulated = 0;
  double parallax_deg = 0.0;  // of the chosen hypothesis (ORB-SLAM's 50th smallest)
  std::string failure;        // why, when !success
};

// `first[i]` and `second[i]` are undistorted pixels of the same point in the two images.
TwoViewResult initialize_two_view(const PinholeCamera& camera,
                                  std::span<const Eigen::Vector2d> first,
                                  std::span<const Eigen::Vector2d> second,
                                  const TwoViewOptions& options = {});

}  // namespace pspslam
