#pragma once

#include <cstdint>
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
  // optimize_frame_pose_judged_first only: which observations a solve uses, which agree with
  // the judged points' pose, and the solve's own observations.
  std::vector<uint8_t> use;
  std::vector<uint8_t> agrees;
  std::vector<PoseObservation> subset;
  std::vector<size_t> subset_of_observation;
};

// Pose-only optimisation of `frame` on its current map point matches (every keypoint with a map
// point, from the frame's pose as the initial guess); sets the optimised, orthonormalised pose
// on the frame. result.inlier[k] is the verdict on keypoint buffers.keypoint_of_observation[k];
// what to do with outliers is the caller's choice (tracking flags them, relocalisation drops them).
// `prior`: see optimize_pose.
PoseOptimizationResult optimize_frame_pose(Frame& frame, const PoseOptimizerOptions& options,
                                           FramePoseBuffers& buffers,
                                           const PosePrior* prior = nullptr);

// The map points a live frame's pose leans on first (optimize_frame_pose_judged_first).
struct JudgedPoints {
  // Points made by keyframes of this frame or older ones: an exact semantic mask has judged them.
  std::uint64_t judged_through_frame = 0;
  // Fewer matches to judged points than this: the pose is solved on every match, as usual.
  int min_points = 30;
};

// optimize_frame_pose for a live frame whose semantic mask is stale. Points made since the newest
// frame an exact mask judged may sit on people the stale mask missed; where people fill the view
// they outnumber the static matches and carry the pose with them. So the pose is solved on the
// judged points first, and a newer point joins the final solve only where it agrees with that
// pose; the others are outliers. A point made after this frame (a loaded map's) counts as judged.
// With fewer than `judged.min_points` judged matches, or no newer ones, this is
// optimize_frame_pose. `set_aside`: the newer matches left out of the final solve.
PoseOptimizationResult optimize_frame_pose_judged_first(Frame& frame,
                                                        const PoseOptimizerOptions& options,
                                                        FramePoseBuffers& buffers,
                                                        const PosePrior* prior,
                                                        const JudgedPoints& judged, int& set_aside);

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
