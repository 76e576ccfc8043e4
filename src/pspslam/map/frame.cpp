#include "pspslam/map/frame.h"

#include <limits>

#include "pspslam/camera/rolling_shutter.h"
#include "pspslam/map/map_point.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {

Frame::Frame(std::uint64_t id, Timestamp timestamp, std::vector<cv::KeyPoint> keypoints,
             cv::Mat descriptors, const cv::Mat& depth_metres,
             std::shared_ptr<const CameraModel> camera, std::shared_ptr<const ScalePyramid> pyramid,
             const Eigen::Vector3d& angular_velocity)
    : id_(id),
      timestamp_(timestamp),
      keypoints_(std::move(keypoints)),
      descriptors_(std::move(descriptors)),
      camera_(std::move(camera)),
      pyramid_(std::move(pyramid)) {
  const size_t n = keypoints_.size();
  depth_.assign(n, -1.0f);
  right_u_.assign(n, std::numeric_limits<float>::quiet_NaN());
  const RollingShutterCorrection shutter(camera_->pinhole, camera_->rolling_shutter_readout_s,
                                         angular_velocity);
  // Depth is registered to the distorted image and taken at one instant, the frame's: it is read
  // where the keypoint lies at that instant, i.e. where the sensor saw it moved by the
  // rolling-shutter correction (found on the undistorted point; distortion is locally a shift
  // of the same size to well under a tenth of a pixel).
  const bool has_depth = !depth_metres.empty();
  const auto read_depth = [&](size_t i, cv::Point2f at) {
    if (!has_depth) return;
    const int u = cvRound(at.x);
    const int v = cvRound(at.y);
    if (u < 0 || v < 0 || u >= depth_metres.cols || v >= depth_metres.rows) return;
    const float z = depth_metres.at<float>(v, u);
    if (z > 0.0f) depth_[i] = z;
  };
  if (camera_->pinhole.has_distortion() && n > 0) {
    std::vector<cv::Point2f> points(n);
    for (size_t i = 0; i < n; ++i) points[i] = keypoints_[i].pt;
    camera_->pinhole.undistort_points(points);
    for (size_t i = 0; i < n; ++i) {
      const cv::Point2f moved = shutter.apply(points[i], keypoints_[i].pt.y);  // sensor row
      read_depth(i, keypoints_[i].pt + (moved - points[i]));
      keypoints_[i].pt = moved;
    }
  } else {
    for (size_t i = 0; i < n; ++i) {
      keypoints_[i].pt = shutter.apply(keypoints_[i].pt, keypoints_[i].pt.y);
      read_depth(i, keypoints_[i].pt);
    }
  }
  for (size_t i = 0; i < n; ++i) {
    if (depth_[i] > 0.0f) {
      right_u_[i] = keypoints_[i].pt.x - static_cast<float>(camera_->bf / depth_[i]);
    }
  }
  grid_ = FeatureGrid(keypoints_, camera_->min_x, camera_->max_x, camera_->min_y, camera_->max_y);
  map_points.assign(n, nullptr);
  outlier.assign(n, 0);
}

Frame::Frame(std::uint64_t id, Timestamp timestamp, std::vector<cv::KeyPoint> keypoints,
             cv::Mat descriptors, std::vector<float> depth, std::vector<float> right_u,
             std::shared_ptr<const CameraModel> camera, std::shared_ptr<const ScalePyramid> pyramid,
             const Eigen::Vector3d& angular_velocity)
    : id_(id),
      timestamp_(timestamp),
      keypoints_(std::move(keypoints)),
      descriptors_(std::move(descriptors)),
      depth_(std::move(depth)),
      right_u_(std::move(right_u)),
      camera_(std::move(camera)),
      pyramid_(std::move(pyramid)) {
  const RollingShutterCorrection shutter(camera_->pinhole, camera_->rolling_shutter_readout_s,
                                         angular_velocity);
  if (shutter.active()) {
    // The right coordinate follows the turned point, as an RGB-D frame's does below.
    for (size_t i = 0; i < keypoints_.size(); ++i) {
      shutter.apply(keypoints_[i].pt, keypoints_[i].pt.y, depth_[i]);
      if (depth_[i] > 0.0f)
        right_u_[i] = keypoints_[i].pt.x - static_cast<float>(camera_->bf / depth_[i]);
    }
  }
  grid_ = FeatureGrid(keypoints_, camera_->min_x, camera_->max_x, camera_->min_y, camera_->max_y);
  map_points.assign(keypoints_.size(), nullptr);
  outlier.assign(keypoints_.size(), 0);
}

void Frame::correct_rotation_rate(const Eigen::Vector3d& rate_correction) {
  const RollingShutterCorrection shutter(camera_->pinhole, camera_->rolling_shutter_readout_s,
                                         rate_correction);
  if (!shutter.active()) return;
  for (size_t i = 0; i < keypoints_.size(); ++i) {
    cv::Point2f& pt = keypoints_[i].pt;
    const cv::Point2f moved = shutter.apply(pt, pt.y);
    right_u_[i] += moved.x - pt.x;  // NaN stays NaN
    pt = moved;
  }
  grid_ = FeatureGrid(keypoints_, camera_->min_x, camera_->max_x, camera_->min_y, camera_->max_y);
}

void Frame::set_pose(const Pose& T_camera_world) { T_camera_world_ = T_camera_world; }

Eigen::Vector3d Frame::unproject_camera(int i) const {
  const cv::Point2f& p = keypoints_[i].pt;
  return camera_->pinhole.unproject({p.x, p.y}, depth_[i]);
}

Eigen::Vector3d Frame::unproject_world(int i) const {
  return T_camera_world_->inverse() * unproject_camera(i);
}

void Frame::compute_bow(const Vocabulary& vocabulary, int direct_index_level) {
  if (has_bow_) return;
  vocabulary.transform(descriptors_, bow_, features_, direct_index_level);
  has_bow_ = true;
}

}  // namespace pspslam
