#include "pspslam/camera/pinhole_camera.h"

#include <opencv2/calib3d.hpp>

namespace pspslam {

bool PinholeCamera::has_distortion() const {
  for (double d : distortion) {
    if (d != 0.0) return true;
  }
  return false;
}

cv::Mat PinholeCamera::K() const {
  return (cv::Mat_<double>(3, 3) << fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0);
}

cv::Mat PinholeCamera::distortion_coeffs() const {
  return (cv::Mat_<double>(1, 5) << distortion[0], distortion[1], distortion[2], distortion[3],
          distortion[4]);
}

void PinholeCamera::undistort_points(std::vector<cv::Point2f>& points) const {
  if (!has_distortion() || points.empty()) return;
  // P = K re-projects the normalised coordinates back to pixels of the ideal camera.
  cv::undistortPoints(points, points, K(), distortion_coeffs(), cv::noArray(), K());
}

}  // namespace pspslam
