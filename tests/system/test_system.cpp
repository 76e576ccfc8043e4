#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pspslam/eval/ate.h"
#include "pspslam/synth/scene.h"
#include "pspslam/system/system.h"

namespace pspslam {
namespace {

SynthOptions static_room(size_t frames) {
  SynthOptions options;
  options.frames = frames;
  options.bodies = 0;
  options.seed = 1;
  options.threads = 1;
  return options;
}

TEST(System, TracksAShortStaticSyntheticSequenceWithinOneCentimetre) {
  const SyntheticScene scene(static_room(60));
  System system(synthetic_system_config());
  Trajectory estimate;
  SynthFrame frame;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    scene.render(i, frame, 1);
    const FrameReport report = system.track(
        scene.timestamp(i),
        [&] {
          cv::Mat gray;
          cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
          return gray;
        }(),
        frame.depth_sensor);
    ASSERT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i << " lost";
    estimate.push_back({scene.timestamp(i), *report.tracking.T_world_camera});
  }
  system.shutdown();
  const AteResult ate = compute_ate(scene.ground_truth(), estimate);
  EXPECT_EQ(ate.error.count, 60u);
  EXPECT_LT(ate.error.rmse, 0.01);
  EXPECT_GE(system.keyframe_trajectory().size(), 1u);
}

TEST(System, ABlackFrameIsReportedLostWithoutAPoseAndTrackingResumes) {
  const SyntheticScene scene(static_room(40));
  System system(synthetic_system_config());
  SynthFrame frame;
  Trajectory estimate;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    scene.render(i, frame, 1);
    cv::Mat gray;
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    cv::Mat depth = frame.depth_sensor;
    if (i == 20) {
      gray.setTo(0);
      depth = cv::Mat::zeros(depth.size(), CV_32F);
    }
    const FrameReport report = system.track(scene.timestamp(i), gray, depth);
    if (i == 20) {
      EXPECT_EQ(report.tracking.state, TrackingState::kLost);
      EXPECT_FALSE(report.tracking.T_world_camera.has_value());
      EXPECT_EQ(report.tracking.num_keypoints, 0);
    } else if (i > 21) {
      ASSERT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i;
      estimate.push_back({scene.timestamp(i), *report.tracking.T_world_camera});
    }
  }
  system.shutdown();
  // Poses after recovery are in the same world frame as before (no new map was started).
  const AteResult ate = compute_ate(scene.ground_truth(), estimate);
  EXPECT_LT(ate.error.rmse, 0.01);
}

}  // namespace
}  // namespace pspslam
