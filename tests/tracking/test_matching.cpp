#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/match/orb_matcher.h"

namespace pspslam {
namespace {

// A synthetic scene: 300 points with known random descriptors, observed by a keyframe at the
// origin, then searched in a frame whose camera moved 5 cm / 2 degrees. The frame's keypoints
// are the projections (with 0.5 px noise and 0-3 flipped descriptor bits) plus 300 distractor
// keypoints with unrelated descriptors.
class ProjectionSearchTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> xy(-0.45, 0.45);
    std::uniform_real_distribution<double> z(1.0, 3.5);
    std::uniform_int_distribution<int> byte(0, 255);
    for (int i = 0; i < kPoints; ++i) {
      const double depth = z(rng);
      positions_.emplace_back(xy(rng) * depth * 1.1, xy(rng) * depth * 0.8, depth);
      OrbDescriptor d;
      for (auto& b : d) b = static_cast<std::uint8_t>(byte(rng));
      descriptors_.push_back(d);
    }
    // Keyframe at the origin that observes every point (level 0, with depth).
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors(kPoints, 32, CV_8U);
    cv::Mat depth(480, 640, CV_32F, cv::Scalar(0));
    for (int i = 0; i < kPoints; ++i) {
      const Eigen::Vector2d pixel = camera_->pinhole.project(positions_[i]);
      keypoints.emplace_back(cv::Point2f(pixel.x(), pixel.y()), 31.0f, 0.0f);
      depth.at<float>(cvRound(pixel.y()), cvRound(pixel.x())) =
          static_cast<float>(positions_[i].z());
      std::memcpy(descriptors.ptr(i), descriptors_[i].data(), 32);
    }
    Frame first(0, 0.0, keypoints, descriptors, depth, camera_, pyramid_);
    first.set_pose(Pose::Identity());
    keyframe_ = std::make_shared<KeyFrame>(map_.next_keyframe_id(), first);
    map_.add_keyframe(keyframe_);
    for (int i = 0; i < kPoints; ++i) {
      auto point = std::make_shared<MapPoint>(map_.next_map_point_id(), positions_[i], keyframe_);
      point->add_observation(keyframe_, i);
      keyframe_->add_map_point(i, point);
      point->compute_distinctive_descriptor();
      point->update_normal_and_depth(*pyramid_);
      map_.add_map_point(point);
      points_.push_back(point);
    }

    T_camera_world_ = Pose::Identity();
    T_camera_world_.linear() =
        Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T_camera_world_.translation() = Eigen::Vector3d(0.05, -0.01, 0.02);
    std::normal_distribution<double> noise(0.0, 0.5);
    std::uniform_int_distribution<int> flips(0, 3);
    std::uniform_int_distribution<int> bit(0, 255);
    std::uniform_real_distribution<float> u(0.0f, 640.0f);
    std::uniform_real_distribution<float> v(0.0f, 480.0f);
    std::vector<cv::KeyPoint> current;
    std::vector<OrbDescriptor> current_descriptors;
    for (int i = 0; i < kPoints; ++i) {
      const Eigen::Vector3d p = T_camera_world_ * positions_[i];
      const Eigen::Vector2d pixel = camera_->pinhole.project(p);
      if (!camera_->in_bounds(pixel.x(), pixel.y())) continue;
      current.emplace_back(cv::Point2f(pixel.x() + noise(rng), pixel.y() + noise(rng)), 31.0f,
                           0.0f);
      OrbDescriptor d = descriptors_[i];
      for (int f = flips(rng); f > 0; --f) {
        const int b = bit(rng);
        d[b / 8] ^= static_cast<std::uint8_t>(1u << (b % 8));
      }
      current_descriptors.push_back(d);
      truth_.push_back(i);
    }
    for (int k = 0; k < kPoints; ++k) {
      current.emplace_back(cv::Point2f(u(rng), v(rng)), 31.0f, 0.0f);
      OrbDescriptor d;
      for (auto& b : d) b = static_cast<std::uint8_t>(byte(rng));
      current_descriptors.push_back(d);
      truth_.push_back(-1);
    }
    cv::Mat current_mat(static_cast<int>(current.size()), 32, CV_8U);
    for (size_t i = 0; i < current.size(); ++i) {
      std::memcpy(current_mat.ptr(static_cast<int>(i)), current_descriptors[i].data(), 32);
    }
    frame_.emplace(1, 0.033, current, current_mat, cv::Mat(), camera_, pyramid_);
  }

  static constexpr int kPoints = 300;
  std::shared_ptr<const CameraModel> camera_ =
      std::make_shared<const CameraModel>(CameraModel::from_config(CameraConfig{}, 0.08));
  std::shared_ptr<const ScalePyramid> pyramid_ =
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  Map map_;
  std::vector<Eigen::Vector3d> positions_;
  std::vector<OrbDescriptor> descriptors_;
  std::shared_ptr<KeyFrame> keyframe_;
  std::vector<std::shared_ptr<MapPoint>> points_;
  Pose T_camera_world_;
  std::optional<Frame> frame_;
  std::vector<int> truth_;  // per frame keypoint: index of its point, -1 = distractor
};

TEST_F(ProjectionSearchTest, FindsTheRightMatchesWithKnownPose) {
  Frame& frame = *frame_;
  frame.set_pose(T_camera_world_);
  std::vector<ProjectedPoint> projected;
  for (const auto& point : points_) {
    ProjectedPoint p;
    if (project_map_point(point, frame, p)) projected.push_back(p);
  }
  const int visible =
      static_cast<int>(std::count_if(truth_.begin(), truth_.end(), [](int t) { return t >= 0; }));
  EXPECT_EQ(static_cast<int>(projected.size()), visible);
  const int matches = search_by_projection(frame, projected, 1.0);
  int correct = 0;
  int wrong = 0;
  for (int i = 0; i < frame.size(); ++i) {
    if (!frame.map_points[i]) continue;
    if (truth_[i] >= 0 && frame.map_points[i] == points_[truth_[i]]) {
      ++correct;
    } else {
      ++wrong;
    }
  }
  EXPECT_EQ(correct + wrong, matches);
  EXPECT_EQ(wrong, 0);
  EXPECT_GE(correct, visible * 95 / 100) << "visible " << visible;
}

TEST_F(ProjectionSearchTest, BruteForceAgainstKeyFrameNeedsNoPose) {
  Frame& frame = *frame_;
  const int matches = search_keyframe_brute_force(frame, *keyframe_);
  int correct = 0;
  for (int i = 0; i < frame.size(); ++i) {
    if (frame.map_points[i] && truth_[i] >= 0 && frame.map_points[i] == points_[truth_[i]]) {
      ++correct;
    }
  }
  const int visible =
      static_cast<int>(std::count_if(truth_.begin(), truth_.end(), [](int t) { return t >= 0; }));
  EXPECT_EQ(correct, matches);
  EXPECT_GE(correct, visible * 95 / 100);
}

TEST(RotationHistogram, KeepsTheDominantRotation) {
  RotationHistogram histogram;
  // 40 matches rotated by ~10 degrees, 5 by ~12, and 3 random outliers at 100-200 degrees.
  for (int m = 0; m < 40; ++m) histogram.add(20.0f, 10.0f, m);
  for (int m = 40; m < 45; ++m) histogram.add(22.0f, 10.0f, m);
  histogram.add(150.0f, 10.0f, 45);
  histogram.add(250.0f, 10.0f, 46);
  histogram.add(300.0f, 95.0f, 47);
  std::vector<int> rejected = histogram.rejected();
  std::sort(rejected.begin(), rejected.end());
  EXPECT_EQ(rejected, (std::vector<int>{45, 46, 47}));
}

}  // namespace
}  // namespace pspslam
