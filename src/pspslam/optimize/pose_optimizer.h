#pragma once

// Pose-only optimisation (motion-only bundle adjustment) of one RGB-D frame against known map
// points, ORB-SLAM2 semantics. Called by tracking on every frame, so it must stay cheap.
//
// Call pattern (tracking):
//   std::vector<PoseObservation> observations;           // one per matched map point
//   observations.push_back({point->position(), keypoint_pixel, right_u_or_negative,
//                           inverse_level_sigma2});
//   const PoseOptimizationResult result = optimize_pose(camera, bf, predicted_T_camera_world,
//                                                       observations);
//   frame.set_pose(result.T_camera_world);              // result.inlier[i] == 0: drop match i

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/optimize/depth_noise_model.h"

namespace pspslam {

// Information of a pose in the left update [ω; v] (rotation rad, translation m).
using PoseInformation = Eigen::Matrix<double, 6, 6>;

struct PoseObservation {
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted keypoint
  // Virtual right coordinate u − bf/z; NaN: no depth (2-dof residual). Not "< 0": a real u_r is
  // negative for close points near the left image border.
  double right_u = std::numeric_limits<double>::quiet_NaN();
  double information = 1.0;  // 1 / σ² of the keypoint's pyramid level (σ² = scale²)
};

// A Gaussian prior on the pose: the constant-velocity prediction of tracking, say. Its residual is
// the whitened difference between the optimised pose and `T_camera_world` in the optimiser's own
// left update δ = [ω; v] (T = (Exp(ω), v) · T_prior ⇔ δ = 0): ω is a rotation about the camera
// centre in the camera frame, v to first order minus the camera-centre displacement in the
// camera frame, so isotropic σs mean what they say.
struct PosePrior {
  Pose T_camera_world = Pose::Identity();
  double sigma_rotation = 0.0;     // rad; > 0
  double sigma_translation = 0.0;  // m; > 0
};

struct PoseOptimizationResult {
  Pose T_camera_world = Pose::Identity();
  std::vector<uint8_t> inlier;  // per observation: 1 = χ² below threshold in the final round
  int num_inliers = 0;
};

struct PoseOptimizerOptions {
  int rounds = 4;
  int iterations_per_round = 10;
  // Rounds [0, robust_rounds) use the Huber kernel; later rounds are plain least squares on the
  // inliers (ORB-SLAM2 drops the kernel from the third round on).
  int robust_rounds = 2;
  double huber_delta_mono = std::sqrt(5.991);
  double huber_delta_stereo = std::sqrt(7.815);
  // χ² thresholds at 95%: 2 dof (u, v) and 3 dof (u, v, u_r).
  double chi2_mono = 5.991;
  double chi2_stereo = 7.815;
  // Fewer inliers than this after a round: stop, the pose is not constrained well enough to
  // keep refining (the remaining rounds would fit the few survivors).
  int min_inliers_to_continue = 10;
  // Weight of the depth row: σ_d twice the Kinect-v1 model, more accurate than the u_r row on
  // both synthetic and real depth. 1× here is better still on the synthetic sequence but worse on
  // real depth, which is worse than the model (registration, edges): the scale belongs to the
  // sensor, not to the code (docs/decisions/depth-weighting.md).
  DepthNoiseModel depth_noise{.scale = 2.0};
};

// Refines initial_T_camera_world. Observations with depth (right_u not NaN) constrain (u, v, u_r)
// with the virtual stereo baseline bf = fx · b; the others (u, v). Never throws on degenerate
// input: with no observations it returns the initial pose and num_inliers = 0. With a `prior`,
// every round also minimises its residual (a 6-dof quadratic term next to the observations';
// the χ² verdicts on the observations do not include it).
PoseOptimizationResult optimize_pose(const PinholeCamera& camera, double bf,
                                     const Pose& initial_T_camera_world,
                                     const std::vector<PoseObservation>& observations,
                                     const PoseOptimizerOptions& options = {},
                                     const PosePrior* prior = nullptr);

// The χ² verdicts of optimize_pose's last round (1 = inlier at 95 %) on `observations` seen from
// `T_camera_world`, without optimising, into `inlier` (resized): which of them agree with a pose
// found on others.
void classify_observations(const PinholeCamera& camera, double bf, const Pose& T_camera_world,
                           const std::vector<PoseObservation>& observations,
                           const PoseOptimizerOptions& options, std::vector<uint8_t>& inlier);

// The information of a prior alone: diag(1/σ_r², 1/σ_r², 1/σ_r², 1/σ_t², 1/σ_t², 1/σ_t²).
PoseInformation prior_information(const PosePrior& prior);

// 6×6 information (Gauss-Newton JᵀJ) of a pose estimated from `observations` (the inliers) under
// the same whitened residuals as optimize_pose, plus the prior's when given. It is expressed in
// the optimiser's left update δ = [ω; v] of T_camera_world: the inverse is the covariance of the
// pose as tracking knows it. Observations behind the camera add nothing.
PoseInformation pose_information(const PinholeCamera& camera, double bf,
                                 const DepthNoiseModel& depth_noise, const Pose& T_camera_world,
                                 const std::vector<PoseObservation>& observations,
                                 const PosePrior* prior = nullptr);

}  // namespace pspslam
