#pragma once

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>

#include "pspslam/config/config.h"
#include "pspslam/core/types.h"

namespace pspslam {

// One EuRoC camera's calibration (mav0/camN/sensor.yaml): pinhole intrinsics, radial-tangential
// distortion and T_BS, the camera-to-body (IMU) transform.
struct EurocCamera {
  int width = 0;
  int height = 0;
  cv::Matx33d K = cv::Matx33d::eye();
  cv::Vec4d distortion;  // k1 k2 p1 p2
  Pose T_body_camera = Pose::Identity();
  double rate_hz = 0.0;
};

// Reads sensor.yaml (the `%YAML:1.0` first line EuRoC writes is skipped; yaml-cpp rejects it).
// Errors name the file and the key: a missing or malformed `intrinsics`, `resolution`,
// `distortion_coefficients`, `T_BS` (16 values), `rate_hz`, a camera_model other than pinhole or
// a distortion_model other than radial-tangential.
EurocCamera read_euroc_camera(const std::filesystem::path& file);

// The rectification of an unrectified pair (cv::stereoRectify): remap tables for each image and
// the rectified left camera with its baseline. Rows of the two rectified images correspond.
struct StereoRectification {
  cv::Mat left_map_x, left_map_y, right_map_x, right_map_y;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double baseline = 0.0;
  // Rotation from the unrectified left camera into the rectified one (x_rect = R * x_left).
  Eigen::Matrix3d R_rect_left = Eigen::Matrix3d::Identity();
  cv::Size size;

  // Throws pspslam::Error when the right camera is not beside the left (a vertical pair) or
  // the cameras differ in resolution. `what` names the calibration in messages.
  static StereoRectification compute(const EurocCamera& left, const EurocCamera& right,
                                     const std::string& what);
  void rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_out,
               cv::Mat& right_out) const;
};

// The undistortion of one camera on its own (a monocular run): remap tables onto a pinhole
// camera without distortion that keeps the camera's orientation, its matrix chosen so that every
// pixel of the result is seen (cv::getOptimalNewCameraMatrix, alpha 0, as the pair's
// rectification keeps only valid pixels). A camera without distortion is kept as it is.
struct Undistortion {
  cv::Mat map_x, map_y;  // empty when there is no distortion to undo
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  cv::Size size;

  static Undistortion compute(const EurocCamera& camera);
  void undistort(const cv::Mat& image, cv::Mat& out) const;
};

}  // namespace pspslam
