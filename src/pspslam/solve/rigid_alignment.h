#pragma once

// Rigid (SE(3)) and similarity (Sim(3)) alignment of two 3D point sets: the closed form of
// Horn / Umeyama and a RANSAC around it. Loop closing uses it between two keyframes' map points:
// on RGB-D and stereo depth fixes the scale, so the loop transform has 6 degrees of freedom
// (ORB-SLAM2's Sim3Solver with the scale fixed to 1); a monocular map drifts in scale, so there
// the scale is estimated too (7 degrees of freedom).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "pspslam/core/similarity.h"
#include "pspslam/core/types.h"

namespace pspslam {

// Least-squares T_target_source minimising Σ w_i |target_i − T · source_i|² (Umeyama 1991
// without scale; the SVD form of Horn's method). Empty weights mean all 1. Returns nullopt
// with fewer than 3 points, mismatched sizes, or a degenerate (collinear) configuration.
std::optional<Pose> align_rigid(std::span<const Eigen::Vector3d> source,
                                std::span<const Eigen::Vector3d> target,
                                std::span<const double> weights = {});

// The same with Umeyama's least-squares scale: S_target_source minimising
// Σ w_i |target_i − s R source_i − t|². Same refusals as align_rigid.
std::optional<Sim3> align_similarity(std::span<const Eigen::Vector3d> source,
                                     std::span<const Eigen::Vector3d> target,
                                     std::span<const double> weights = {});

struct RigidCorrespondence {
  Eigen::Vector3d source = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  // Largest |target − S · source| (target units) for which the pair is an inlier. Per pair,
  // because depth error grows with depth (the caller knows both points' depths).
  double max_error = 0.05;
};

struct RigidRansacOptions {
  int max_iterations = 300;  // ORB-SLAM2's Sim3Solver budget per candidate
  double confidence = 0.99;
  int min_inliers = 20;
  std::uint64_t seed = 1;       // same seed, same samples: runs are reproducible
  bool estimate_scale = false;  // Sim(3) instead of SE(3) (monocular)
};

struct RigidRansacResult {
  bool success = false;
  Sim3 S_target_source;              // scale 1 unless estimate_scale
  std::vector<std::uint8_t> inlier;  // per correspondence
  int num_inliers = 0;
  int iterations = 0;
};

// RANSAC over 3-point samples, then the transform is re-estimated on all inliers and the inlier
// set recomputed (twice). success needs >= min_inliers inliers of the final transform.
RigidRansacResult solve_rigid_ransac(std::span<const RigidCorrespondence> correspondences,
                                     const RigidRansacOptions& options = {});

}  // namespace pspslam
