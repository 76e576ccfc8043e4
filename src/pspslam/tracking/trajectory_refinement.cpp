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
  Trajectory trajectory;
  trajectory.reserve(frames.size());
  std::vector<Correction> corrections;
  // One map epoch at a time: [begin, end) share map_epoch.
  for (size_t begin = 0; begin < frames.size();) {
    size_t end = begin;
    while (end < frames.size() && frames[end].map_epoch == frames[begin].map_epoch) ++end;
    corrections.clear();
    for (size_t f = begin; f < end; ++f) {
      if (!frames[f].T_world_camera_keyframe_now) continue;
      const Pose D =
          *frames[f].T_world_camera_keyframe_now * frames[f].T_world_camera_tracked.inverse();
      corrections.push_back(
          {frames[f].timestamp, Eigen::Quaterniond(D.rotation()).normalized(), D.translation()});
    }
    size_t next = 0;  // first correction at or after the frame
    for (size_t f = begin; f < end; ++f) {
      const TrackedFramePose& frame = frames[f];
      if (corrections.empty()) {
        trajectory.push_back({frame.timestamp, frame.T_world_camera_through_reference});
        continue;
      }
      while (next < corrections.size() && corrections[next].timestamp < frame.timestamp) ++next;
      Pose D;
      if (next == 0 || next == corrections.size()) {
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
    begin = end;
  }
  return trajectory;
}

}  // namespace pspslam
