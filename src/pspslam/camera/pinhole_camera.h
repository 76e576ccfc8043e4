#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam {

// Pinhole camera with radial-tangential distortion (OpenCV order k1 k2 p1 p2 k3).
// project()/unproject() work on *undistorted* pixel coordinates: features are undistorted once
// after extraction, so everything downstream uses the ideal pinhole model.
struct PinholeCamera {
  int width = 640;
  int height = 480;
  double fx = 525.0;
  double fy = 525.0;
  double cx = 319.5;
  double cy = 239.5;
  std::array<double, 5> distortion{};  // k1 k2 p1 p2 k3

  bool has_distortion() const;
  cv::Mat K() const;                  // 3x3 CV_64F
  cv::Mat distortion_coeffs() const;  // 1x5 CV_64F

  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const {
    return {fx * point_camera.x() / point_camera.z() + cx,
            fy * point_camera.y() / point_camera.z() + cy};
  }
  Eigen::Vector3d unproject(const Eigen::Vector2d& pixel, double depth) const {
    return {(pixel.x() - cx) / fx * depth, (pixel.y() - cy) / fy * depth, depth};
  }
  bool in_image(const Eigen::Vector2d& pixel, double border = 0.0) const {
    return pixel.x() >= border && pixel.y() >= border && pixel.x() < width - border &&
           pixel.y() < height - border;
  }

  // Undistorts pixel coordinates in place (no-op without distortion).
  void undistort_points(std::vector<cv::Point2f>& points) const;
};

}  // namespace pspslam
