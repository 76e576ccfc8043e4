// The tracker on its own: Frames built by the RGB-D frame builder from synthetic renders, no
// System and no threads; keyframes go to a sink that keeps them, where local mapping would be.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <memory>
#include <vector>

#include "pspslam/eval/ate.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/synth/scene.h"
#include "pspslam/system/frame_builder.h"
#include "pspslam/tracking/keyframe_sink.h"
#include "pspslam/tracking/tracker.h"
#include "support/input_frames.h"

namespace pspslam {
namespace {

class KeptKeyFrames final : public KeyFrameSink {
 public:
  void insert_keyframe(std::shared_ptr<KeyFrame> keyframe) override {
    keyframes.push_back(std::move(keyframe));
  }
  bool accepts_keyframes() const override { return true; }
  size_t queued_keyframes() const override { return 0; }
  void interrupt_bundle_adjustment() override {}

  std::vector<std::shared_ptr<KeyFrame>> keyframes;
};

// A tracker and what it needs, for a synthetic RGB-D sequence.
struct TrackerRig {
  explicit TrackerRig(const SyntheticScene& scene)
      : config(synthetic_system_config()),
        camera(std::make_shared<const CameraModel>(CameraModel::from_config(config.camera, 0.08))),
        pyramid(std::make_shared<const ScalePyramid>(
            ScalePyramid::from_config(read_orb_config(config.orb)))),
        builder(make_frame_builder(config, camera, pyramid, false)),
        tracker(map, &sink, {}, nullptr, builder->make_map_initializer({})),
        scene_(scene) {}

  // Frame `index` through the tracker; `mask` (non-zero = no features there) may be empty.
  TrackResult track(size_t index, bool mask_people) {
    scene_.render(index, rendered_, 1);
    cv::Mat gray;
    cv::cvtColor(rendered_.bgr, gray, cv::COLOR_BGR2GRAY);
    const InputFrame input =
        grey_depth_frame(scene_.timestamp(index), gray, rendered_.depth_sensor);
    const cv::Mat mask = mask_people ? cv::Mat(rendered_.labels != kSynthLabelStatic) : cv::Mat();
    OrbFeatures features;
    builder->extract(input, gray, mask, features);
    return tracker.track(
        builder->build(index, input, std::move(features), {}, tracker.angular_velocity()));
  }

  SystemConfig config;
  std::shared_ptr<const CameraModel> camera;
  std::shared_ptr<const ScalePyramid> pyramid;
  std::unique_ptr<FrameBuilder> builder;
  Map map;
  KeptKeyFrames sink;
  Tracker tracker;

 private:
  const SyntheticScene& scene_;
  SynthFrame rendered_;
};

SynthOptions room(size_t frames, int bodies) {
  SynthOptions options;
  options.frames = frames;
  options.bodies = bodies;
  options.seed = 3;
  options.threads = 1;
  return options;
}

TEST(Tracker, StartsTheMapThenFollowsTheMotionModelWithinACentimetre) {
  const SyntheticScene scene(room(45, 0));
  TrackerRig rig(scene);
  Trajectory estimate;
  size_t motion_model_frames = 0;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const TrackResult result = rig.track(i, false);
    ASSERT_EQ(result.state, TrackingState::kOk) << "frame " << i;
    ASSERT_TRUE(result.T_world_camera.has_value()) << "frame " << i;
    if (i == 0) {
      EXPECT_EQ(result.method, TrackingMethod::kInitialization);
    }
    if (result.method == TrackingMethod::kMotionModel) ++motion_model_frames;
    estimate.push_back({scene.timestamp(i), *result.T_world_camera});
  }
  // Every frame after the first has the previous two to predict from.
  EXPECT_GE(motion_model_frames, scene.frame_count() - 2);
  const AteResult ate = compute_ate(scene.ground_truth(), estimate);
  EXPECT_EQ(ate.error.count, scene.frame_count());
  EXPECT_LT(ate.error.rmse, 0.01);
  // The first keyframe starts the map; the policy asks for more as the camera moves (at least
  // once a second at 30 Hz), and each one the sink got is in the map.
  ASSERT_GE(rig.sink.keyframes.size(), 2u);
  for (const auto& keyframe : rig.sink.keyframes)
    EXPECT_NE(rig.map.keyframe(keyframe->id()), nullptr) << "keyframe " << keyframe->id();
  EXPECT_GT(rig.map.num_map_points(), 500u);
}

// With the people's pixels kept from extraction, as the dynamic pipeline does, nothing the
// tracker sees moves: it stays as accurate as in the empty room.
TEST(Tracker, TracksAmongWalkingPeopleWhenTheirPixelsAreMasked) {
  const SyntheticScene scene(room(45, 3));
  TrackerRig rig(scene);
  Trajectory estimate;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const TrackResult result = rig.track(i, true);
    ASSERT_TRUE(result.T_world_camera.has_value()) << "frame " << i;
    estimate.push_back({scene.timestamp(i), *result.T_world_camera});
  }
  EXPECT_LT(compute_ate(scene.ground_truth(), estimate).error.rmse, 0.01);
}

}  // namespace
}  // namespace pspslam
