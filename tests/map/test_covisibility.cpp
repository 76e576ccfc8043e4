#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

// Keyframes of 60 keypoints without depth (every observation counts once).
class CovisibilityTest : public ::testing::Test {
 protected:
  std::shared_ptr<KeyFrame> make_keyframe(std::uint64_t frame_id) {
    std::vector<cv::KeyPoint> keypoints;
    for (int i = 0; i < 60; ++i) keypoints.emplace_back(cv::Point2f(10.0f * i, 100.0f), 31.0f);
    cv::Mat descriptors(60, 32, CV_8U);
    cv::randu(descriptors, 0, 256);
    Frame frame(frame_id, static_cast<double>(frame_id), keypoints, descriptors, cv::Mat(), camera_,
                pyramid_);
    frame.set_pose(Pose::Identity());
    auto keyframe = std::make_shared<KeyFrame>(map_.next_keyframe_id(), frame);
    map_.add_keyframe(keyframe);
    return keyframe;
  }

  // `count` new points seen by keyframe a at indices [a_first, ...) and b at [b_first, ...).
  std::vector<std::shared_ptr<MapPoint>> share(const std::shared_ptr<KeyFrame>& a, int a_first,
                                               const std::shared_ptr<KeyFrame>& b, int b_first,
                                               int count) {
    std::vector<std::shared_ptr<MapPoint>> points;
    for (int k = 0; k < count; ++k) {
      auto point =
          std::make_shared<MapPoint>(map_.next_map_point_id(), Eigen::Vector3d(k, 0.0, 3.0), a);
      point->add_observation(a, a_first + k);
      point->add_observation(b, b_first + k);
      a->add_map_point(a_first + k, point);
      b->add_map_point(b_first + k, point);
      map_.add_map_point(point);
      points.push_back(point);
    }
    return points;
  }

  std::shared_ptr<const CameraModel> camera_ =
      std::make_shared<const CameraModel>(CameraModel::from_config(CameraConfig{}, 0.08));
  std::shared_ptr<const ScalePyramid> pyramid_ =
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  Map map_;
};

TEST_F(CovisibilityTest, WeightsOrderAndSpanningTree) {
  auto kf0 = make_keyframe(0);
  auto kf1 = make_keyframe(10);
  auto kf2 = make_keyframe(20);
  const auto a = share(kf0, 0, kf1, 0, 20);   // kf0-kf1: 20 shared points
  const auto b = share(kf1, 20, kf2, 0, 16);  // kf1-kf2: 16
  const auto c = share(kf0, 20, kf2, 16, 5);  // kf0-kf2: 5 (below the edge threshold of 15)
  kf0->update_connections();
  kf1->update_connections();
  kf2->update_connections();

  EXPECT_EQ(kf0->weight(kf1->id()), 20);
  EXPECT_EQ(kf1->weight(kf0->id()), 20);
  EXPECT_EQ(kf1->weight(kf2->id()), 16);
  EXPECT_EQ(kf2->weight(kf1->id()), 16);
  EXPECT_EQ(kf0->weight(kf2->id()), 0);
  EXPECT_EQ(kf2->weight(kf0->id()), 0);

  const auto ordered = kf1->covisibles();
  ASSERT_EQ(ordered.size(), 2u);
  EXPECT_EQ(ordered[0]->id(), kf0->id());
  EXPECT_EQ(ordered[1]->id(), kf2->id());
  EXPECT_EQ(kf1->best_covisibles(1).size(), 1u);
  EXPECT_EQ(kf1->covisibles_with_min_weight(17).size(), 1u);

  EXPECT_EQ(kf0->parent(), nullptr);
  EXPECT_EQ(kf1->parent(), kf0);
  EXPECT_EQ(kf2->parent(), kf1);
  ASSERT_EQ(kf0->children().size(), 1u);
  EXPECT_EQ(kf0->children()[0], kf1);
  EXPECT_EQ(a[0]->num_observations(), 2);
  EXPECT_EQ(kf0->tracked_map_points(2), 25);
}

TEST_F(CovisibilityTest, RemovingAKeyFrameReparentsChildrenAndDropsObservations) {
  auto kf0 = make_keyframe(0);
  auto kf1 = make_keyframe(10);
  auto kf2 = make_keyframe(20);
  const auto a = share(kf0, 0, kf1, 0, 20);
  const auto b = share(kf1, 20, kf2, 0, 16);
  const auto c = share(kf0, 20, kf2, 16, 5);
  for (const auto& kf : {kf0, kf1, kf2}) kf->update_connections();

  map_.erase_keyframe(kf1);
  EXPECT_TRUE(kf1->is_bad());
  EXPECT_EQ(map_.num_keyframes(), 2u);
  EXPECT_EQ(map_.keyframe(kf1->id()), nullptr);
  EXPECT_EQ(kf2->parent(), kf0);
  EXPECT_EQ(kf0->weight(kf1->id()), 0);
  EXPECT_EQ(kf2->weight(kf1->id()), 0);
  // Points seen by kf1 and one other keyframe are left with a single view: bad, detached.
  EXPECT_TRUE(a[0]->is_bad());
  EXPECT_TRUE(b[0]->is_bad());
  EXPECT_EQ(kf0->map_point(0), nullptr);
  EXPECT_EQ(kf2->map_point(0), nullptr);
  EXPECT_FALSE(c[0]->is_bad());
  EXPECT_EQ(kf0->map_point(20), c[0]);

  // The first keyframe anchors the map and is never removed.
  map_.erase_keyframe(kf0);
  EXPECT_FALSE(kf0->is_bad());
  EXPECT_EQ(map_.num_keyframes(), 2u);
}

TEST_F(CovisibilityTest, ReplacingAPointMovesObservations) {
  auto kf0 = make_keyframe(0);
  auto kf1 = make_keyframe(10);
  auto kf2 = make_keyframe(20);
  const auto a = share(kf0, 0, kf1, 0, 1);
  const auto b = share(kf1, 5, kf2, 5, 1);
  ASSERT_TRUE(a[0]->replace_with(b[0]));
  EXPECT_TRUE(a[0]->is_bad());
  EXPECT_EQ(a[0]->replaced_by(), b[0]);
  EXPECT_EQ(b[0]->keypoint_index_in(kf0->id()), 0);
  EXPECT_EQ(kf0->map_point(0), b[0]);
  // kf1 already saw b at index 5: its slot for a is cleared instead of duplicated.
  EXPECT_EQ(kf1->map_point(0), nullptr);
  EXPECT_EQ(b[0]->num_observations(), 3);
}

// A point that loses its second observation turns bad inside MapPoint::erase_observation; nothing
// on that path can reach the Map, so the Map must sweep it.
TEST_F(CovisibilityTest, PointsThatTurnBadAreSweptFromTheMap) {
  auto kf0 = make_keyframe(0);
  auto kf1 = make_keyframe(10);
  const auto points = share(kf0, 0, kf1, 0, 4);  // two observations without depth each
  ASSERT_EQ(map_.num_map_points(), 4u);
  kf1->erase_map_point(0);
  EXPECT_TRUE(points[0]->erase_observation(kf1->id()));  // one observation left: bad
  EXPECT_TRUE(points[0]->is_bad());
  EXPECT_EQ(kf0->map_point(0), nullptr);  // set_bad detached it from kf0 too
  EXPECT_EQ(map_.num_map_points(), 4u);   // ...but the Map still owns it
  EXPECT_EQ(map_.erase_bad_map_points(), 1u);
  EXPECT_EQ(map_.num_map_points(), 3u);
  for (const auto& point : map_.map_points()) EXPECT_FALSE(point->is_bad());
  EXPECT_EQ(map_.erase_bad_map_points(), 0u);
}

// A close point near the left border has a negative virtual right coordinate u − bf/z; it still
// has depth: "no depth" is a NaN right coordinate, not a negative one.
TEST_F(CovisibilityTest, NegativeRightCoordinateStillCountsAsDepth) {
  const std::vector<cv::KeyPoint> keypoints = {cv::KeyPoint(cv::Point2f(5.0f, 100.0f), 31.0f),
                                               cv::KeyPoint(cv::Point2f(300.0f, 100.0f), 31.0f)};
  cv::Mat descriptors(2, 32, CV_8U, cv::Scalar(0));
  cv::Mat depth(480, 640, CV_32F, cv::Scalar(0.5f));
  depth.at<float>(100, 300) = 0.0f;  // no reading at the second keypoint
  Frame frame(0, 0.0, keypoints, descriptors, depth, camera_, pyramid_);
  ASSERT_TRUE(frame.has_depth(0));
  EXPECT_NEAR(frame.right_u(0), 5.0 - camera_->bf / 0.5, 1e-3);
  EXPECT_LT(frame.right_u(0), 0.0f);
  EXPECT_FALSE(frame.has_depth(1));
  EXPECT_TRUE(std::isnan(frame.right_u(1)));

  frame.set_pose(Pose::Identity());
  auto keyframe = std::make_shared<KeyFrame>(map_.next_keyframe_id(), frame);
  auto with_depth = std::make_shared<MapPoint>(0, frame.unproject_world(0), keyframe);
  with_depth->add_observation(keyframe, 0);
  EXPECT_EQ(with_depth->num_observations(), 2);  // a depth observation counts twice
  auto without_depth = std::make_shared<MapPoint>(1, Eigen::Vector3d(0.0, 0.0, 2.0), keyframe);
  without_depth->add_observation(keyframe, 1);
  EXPECT_EQ(without_depth->num_observations(), 1);
}

}  // namespace
}  // namespace pspslam
