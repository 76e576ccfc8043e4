#pragma once

// Refinement of a loop's similarity by reprojection in both keyframes (ORB-SLAM2 OptimizeSim3).
// The 3D-3D fit that finds the loop (solve/rigid_alignment) weighs every point's position
// equally in all directions; a monocular map point's depth is known far worse than its bearing,
// so the fit's transform can move the current keyframe's neighbourhood well away from the truth.
// Reprojection errors measure what the keyframes saw: bearings.

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/similarity.h"

namespace pspslam {

// One matched map point pair: the point of keyframe B (in B's camera) and the keypoint of A that
// matched it, and the other way round.
struct SimilarityPair {
  Eigen::Vector3d in_a = Eigen::Vector3d::Zero();        // A's map point, in A's camera
  Eigen::Vector3d in_b = Eigen::Vector3d::Zero();        // B's map point, in B's camera
  Eigen::Vector2d pixel_in_a = Eigen::Vector2d::Zero();  // undistorted keypoint of A
  Eigen::Vector2d pixel_in_b = Eigen::Vector2d::Zero();  // undistorted keypoint of B
  double information_a = 1.0;                            // 1 / σ² of the keypoint's pyramid level
  double information_b = 1.0;
};

struct SimilarityOptimizationOptions {
  // ORB-SLAM2: 5 iterations with the Huber kernel, drop pairs above χ² = 10 in either image, then
  // 10 more on the rest.
  int first_iterations = 5;
  int second_iterations = 10;
  double chi2 = 10.0;
  bool estimate_scale = true;  // false: the scale stays as given (RGB-D, stereo)
};

struct SimilarityOptimizationResult {
  Sim3 S_a_b;
  std::vector<std::uint8_t> inlier;  // per pair: within chi2 in both images after the solve
  int num_inliers = 0;
};

// Minimises Σ ρ(|π(S_a_b · in_b) − pixel_in_a|² · information_a) + ρ(|π(S_a_b⁻¹ · in_a) −
// pixel_in_b|² · information_b) over S_a_b (rotation, translation, log-scale), from `initial`.
// Both keyframes share `camera`.
SimilarityOptimizationResult optimize_similarity(const PinholeCamera& camera, const Sim3& initial,
                                                 std::span<const SimilarityPair> pairs,
                                                 const SimilarityOptimizationOptions& options = {});

}  // namespace pspslam
