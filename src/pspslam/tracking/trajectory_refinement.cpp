#include "pspslam/tracking/trajectory_refinement.h"

#include <Eigen/Geometry>
#include <vector>

namespace pspslam {

namespace {

struct Correction {
  Timestamp timestamp;
  Eigen::Quaterniond rotation;
  Eigen::Vector3d translation;
};

Pose to_pose(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation) {
  Pose pose = Pose::Identity();
  pose.linear() = rotation.toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

}  // namespace

Trajectory refine_by_keyframe_corrections(std::span<const TrackedFramePose> frames) {
  std::vector<Correction> corrections;
  for (const TrackedFramePose& frame : frames) {
    if (!frame.T_world_camera_keyframe_now) continue;
    const Pose D = *frame.T_world_camera_keyframe_now * frame.T_world_camera_tracked.inverse();
    corrections.push_back(
        {frame.timestamp, Eigen::Quaterniond(D.rotation()).normalized(), D.translation()});
  }

  Trajectory trajectory;
  trajectory.reserve(frames.size());
  size_t next = 0;  // first correction at or after the frame
  for (const TrackedFramePose& frame : frames) {
    while (next < corrections.size() && corrections[next].timestamp < frame.timestamp) ++next;
    Pose D = Pose::Identity();
    if (corrections.empty()) {
      // No keyframe survives: nothing to correct by.
    } else if (next == 0 || next == corrections.size()) {
      const Correction& nearest = corrections[next == 0 ? 0 : corrections.size() - 1];
      D = to_pose(nearest.rotation, nearest.translation);
    } else {
      const Correction& before = corrections[next - 1];
      const Correction& after = corrections[next];
      const double span = after.timestamp - before.timestamp;
      const double s = span > 0.0 ? (frame.timestamp - before.timestamp) / span : 1.0;
      D = to_pose(before.rotation.slerp(s, after.rotation),
                  (1.0 - s) * before.translation + s * after.translation);
    }
    trajectory.push_back({frame.timestamp, D * frame.T_world_camera_tracked});
  }
  return trajectory;
}

}  // namespace pspslam
