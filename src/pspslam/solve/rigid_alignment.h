#pragma once

// Rigid (SE(3), scale fixed) alignment of two 3D point sets: the closed form of Horn / Umeyama
// and a RANSAC around it. Loop closing on RGB-D uses it: depth fixes the scale, so the loop
// transform between two keyframes has 6 degrees of freedom (ORB-SLAM2 estimates Sim(3) with
// the scale fixed to 1 for RGB-D, which is this).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam {

// Least-squares T_target_source minimising Σ w_i |target_i − T · source_i|² (Umeyama 1991
// without scale; the SVD form of Horn's method). Empty weights mean all 1. Returns nullopt
// with fewer than 3 points, mismatched sizes, or a degenerate (collinear) configuration.
std::optional<Pose> align_rigid(std::span<const Eigen::Vector3d> source,
                                std::span<const Eigen::Vector3d> target,
                                std::span<const double> weights = {});

struct RigidCorrespondence {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  // Largest |target − T · source| (metres) for which the pair is an inlier. Per pair, because
  // RGB-D depth error grows with depth (the caller knows both points' depths).
  double max_error = 0.05;
};

struct RigidRansacOptions {
  int max_iterations = 300;  // ORB-SLAM2's Sim3Solver budget per candidate
  double confidence = 0.99;
  int min_inliers = 20;
  std::uint64_t seed = 1;  // same seed, same samples: runs are reproducible
};

struct RigidRansacResult {
  bool success = false;
  Pose T_target_source = Pose::Identity();
  std::vector<std::uint8_t> inlier;  // per correspondence
  int num_inliers = 0;
  int iterations = 0;
};

// RANSAC over 3-point samples, then the transform is re-estimated on all inliers and the inlier
// set recomputed (twice). success needs >= min_inliers inliers of the final transform.
RigidRansacResult solve_rigid_ransac(std::span<const RigidCorrespondence> correspondences,
                                     const RigidRansacOptions& options = {});

}  // namespace pspslam
