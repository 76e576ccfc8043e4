#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/feature_grid.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/place/bow_vector.h"

namespace pspslam {

class MapPoint;
class Vocabulary;

// One tracked image: undistorted keypoints with their depth, descriptors and the map points
// that tracking associates with them. A Frame is transient and owned by tracking; it shares
// ownership of the map points it currently uses (they never point back to a Frame).
class Frame {
 public:
  // `keypoints` are in distorted image coordinates as the extractor returns them; depth is
  // read there (the depth image is registered to the distorted colour image), then the
  // keypoints are undistorted once and, for a rolling-shutter camera
  // (CameraModel::rolling_shutter_readout_s), moved to the frame's instant with
  // `angular_velocity` (rad/s, camera frame; camera/rolling_shutter.h). `descriptors`: N x 32
  // CV_8U (shared, not copied).
  Frame(std::uint64_t id, Timestamp timestamp, std::vector<cv::KeyPoint> keypoints,
        cv::Mat descriptors, const cv::Mat& depth_metres, std::shared_ptr<const CameraModel> camera,
        std::shared_ptr<const ScalePyramid> pyramid,
        const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());
  // A frame whose depth was measured per keypoint (a rectified stereo pair: depth and right
  // coordinate from match/stereo_matcher.h; depth <= 0 and NaN where a keypoint has no partner).
  // Keypoints are in the rectified image, which has no distortion; both cameras are taken to
  // read their rows together, so a rolling-shutter correction turns the triangulated point.
  Frame(std::uint64_t id, Timestamp timestamp, std::vector<cv::KeyPoint> keypoints,
        cv::Mat descriptors, std::vector<float> depth, std::vector<float> right_u,
        std::shared_ptr<const CameraModel> camera, std::shared_ptr<const ScalePyramid> pyramid,
        const Eigen::Vector3d& angular_velocity = Eigen::Vector3d::Zero());

  std::uint64_t id() const { return id_; }
  Timestamp timestamp() const { return timestamp_; }
  int size() const { return static_cast<int>(keypoints_.size()); }

  const std::vector<cv::KeyPoint>& keypoints() const { return keypoints_; }
  const cv::Mat& descriptors() const { return descriptors_; }
  const std::uint8_t* descriptor(int i) const { return descriptors_.ptr<std::uint8_t>(i); }
  // Depth in metres (<= 0: no valid reading) and virtual right coordinate u − bf/z (NaN without
  // depth: a real u_r is negative for close points near the left border, so no sign can mean
  // "none"). Test has_depth(i), never the sign of right_u(i).
  float depth(int i) const { return depth_[i]; }
  float right_u(int i) const { return right_u_[i]; }
  bool has_depth(int i) const { return depth_[i] > 0.0f; }
  const std::vector<float>& depths() const { return depth_; }
  const std::vector<float>& right_us() const { return right_u_; }
  const CameraModel& camera() const { return *camera_; }
  const ScalePyramid& pyramid() const { return *pyramid_; }
  const std::shared_ptr<const CameraModel>& camera_ptr() const { return camera_; }
  const std::shared_ptr<const ScalePyramid>& pyramid_ptr() const { return pyramid_; }
  const FeatureGrid& grid() const { return grid_; }

  // Keypoints within `radius` of (x, y) with octave in [min_level, max_level] (<0: any).
  void features_in_area(double x, double y, double radius, int min_level, int max_level,
                        std::vector<int>& out) const {
    grid_.query(keypoints_, x, y, radius, min_level, max_level, out);
  }

  // Rolling shutter: the rate tracking measured differs from the one the keypoints were moved
  // with by `rate_correction` (rad/s, camera frame; optimize/rolling_shutter_pose.h): moves them
  // the rest of the way. Depth stays (taken at the frame's instant); the right coordinate keeps
  // its disparity. The row of a keypoint is taken at its undistorted y (the rest is small).
  void correct_rotation_rate(const Eigen::Vector3d& rate_correction);

  // Pose (unset until tracking estimates it; lost frames never get one).
  bool has_pose() const { return T_camera_world_.has_value(); }
  void set_pose(const Pose& T_camera_world);
  void clear_pose() { T_camera_world_.reset(); }
  const Pose& T_camera_world() const { return *T_camera_world_; }
  Pose T_world_camera() const { return T_camera_world_->inverse(); }
  Eigen::Vector3d camera_center() const { return T_camera_world_->inverse().translation(); }

  // Back-projects keypoint i with its depth into camera / world coordinates (needs depth > 0).
  Eigen::Vector3d unproject_camera(int i) const;
  Eigen::Vector3d unproject_world(int i) const;

  // Bag of words, computed only when needed (relocalisation of a lost frame): a tracked frame
  // never pays for it. Computed once; later calls return at once.
  void compute_bow(const Vocabulary& vocabulary, int direct_index_level);
  bool has_bow() const { return has_bow_; }
  const BowVector& bow_vector() const { return bow_; }
  const FeatureVector& feature_vector() const { return features_; }

  // Association of keypoint i with a map point (nullptr: none) and its outlier flag.
  std::vector<std::shared_ptr<MapPoint>> map_points;
  std::vector<std::uint8_t> outlier;

 private:
  std::uint64_t id_;
  Timestamp timestamp_;
  std::vector<cv::KeyPoint> keypoints_;
  cv::Mat descriptors_;
  std::vector<float> depth_;
  std::vector<float> right_u_;
  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  FeatureGrid grid_;
  std::optional<Pose> T_camera_world_;
  bool has_bow_ = false;
  BowVector bow_;
  FeatureVector features_;
};

}  // namespace pspslam
