#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <optional>
#include <string>
#include <vector>

#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "pspslam/system/system.h"
#include "support/input_frames.h"

namespace pspslam {
namespace {

constexpr double kTimeStep = 1.0 / 30.0;

// Feeds a System rendered frames of a static synthetic room, black frames, or earlier frames
// again (a "kidnapped" camera), with strictly increasing timestamps, and records per frame
// whether it was tracked, how, and its position error. The estimate's world frame is the first
// camera, so the ground truth is re-expressed in it (no alignment that could hide an offset).
class Feeder {
 public:
  Feeder(const SyntheticScene& scene, SystemOptions options)
      : scene_(scene), system_(synthetic_system_config(), std::move(options)) {}

  struct Step {
    bool tracked = false;
    TrackingMethod method = TrackingMethod::kNone;
    double error_m = 0.0;
  };

  Step feed(std::optional<size_t> scene_index) {
    cv::Mat gray;
    cv::Mat depth;
    if (scene_index) {
      scene_.render(*scene_index, frame_, 1);
      cv::cvtColor(frame_.bgr, gray, cv::COLOR_BGR2GRAY);
      depth = frame_.depth_sensor;
    } else {
      // The camera sees nothing: no features, no depth, so tracking is lost for real.
      gray = cv::Mat::zeros(480, 640, CV_8UC1);
      depth = cv::Mat::zeros(480, 640, CV_32FC1);
    }
    const FrameReport report = system_.process(
        grey_depth_frame(1e6 + kTimeStep * static_cast<double>(fed_++), gray, depth));
    Step step;
    step.tracked = report.tracking.T_world_camera.has_value();
    step.method = report.tracking.method;
    if (step.tracked && scene_index) {
      if (!T_first_world_) T_first_world_ = frame_.T_world_camera.inverse();
      const Pose expected = *T_first_world_ * frame_.T_world_camera;
      step.error_m =
          (expected.translation() - report.tracking.T_world_camera->translation()).norm();
    }
    return step;
  }

  System& system() { return system_; }

 private:
  const SyntheticScene& scene_;
  System system_;
  SynthFrame frame_;
  size_t fed_ = 0;
  std::optional<Pose> T_first_world_;
};

SyntheticScene exact_depth_room() {
  SynthOptions options;
  options.frames = 120;
  options.bodies = 0;
  options.seed = 1;
  options.threads = 1;
  // Exact depth keeps tracking drift at millimetres, so the check measures relocalisation.
  options.depth_noise = false;
  return SyntheticScene(options);
}

// 30 black frames, then the system relocalises within 5 frames of the
// return and the poses after it are within 2 cm of ground truth. Then a second blackout after
// which the camera is back where it was 1.5 s earlier (kidnapped), to be found through the
// keyframe database among all keyframes.
TEST(Relocalisation, RecoversAfterThirtyBlackFramesAndAfterAKidnapping) {
  const SyntheticScene scene = exact_depth_room();
  Feeder feeder(scene, SystemOptions{});
  for (size_t i = 0; i < 60; ++i) {
    ASSERT_TRUE(feeder.feed(i).tracked) << "frame " << i << " lost before the blackout";
  }
  for (int k = 0; k < 30; ++k) {
    const auto step = feeder.feed(std::nullopt);
    ASSERT_FALSE(step.tracked) << "black frame " << k << " got a pose";
  }

  // Return: the scene continues at frame 90 (the camera moved on during the blackout).
  std::optional<int> relocalised_after;
  double max_error = 0.0;
  for (size_t i = 90; i < 120; ++i) {
    const auto step = feeder.feed(i);
    if (!relocalised_after && step.tracked) {
      relocalised_after = static_cast<int>(i - 90);
      EXPECT_EQ(step.method, TrackingMethod::kRelocalisation) << to_string(step.method);
    }
    if (relocalised_after) {
      EXPECT_TRUE(step.tracked) << "frame " << i << " lost again after relocalisation";
      if (step.tracked) max_error = std::max(max_error, step.error_m);
    }
  }
  ASSERT_TRUE(relocalised_after.has_value()) << "never relocalised after the blackout";
  EXPECT_LE(*relocalised_after, 5);
  EXPECT_LT(max_error, 0.02) << "worst position error after the return";

  // Kidnapped: black again, then the camera is back at frames 15..44.
  for (int k = 0; k < 30; ++k) ASSERT_FALSE(feeder.feed(std::nullopt).tracked);
  relocalised_after.reset();
  max_error = 0.0;
  for (size_t i = 15; i < 45; ++i) {
    const auto step = feeder.feed(i);
    if (!relocalised_after && step.tracked) {
      relocalised_after = static_cast<int>(i - 15);
      EXPECT_EQ(step.method, TrackingMethod::kRelocalisation) << to_string(step.method);
    }
    if (relocalised_after && step.tracked) max_error = std::max(max_error, step.error_m);
  }
  ASSERT_TRUE(relocalised_after.has_value()) << "never relocalised after the kidnapping";
  EXPECT_LE(*relocalised_after, 5);
  EXPECT_LT(max_error, 0.02) << "worst position error after the kidnapping";
}

}  // namespace
}  // namespace pspslam
