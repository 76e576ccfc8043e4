#pragma once

#include <optional>
#include <span>

#include "pspslam/core/types.h"

namespace pspslam {

// One tracked frame: its pose as tracking estimated it then, and, when the frame became a
// keyframe that is still in the map, that keyframe's pose now (after local BA, loop closing and
// global BA moved it).
struct TrackedFramePose {
  Timestamp timestamp = 0.0;
  Pose T_world_camera_tracked = Pose::Identity();
  std::optional<Pose> T_world_camera_keyframe_now;
  // How many map corrections (loop closures, global BAs) had been applied when the frame was
  // tracked. Frames on either side of a correction were tracked in differently corrected maps,
  // so a correction is never interpolated across one.
  int map_epoch = 0;
  // The frame re-expressed through its reference keyframe (T_world_reference(now) *
  // T_reference_camera as tracked): used for an epoch in which no keyframe survives.
  Pose T_world_camera_through_reference = Pose::Identity();
};

// The final trajectory: every tracked frame moved by the correction that mapping applied to the
// keyframes around it. A keyframe's correction is D = T_world_camera_now * T_world_camera_tracked⁻¹
// (a world-frame motion); a frame between two keyframes of its map epoch gets D interpolated in
// time (rotation slerp, translation linear), a frame before the first or after the last
// keyframe of its epoch gets that keyframe's D, and a frame of an epoch without keyframes its
// pose through its reference keyframe.
//
// Why not ORB-SLAM2's T_camera_reference * T_reference_world(now): that moves a frame only by
// what its reference keyframe moved after the frame was tracked. Tracking errors of consecutive
// frames are correlated (motion model, the same map points), so the whole correction BA applied
// to a keyframe since it was tracked is the better estimate of its neighbours' errors. On real
// sequences the reference-keyframe trajectory is worse than the tracked one and this one better
// (docs/decisions/file-to-evaluate.md).
// `frames` must be sorted by timestamp (and so by epoch).
Trajectory refine_by_keyframe_corrections(std::span<const TrackedFramePose> frames);

}  // namespace pspslam
