#pragma once

#include <Eigen/Geometry>

#include "pspslam/core/types.h"

namespace pspslam {

// A similarity transform, Sim(3): x ↦ scale · R x + t. Named like Pose: S_a_b maps frame b into
// frame a. Monocular loop closing needs it because a single camera's map drifts in scale, so the
// loop keyframe and the current keyframe disagree by a scale as well as a rigid motion; RGB-D and
// stereo use it with scale 1 (depth fixes the scale), as ORB-SLAM2 does.
struct Sim3 {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double scale = 1.0;

  Sim3() = default;
  Sim3(const Eigen::Matrix3d& rotation_, const Eigen::Vector3d& translation_, double scale_)
      : rotation(rotation_), translation(translation_), scale(scale_) {}
  // A rigid transform as a similarity of scale 1.
  explicit Sim3(const Pose& rigid)
      : rotation(rigid.linear()), translation(rigid.translation()), scale(1.0) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return scale * (rotation * point) + translation;
  }
  // (S₁ S₂)(x) = S₁(S₂(x)).
  Sim3 operator*(const Sim3& other) const {
    return {rotation * other.rotation, scale * (rotation * other.translation) + translation,
            scale * other.scale};
  }
  Sim3 operator*(const Pose& rigid) const { return *this * Sim3(rigid); }
  Sim3 inverse() const {
    const Eigen::Matrix3d rotation_inverse = rotation.transpose();
    return {rotation_inverse, -(rotation_inverse * translation) / scale, 1.0 / scale};
  }

  // The camera pose a similarity S_camera_world stands for once the world is expressed in the
  // camera's (rescaled) units: (R, t / s). It projects every point exactly as S does, because
  // S(x) = s · (R x + t / s) and projection ignores a positive factor (ORB-SLAM2 CorrectLoop).
  Pose rescaled_pose() const {
    Pose pose = Pose::Identity();
    pose.linear() = rotation;
    pose.translation() = translation / scale;
    return pose;
  }
};

}  // namespace pspslam
