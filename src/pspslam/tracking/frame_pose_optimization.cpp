#include "pspslam/tracking/frame_pose_optimization.h"

#include "pspslam/map/frame.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

Pose orthonormalized(const Pose& pose) {
  Pose out = pose;
  out.linear() = Eigen::Quaterniond(pose.rotation()).normalized().toRotationMatrix();
  return out;
}

PoseOptimizationResult optimize_frame_pose(Frame& frame, const PoseOptimizerOptions& options,
                                           FramePoseBuffers& buffers, const PosePrior* prior) {
  buffers.observations.clear();
  buffers.keypoint_of_observation.clear();
  const ScalePyramid& pyramid = frame.pyramid();
  for (int i = 0; i < frame.size(); ++i) {
    const auto& point = frame.map_points[i];
    if (!point) continue;
    const cv::KeyPoint& kp = frame.keypoints()[i];
    buffers.observations.push_back({point->position(), Eigen::Vector2d(kp.pt.x, kp.pt.y),
                                    static_cast<double>(frame.right_u(i)),
                                    pyramid.inv_sigma2[kp.octave]});
    buffers.keypoint_of_observation.push_back(i);
  }
  PoseOptimizationResult optimized =
      optimize_pose(frame.camera().pinhole, frame.camera().bf, frame.T_camera_world(),
                    buffers.observations, options, prior);
  frame.set_pose(orthonormalized(optimized.T_camera_world));
  return optimized;
}

}  // namespace pspslam
