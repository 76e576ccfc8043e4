#include "pspslam/solve/pnp_ransac.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace pspslam {

PnpRansacResult solve_pnp_ransac(const PinholeCamera& camera,
                                 const std::vector<Eigen::Vector3d>& points_world,
                                 const std::vector<Eigen::Vector2d>& pixels,
                                 const PnpRansacOptions& options) {
  PnpRansacResult result;
  const size_t n = points_world.size();
  result.inlier.assign(n, 0);
  if (n < 6 || pixels.size() != n) return result;
  std::vector<cv::Point3d> object(n);
  std::vector<cv::Point2d> image(n);
  for (size_t i = 0; i < n; ++i) {
    object[i] = {points_world[i].x(), points_world[i].y(), points_world[i].z()};
    image[i] = {pixels[i].x(), pixels[i].y()};
  }
  cv::Mat rvec;
  cv::Mat tvec;
  std::vector<int> inliers;
  // Keypoints are already undistorted: no distortion coefficients here.
  const bool ok =
      cv::solvePnPRansac(object, image, camera.K(), cv::noArray(), rvec, tvec, false,
                         options.iterations, static_cast<float>(options.max_reprojection_error),
                         options.confidence, inliers, cv::SOLVEPNP_EPNP);
  if (!ok || static_cast<int>(inliers.size()) < options.min_inliers) return result;
  cv::Mat rotation;
  cv::Rodrigues(rvec, rotation);
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  cv::cv2eigen(rotation, R);
  cv::cv2eigen(tvec, t);
  result.T_camera_world.linear() = R;
  result.T_camera_world.translation() = t;
  for (int i : inliers) result.inlier[i] = 1;
  result.num_inliers = static_cast<int>(inliers.size());
  result.success = true;
  return result;
}

}  // namespace pspslam
