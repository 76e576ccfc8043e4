#include "pspslam/camera/rolling_shutter.h"

#include <Eigen/Geometry>

namespace pspslam {

RollingShutterCorrection::RollingShutterCorrection(const PinholeCamera& camera, double readout_s,
                                                   const Eigen::Vector3d& angular_velocity)
    : camera_(camera),
      seconds_per_row_(readout_s / camera.height),
      middle_row_(0.5 * camera.height),
      rate_(angular_velocity.norm()) {
  active_ = readout_s != 0.0 && rate_ > 0.0;
  if (active_) axis_ = angular_velocity / rate_;
}

cv::Point2f RollingShutterCorrection::apply(cv::Point2f undistorted, float sensor_row) const {
  float no_depth = -1.0f;
  apply(undistorted, sensor_row, no_depth);
  return undistorted;
}

void RollingShutterCorrection::apply(cv::Point2f& undistorted, float sensor_row,
                                     float& depth) const {
  if (!active_) return;
  // Row v covers [v, v + 1) in pixel-centre coordinates' terms; v + 0.5 is its centre.
  const double dt = (sensor_row + 0.5 - middle_row_) * seconds_per_row_;
  const Eigen::AngleAxisd turn(rate_ * dt, axis_);
  const double z = depth > 0.0f ? depth : 1.0;
  const Eigen::Vector3d seen = turn * camera_.unproject({undistorted.x, undistorted.y}, z);
  if (!(seen.z() > 0.0)) return;  // a bearing turned past 90 degrees: no sane frame does that
  const Eigen::Vector2d pixel = camera_.project(seen);
  undistorted = {static_cast<float>(pixel.x()), static_cast<float>(pixel.y())};
  if (depth > 0.0f) depth = static_cast<float>(seen.z());
}

}  // namespace pspslam
