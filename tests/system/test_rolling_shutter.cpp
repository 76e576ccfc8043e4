#include <gtest/gtest.h>

#include <cstdio>

#include "pspslam/eval/ate.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/synth/scene.h"
#include "pspslam/system/system.h"

namespace pspslam {
namespace {

// The Kinect-faults renderer with only its rolling shutter (30 ms readout) on: the camera's
// config carries the readout, as `pspslam synth --sensor kinect` writes it.
SynthOptions rolling_shutter_room() {
  SynthOptions options;
  options.frames = 150;
  options.bodies = 0;
  options.seed = 1;
  options.threads = 1;
  options.sensor = SynthSensor::kKinect;
  for (const std::string& fault : synth::KinectFaults::names()) {
    options.faults.set(fault, fault == "rolling-shutter" || fault == "handheld-motion");
  }
  return options;
}

double online_ate(const SyntheticScene& scene, const SystemConfig& config) {
  SystemOptions options;
  options.place.loop_closing = false;
  options.back_end_wait = BackEndWait::whole_back_end;
  System system(config, options);
  Trajectory estimate;
  SynthFrame rendered;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    scene.render(i, rendered, 1);
    InputFrame frame;
    frame.index = i;
    frame.timestamp = scene.timestamp(i);
    frame.bgr = rendered.bgr;
    frame.depth = rendered.depth_sensor;
    const FrameReport report = system.process(frame);
    EXPECT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i << " lost";
    if (report.tracking.T_world_camera) {
      estimate.push_back({frame.timestamp, *report.tracking.T_world_camera});
    }
  }
  system.shutdown();
  return compute_ate(scene.ground_truth(), estimate).error.rmse;
}

// Tracking that knows the readout moves each keypoint to the frame's instant with the rotation
// rate it measures per frame (camera/rolling_shutter.h, optimize/rolling_shutter_pose.h); one that
// takes the camera for a global shutter fits every frame with a skewed image.
TEST(RollingShutterSystem, KnowingTheReadoutRemovesTheSkewsError) {
  const SyntheticScene scene(rolling_shutter_room());
  SystemConfig config = scene.system_config();
  ASSERT_DOUBLE_EQ(config.camera.rolling_shutter_readout_s, 0.030);
  const double corrected = online_ate(scene, config);
  config.camera.rolling_shutter_readout_s = 0.0;
  const double global_shutter = online_ate(scene, config);
  std::printf("online ATE: %.2f mm with the readout, %.2f mm taken for a global shutter\n",
              corrected * 1e3, global_shutter * 1e3);
  EXPECT_LT(corrected, 0.6 * global_shutter);
  EXPECT_LT(corrected, 0.004);
}

}  // namespace
}  // namespace pspslam
