#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "pspslam/camera/pinhole_camera.h"

namespace pspslam {

// A rolling-shutter colour camera (most RGB-D and USB colour sensors) exposes its rows one after
// another: row v at t + readout_s * (v / rows - 1/2), so a frame's timestamp is its middle row's
// instant (as synth/ renders it). Everything downstream of the Frame assumes one instant per
// image; while the camera turns, a keypoint on row v was seen from another orientation, and a
// 30 ms readout while a hand-held camera turns at 12 deg/s skews the image by ~3 px top to
// bottom. On the synthetic Kinect sequences that skew is the largest single source of tracking
// error, and real Kinect-class colour cameras read their rows over a similar time
// (docs/decisions/rolling-shutter.md).
//
// The correction turns each keypoint's bearing by the camera's rotation between its row's
// instant and the frame's: a static point seen at X_v from the camera at t_v is at
// X = exp(dt [w]x) X_v from the camera at t (dt = t_v - t, w the body angular velocity), to
// first order in the camera's motion over one readout. The translation over the same dt (a few
// millimetres at hand-held speeds) is left out: its pixel shift is ~0.2 px at 2 m.
// Seconds from the frame's instant (its middle row's) to the reading of `sensor_row` (a pixel
// coordinate: row r spans [r - 1/2, r + 1/2)).
inline double rolling_shutter_row_time(double readout_s, int rows, double sensor_row) {
  return readout_s * ((sensor_row + 0.5) / rows - 0.5);
}

class RollingShutterCorrection {
 public:
  // `readout_s`: seconds from the first row to the last (0: global shutter, nothing moves;
  // negative: the bottom row is read first). `angular_velocity`: rad/s in the camera frame (the
  // rate tracking measured on the previous frame; zero before there is one). Keeps a reference to
  // `camera`: a correction lives for the frame it is made for.
  RollingShutterCorrection(const PinholeCamera& camera, double readout_s,
                           const Eigen::Vector3d& angular_velocity);

  bool active() const { return active_; }

  // Where the camera would have seen an undistorted keypoint at the frame's instant.
  // `sensor_row`: the row it was read on (the distorted image's y).
  cv::Point2f apply(cv::Point2f undistorted, float sensor_row) const;
  // The same for a point whose depth was measured at its row's instant (a stereo pair's rows are
  // read together): `depth` (metres, <= 0: none) becomes its z at the frame's instant.
  void apply(cv::Point2f& undistorted, float sensor_row, float& depth) const;

 private:
  const PinholeCamera& camera_;
  double readout_s_ = 0.0;
  Eigen::Vector3d axis_ = Eigen::Vector3d::UnitZ();
  double rate_ = 0.0;  // rad/s about axis_
  bool active_ = false;
};

}  // namespace pspslam
