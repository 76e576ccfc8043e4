#pragma once

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/config/config.h"

namespace pspslam {

// Any sensor as the SLAM core sees it: an undistorted pinhole camera plus a stereo baseline
// (a stereo rig's real one; for RGB-D the virtual one that turns a depth reading into a
// right-image coordinate u_r = u - bf / z, ORB-SLAM2's treatment; none for monocular), and the
// depth below which a point counts as "close".
struct CameraModel {
  PinholeCamera pinhole;
  double bf = 0.0;                         // fx * virtual baseline [pixel * metre]
  double depth_threshold = 4.0;            // metres
  double rolling_shutter_readout_s = 0.0;  // 0: global shutter (camera/rolling_shutter.h)
  // Bounds of the undistorted image (the distorted border maps to a slightly different box).
  double min_x = 0.0;
  double max_x = 0.0;
  double min_y = 0.0;
  double max_y = 0.0;

  // `virtual_baseline` in metres (ORB-SLAM2 uses 0.08 for Kinect-class sensors); a stereo
  // camera uses its config's real baseline instead.
  static CameraModel from_config(const CameraConfig& camera, double virtual_baseline);

  bool in_bounds(double u, double v) const {
    return u >= min_x && u < max_x && v >= min_y && v < max_y;
  }
  double baseline() const { return bf / pinhole.fx; }
};

}  // namespace pspslam
