#include <gtest/gtest.h>

#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

// Keyframes of a few keypoints, made in the map's active map as tracking makes them.
class AtlasTest : public ::testing::Test {
 protected:
  std::shared_ptr<KeyFrame> make_keyframe() {
    std::vector<cv::KeyPoint> keypoints;
    for (int i = 0; i < 20; ++i) keypoints.emplace_back(cv::Point2f(10.0f * i, 100.0f), 31.0f);
    cv::Mat descriptors(20, 32, CV_8U, cv::Scalar(0));
    Frame frame(0, 0.0, keypoints, descriptors, cv::Mat(), camera_, pyramid_);
    frame.set_pose(Pose::Identity());
    auto keyframe = std::make_shared<KeyFrame>(map_.next_keyframe_id(), frame);
    keyframe->set_map(map_.active_map(), false);
    map_.add_keyframe(keyframe);
    return keyframe;
  }

  std::shared_ptr<MapPoint> observe(const std::shared_ptr<KeyFrame>& keyframe, int index) {
    auto point =
        std::make_shared<MapPoint>(map_.next_map_point_id(), Eigen::Vector3d(0, 0, 2), keyframe);
    point->add_observation(keyframe, index);
    keyframe->add_map_point(index, point);
    map_.add_map_point(point);
    return point;
  }

  std::shared_ptr<const CameraModel> camera_ =
      std::make_shared<const CameraModel>(CameraModel::from_config(CameraConfig{}, 0.08));
  std::shared_ptr<const ScalePyramid> pyramid_ =
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(OrbConfig{}));
  Map map_;
};

TEST_F(AtlasTest, EachMapsFirstKeyframeAnchorsItAndIsNeverMadeBad) {
  const auto first = make_keyframe();
  const auto second = make_keyframe();
  EXPECT_EQ(map_.open_new_map(), 1u);
  EXPECT_EQ(map_.active_map(), 1u);
  const auto third = make_keyframe();
  const auto fourth = make_keyframe();
  EXPECT_TRUE(first->is_anchor());
  EXPECT_FALSE(second->is_anchor());
  EXPECT_TRUE(third->is_anchor());
  EXPECT_FALSE(fourth->is_anchor());
  EXPECT_EQ(third->map_id(), 1u);
  EXPECT_EQ(map_.num_keyframes_in(0), 2u);
  EXPECT_EQ(map_.num_keyframes_in(1), 2u);
  EXPECT_EQ(map_.map_ids(), (std::vector<std::uint32_t>{0, 1}));

  map_.erase_keyframe(third);  // the anchor refuses
  EXPECT_FALSE(third->is_bad());
  map_.erase_keyframe(fourth);
  EXPECT_TRUE(fourth->is_bad());
  EXPECT_EQ(map_.num_keyframes_in(1), 1u);
}

TEST_F(AtlasTest, AKeyframeAddedAgainCountsOnce) {
  const auto keyframe = make_keyframe();
  map_.add_keyframe(keyframe);  // local mapping adds what tracking added
  EXPECT_EQ(map_.num_keyframes_in(0), 1u);
  make_keyframe();
  EXPECT_EQ(map_.num_keyframes_in(0), 2u);
  EXPECT_TRUE(keyframe->is_anchor());
}

TEST_F(AtlasTest, AnOpenedMapKeepsItsIdUntilItHoldsAKeyframe) {
  make_keyframe();
  EXPECT_EQ(map_.open_new_map(), 1u);
  map_.set_active_map(0);  // relocalised in map 0 instead
  EXPECT_EQ(map_.open_new_map(), 1u);
  make_keyframe();
  EXPECT_EQ(map_.open_new_map(), 2u);
}

TEST_F(AtlasTest, AMergeRelabelsTheMapAndTheAnchorOfTheMapBroughtInStopsAnchoring) {
  const auto a = make_keyframe();
  map_.open_new_map();
  const auto b_anchor = make_keyframe();
  const auto b = make_keyframe();
  map_.open_new_map();
  const auto c = make_keyframe();
  map_.set_active_map(1);
  map_.merge_map({.from = 1, .into = 0, .current_keyframe = b->id(), .matched_keyframe = a->id()});
  EXPECT_EQ(b_anchor->map_id(), 0u);
  EXPECT_EQ(b->map_id(), 0u);
  EXPECT_FALSE(b_anchor->is_anchor());
  EXPECT_TRUE(a->is_anchor());
  EXPECT_EQ(map_.active_map(), 0u);
  EXPECT_EQ(map_.num_keyframes_in(0), 3u);
  EXPECT_EQ(map_.num_keyframes_in(1), 0u);
  EXPECT_EQ(map_.map_ids(), (std::vector<std::uint32_t>{0, 2}));
  // A chain of merges resolves in order.
  map_.merge_map({.from = 0, .into = 2, .current_keyframe = a->id(), .matched_keyframe = c->id()});
  EXPECT_EQ(map_.current_map_of(1), 2u);
  EXPECT_EQ(map_.current_map_of(0), 2u);
  EXPECT_EQ(map_.current_map_of(2), 2u);
  ASSERT_EQ(map_.merges().size(), 2u);
  EXPECT_EQ(map_.merges()[0].current_keyframe, b->id());
}

TEST_F(AtlasTest, ErasingAFailedStartLeavesTheOtherMapsAndReusesItsId) {
  const auto kept = make_keyframe();
  const auto kept_point = observe(kept, 0);
  map_.open_new_map();
  const auto failed = make_keyframe();
  const auto failed_point = observe(failed, 1);
  map_.erase_map(1);
  EXPECT_EQ(map_.num_keyframes(), 1u);
  EXPECT_EQ(map_.num_map_points(), 1u);
  EXPECT_TRUE(failed->is_bad());
  EXPECT_TRUE(failed_point->is_bad());
  EXPECT_FALSE(kept_point->is_bad());
  EXPECT_EQ(map_.map_ids(), (std::vector<std::uint32_t>{0}));
  EXPECT_EQ(map_.open_new_map(), 1u);
}

}  // namespace
}  // namespace pspslam
