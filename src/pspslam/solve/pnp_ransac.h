#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

struct PnpRansacOptions {
  double max_reprojection_error = 4.0;  // pixels, on undistorted coordinates
  int iterations = 200;
  double confidence = 0.99;
  int min_inliers = 15;
};

struct PnpRansacResult {
  bool success = false;
  Pose T_camera_world = Pose::Identity();
  std::vector<std::uint8_t> inlier;  // per correspondence
  int num_inliers = 0;
};

// Camera pose from 3D-2D correspondences without any prior (EPnP inside RANSAC, refined on the
// inliers). Tracking uses it only to recover after losing track, where the last pose can be
// far from the current one and pose-only optimisation from it would not converge.
PnpRansacResult solve_pnp_ransac(const PinholeCamera& camera,
                                 const std::vector<Eigen::Vector3d>& points_world,
                                 const std::vector<Eigen::Vector2d>& pixels,
                                 const PnpRansacOptions& options = {});

}  // namespace pspslam
