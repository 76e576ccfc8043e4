#include "pspslam/camera/rolling_shutter.h"

#include <Eigen/Geometry>

namespace pspslam {

RollingShutterCorrection::RollingShutterCorrection(const PinholeCamera& camera, double readout_s,
                                                   const Eigen::Vector3d& angular_velocity)
    : camera_(camera), readout_s_(readout_s), rate_(angular_velocity.norm()) {
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
  const double dt = rolling_shutter_row_time(readout_s_, camera_.height, sensor_row);
  const Eigen::AngleAxisd turn(rate_ * dt, axis_);
  const double z = depth > 0.0f ? depth : 1.0;
  const Eigen::Vector3d seen = turn * camera_.unproject({undistorted.x, undistorted.y}, z);
  if (!(seen.z() > 0.0)) return;  // a bearing turned past 90 degrees: no sane frame does that
  const Eigen::Vector2d pixel = camera_.project(seen);
  undistorted = {static_cast<float>(pixel.x()), static_cast<float>(pixel.y())};
  if (depth > 0.0f) depth = static_cast<float>(seen.z());
}

}  // namespace pspslam
