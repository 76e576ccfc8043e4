#include <gtest/gtest.h>

#include "support/test_support.h"

#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "pspslam/core/shared_paths.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
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

namespace pspslam {
namespace {

int count_pose_lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  int lines = 0;
  for (std::string line; std::getline(in, line);) lines += !line.empty() && line[0] != '#';
  return lines;
}

TEST(RunCommand, WritesEveryOutputForASyntheticSequence) {
  const std::filesystem::path dir = testing::make_temp_dir("run_cli");
  SynthOptions options = static_room(30);
  write_sequence(options, dir / "sequence");
  std::string output;
  const int status =
      testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --sequence " +
                             (dir / "sequence").string() + " --out " + (dir / "out").string(),
                         &output);
  ASSERT_EQ(status, 0) << output;
  EXPECT_EQ(count_pose_lines(dir / "out" / "trajectory.txt"), 30);
  EXPECT_EQ(count_pose_lines(dir / "out" / "trajectory_refined.txt"), 30);
  EXPECT_EQ(count_pose_lines(dir / "out" / "lost_frames.txt"), 0);
  EXPECT_GE(count_pose_lines(dir / "out" / "keyframes.txt"), 1);
  EXPECT_EQ(count_pose_lines(dir / "out" / "timing.csv"), 31);  // header + one row per frame
  EXPECT_NE(output.find("30 processed, 30 tracked, 0 without pose"), std::string::npos) << output;
  EXPECT_NE(output.find("ATE trajectory.txt"), std::string::npos) << output;
}

TEST(RunCommand, RejectsANegativeFrameLimit) {
  std::string output;
  const int status = testing::run_shell(
      std::string(PSPSLAM_CLI_PATH) + " run --sequence /nonexistent --max-frames -3", &output);
  EXPECT_EQ(status, 2);
  EXPECT_NE(output.find("--max-frames must be >= 0, got -3"), std::string::npos) << output;
}

// The static first 200 frames of the real Bonn clip (nobody in view until ~frame 220).
TEST(RunCommand, TracksTheStaticStretchOfBonnCrowd) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const std::filesystem::path dir = testing::make_temp_dir("run_bonn");
  std::string output;
  const int status =
      testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --sequence " +
                             (shared / "data" / "bonn_crowd_dev").string() + " --config " +
                             (source_dir() / "config" / "bonn.yaml").string() +
                             " --max-frames 200 --out " + (dir / "out").string(),
                         &output);
  ASSERT_EQ(status, 0) << output;
  EXPECT_EQ(count_pose_lines(dir / "out" / "trajectory.txt"), 200);
  const Trajectory estimate = read_tum_trajectory(dir / "out" / "trajectory.txt");
  const Trajectory ground_truth =
      read_tum_trajectory(shared / "data" / "bonn_crowd_dev" / "groundtruth.txt");
  const AteResult ate = compute_ate(ground_truth, estimate);
  EXPECT_LT(ate.error.rmse, 0.05) << output;
}

}  // namespace
}  // namespace pspslam
