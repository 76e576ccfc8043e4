#include "pspslam/map/camera_model.h"

#include <algorithm>
#include <vector>

namespace pspslam {

CameraModel CameraModel::from_config(const CameraConfig& camera, double virtual_baseline) {
  CameraModel c;
  c.pinhole = camera.pinhole;
  // A stereo pair has a real baseline: its right coordinate is measured, not derived from depth.
  // A monocular camera has none: no keypoint has a depth, and a baseline would only make local
  // mapping skip neighbours closer than it (in a map of arbitrary scale).
  switch (camera.type) {
    case SensorType::stereo:
      c.bf = camera.pinhole.fx * camera.baseline;
      break;
    case SensorType::monocular:
      c.bf = 0.0;
      break;
    case SensorType::rgbd:
      c.bf = camera.pinhole.fx * virtual_baseline;
      break;
  }
  c.depth_threshold = camera.depth_threshold;
  c.rolling_shutter_readout_s = camera.rolling_shutter_readout_s;
  const double w = camera.pinhole.width;
  const double h = camera.pinhole.height;
  std::vector<cv::Point2f> corners = {{0.0f, 0.0f},
                                      {static_cast<float>(w), 0.0f},
                                      {0.0f, static_cast<float>(h)},
                                      {static_cast<float>(w), static_cast<float>(h)}};
  camera.pinhole.undistort_points(corners);
  // Same box as ORB-SLAM2: the widest extent of the undistorted corners.
  c.min_x = std::min(corners[0].x, corners[2].x);
  c.max_x = std::max(corners[1].x, corners[3].x);
  c.min_y = std::min(corners[0].y, corners[1].y);
  c.max_y = std::max(corners[2].y, corners[3].y);
  return c;
}

}  // namespace pspslam
