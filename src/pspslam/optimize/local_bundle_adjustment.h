#pragma once

// Bundle adjustment over plain structs (no map/ types): local mapping copies the local window
// into a BaProblem, solves, and writes poses/points back and erases the outlier observations.
//
// Call pattern (local mapping):
//   BaProblem problem;                    // keyframes: local (fixed = false) + border (fixed =
//   true)
//   ... fill keyframes, points, observations (indices into the two vectors) ...
//   BaOptions options;
//   options.should_stop = [&] { return new_keyframe_waiting(); };   // aborts between iterations
//   const BaResult result = solve_bundle_adjustment(problem, camera, bf, options);
//   // problem.keyframes[k].T_camera_world / problem.points[p].position_world are updated;
//   // result.observation_inlier[o] == 0: erase that observation from the map.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/optimize/depth_noise_model.h"
#include "pspslam/optimize/pose_optimizer.h"

namespace pspslam {

struct BaKeyframe {
  uint64_t id = 0;
  Pose T_camera_world = Pose::Identity();
  bool fixed = false;  // held constant (border keyframes, the first keyframe)
};

struct BaPoint {
  uint64_t id = 0;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
};

struct BaObservation {
  size_t keyframe = 0;  // index into BaProblem::keyframes
  size_t point = 0;     // index into BaProblem::points
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double right_u = std::numeric_limits<double>::quiet_NaN();  // NaN: no depth (2-dof residual)
  double information = 1.0;  // 1 / σ² of the keypoint's pyramid level
};

// What tracking measured between two keyframes: b was tracked at T_b_a from a (a as the map
// held it then), with `information` in b's left update (optimize/pose_optimizer.h).
struct BaRelativePose {
  size_t from = 0;  // a: index into BaProblem::keyframes
  size_t to = 0;    // b
  Pose T_to_from = Pose::Identity();
  PoseInformation information = PoseInformation::Identity();
};

struct BaProblem {
  std::vector<BaKeyframe> keyframes;
  std::vector<BaPoint> points;
  std::vector<BaObservation> observations;
  std::vector<BaRelativePose> relative_poses;  // optional: tracking's factors
};

struct BaOptions {
  // Stage 1 (Huber) and stage 2 (plain least squares on the stage-1 inliers), as in ORB-SLAM2.
  // The kernel acts on each observation's 2- or 3-dof χ², applied inside the residuals (IRLS
  // weighting as in g2o) because an RGB-D observation spans two Ceres residual blocks.
  int robust_iterations = 5;
  int refine_iterations = 10;
  double huber_delta_mono = std::sqrt(5.991);
  double huber_delta_stereo = std::sqrt(7.815);
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Relative-pose factors keep a Huber kernel in both stages, at the 95% χ² of 6 dof: a tracked
  // pose that followed a moving crowd must not hold its keyframe.
  double huber_delta_relative_pose = std::sqrt(12.592);
  // Weight of the depth row. Much looser than in pose-only optimisation (σ_d ≈ 1.4 px, about the
  // u_r row's weight but without its pixel error): BA also moves the points, and on real depth a
  // tight depth row there pulls the map off (docs/decisions/depth-weighting.md).
  DepthNoiseModel depth_noise{.scale = 20.0};
  // Wall-clock budget for both stages together; stage 2 gets what stage 1 left.
  double max_seconds = 0.5;
  int num_threads = 1;
  // Up to this many free keyframes the reduced camera system is solved dense (DENSE_SCHUR),
  // above it sparse (SPARSE_SCHUR).
  int max_free_keyframes_for_dense_schur = 25;
  // Polled after every iteration; returning true stops the solve keeping the progress so far
  // and skips stage 2 (local mapping: a new keyframe is waiting).
  std::function<bool()> should_stop;
};

struct BaResult {
  std::vector<uint8_t> observation_inlier;  // per observation, χ² check after the last stage
  // ½ Σ χ² (no robust kernel) over the final inliers, before and after: comparable numbers.
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;          // both stages together
  bool stopped_early = false;  // should_stop fired or the time budget ran out
};

// Optimises the non-fixed keyframe poses and all points that have observations, in place.
// Relative-pose factors join the cost when both their keyframes are in it (have observations)
// and at least one is free; they do not count in BaResult's costs.
// Throws pspslam::Error when an observation or a factor indexes outside the vectors.
BaResult solve_bundle_adjustment(BaProblem& problem, const PinholeCamera& camera, double bf,
                                 const BaOptions& options = {});

}  // namespace pspslam
