#include "pspslam/map/frame.h"

#include <limits>

#include "pspslam/map/map_point.h"
#include "pspslam/place/vocabulary.h"

namespace pspslam {

Frame::Frame(std::uint64_t id, Timestamp timestamp, std::vector<cv::KeyPoint> keypoints,
             cv::Mat descriptors, const cv::Mat& depth_metres,
             std::shared_ptr<const RgbdCamera> camera, std::shared_ptr<const ScalePyramid> pyramid)
    : id_(id),
      timestamp_(timestamp),
      keypoints_(std::move(keypoints)),
      descriptors_(std::move(descriptors)),
      camera_(std::move(camera)),
      pyramid_(std::move(pyramid)) {
  const size_t n = keypoints_.size();
  depth_.assign(n, -1.0f);
  right_u_.assign(n, std::numeric_limits<float>::quiet_NaN());
  // Depth is registered to the distorted image: read it before undistorting.
  const bool has_depth = !depth_metres.empty();
  for (size_t i = 0; i < n; ++i) {
    if (!has_depth) break;
    const int u = cvRound(keypoints_[i].pt.x);
    const int v = cvRound(keypoints_[i].pt.y);
    if (u < 0 || v < 0 || u >= depth_metres.cols || v >= depth_metres.rows) continue;
    const float z = depth_metres.at<float>(v, u);
    if (z > 0.0f) depth_[i] = z;
  }
  if (camera_->pinhole.has_distortion() && n > 0) {
    std::vector<cv::Point2f> points(n);
    for (size_t i = 0; i < n; ++i) points[i] = keypoints_[i].pt;
    camera_->pinhole.undistort_points(points);
    for (size_t i = 0; i < n; ++i) keypoints_[i].pt = points[i];
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
             std::shared_ptr<const RgbdCamera> camera, std::shared_ptr<const ScalePyramid> pyramid)
    : id_(id),
      timestamp_(timestamp),
      keypoints_(std::move(keypoints)),
      descriptors_(std::move(descriptors)),
      depth_(std::move(depth)),
      right_u_(std::move(right_u)),
      camera_(std::move(camera)),
      pyramid_(std::move(pyramid)) {
  grid_ = FeatureGrid(keypoints_, camera_->min_x, camera_->max_x, camera_->min_y, camera_->max_y);
  map_points.assign(keypoints_.size(), nullptr);
  outlier.assign(keypoints_.size(), 0);
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
