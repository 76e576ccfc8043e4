#pragma once

#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/optimize/pose_optimizer.h"
#include "pspslam/optimize/rolling_shutter_pose.h"

namespace pspslam {

class Frame;

// Re-projects the rotation onto SO(3). The constant-velocity prediction multiplies a pose by
// the inverse of another (Isometry inverse = transpose): rounding errors in the rotation grow
// by a factor ~2 per frame through that loop unless they are removed.
Pose orthonormalized(const Pose& pose);

// Buffers reused from frame to frame (no allocation per keypoint once they have grown).
struct FramePoseBuffers {
  std::vector<PoseObservation> observations;
  std::vector<int> keypoint_of_observation;  // frame keypoint index of observations[k]
  std::vector<double> row_times;             // refine_frame_rotation_rate only
};

// Pose-only optimisation of `frame` on its current map point matches (every keypoint with a map
// point, from the frame's pose as the initial guess); sets the optimised, orthonormalised pose
// on the frame. result.inlier[k] is the verdict on keypoint buffers.keypoint_of_observation[k];
// what to do with outliers is the caller's choice (tracking flags them, relocalisation drops them).
// `prior`: see optimize_pose.
PoseOptimizationResult optimize_frame_pose(Frame& frame, const PoseOptimizerOptions& options,
                                           FramePoseBuffers& buffers,
                                           const PosePrior* prior = nullptr);

// The frame's pose from its map point matches alone (PnP-RANSAC), for a frame whose last pose is
// stale or unknown (recovery, a lost frame placed in a new map): set on the frame, the matches
// outside the consensus dropped. False, the frame unchanged, when it fails.
bool pose_from_matches(Frame& frame);

// Rolling shutter (CameraModel::rolling_shutter_readout_s != 0): the pose and the rotation rate of
// `frame` refined together on its inlier matches (optimize/rolling_shutter_pose.h, prior
// `sigma_rate` rad/s), the pose set and the keypoints moved by the rate correction, which is
// returned (rad/s, camera frame) with the pose's information, the rate marginalised. A global
// shutter changes nothing and gets zeros.
RollingShutterPose refine_frame_rotation_rate(Frame& frame, const PoseOptimizerOptions& options,
                                              double sigma_rate, FramePoseBuffers& buffers);

// The information of the frame's pose on its inlier matches (optimize/pose_optimizer.h
// pose_information), with `prior`'s when given.
PoseInformation frame_pose_information(const Frame& frame, const PoseOptimizerOptions& options,
                                       FramePoseBuffers& buffers, const PosePrior* prior);

}  // namespace pspslam
