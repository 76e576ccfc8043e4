#pragma once

#include <Eigen/Geometry>
#include <vector>

namespace pspslam {

// Seconds, as in the TUM RGB-D file formats.
using Timestamp = double;

// Rigid transform. Naming convention: T_a_b maps coordinates in frame b into frame a,
// so T_world_camera is the camera pose (camera-to-world), the convention of TUM files.
using Pose = Eigen::Isometry3d;

struct StampedPose {
  Timestamp timestamp = 0.0;
  Pose T_world_camera = Pose::Identity();
};

using Trajectory = std::vector<StampedPose>;

// [v]x, the matrix with [v]x w = v x w.
inline Eigen::Matrix3d skew_symmetric(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

}  // namespace pspslam
