#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/io/kitti_sequence.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/io/tum_sequence.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

using testing::error_of;
using testing::write_text;

constexpr const char* kCalibration =
    "P0: 500 0 320 0 0 510 240 0 0 0 1 0\n"
    "P1: 500 0 320 -60 0 510 240 0 0 0 1 0\n"
    "P2: 500 0 320 4 0 510 240 0 0 0 1 0\n";

// A KITTI odometry folder: `frames` grey pairs (left value 10 i, right 10 i + 1), times.txt at
// 10 Hz, calib.txt (fx 500, baseline 0.12 m), poses.txt moving 0.1 m along z per frame.
fs::path make_kitti(const std::string& tag, int frames = 3) {
  const fs::path dir = testing::make_temp_dir(tag);
  fs::create_directories(dir / "image_0");
  fs::create_directories(dir / "image_1");
  std::string times, poses;
  for (int i = 0; i < frames; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "%06d.png", i);
    cv::imwrite((dir / "image_0" / name).string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(10 * i)));
    cv::imwrite((dir / "image_1" / name).string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(10 * i + 1)));
    times += std::to_string(0.1 * i) + "\n";
    poses += "1 0 0 0 0 1 0 0 0 0 1 " + std::to_string(0.1 * i) + "\n";
  }
  write_text(dir / "times.txt", times);
  write_text(dir / "poses.txt", poses);
  write_text(dir / "calib.txt", kCalibration);
  return dir;
}

SequenceOptions quiet() {
  SequenceOptions options;
  options.warnings = nullptr;
  return options;
}

TEST(KittiSequence, ReadsPairsTimesCalibrationAndPoses) {
  const fs::path dir = make_kitti("kitti_ok");
  const KittiSequence sequence = KittiSequence::open(dir, quiet());
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_EQ(sequence.layout(), SequenceLayout::kitti);
  EXPECT_TRUE(sequence.stereo());
  EXPECT_DOUBLE_EQ(sequence.timestamp(2), 0.2);
  const InputFrame frame = sequence.load(2);
  EXPECT_EQ(frame.bgr.type(), CV_8UC3);
  EXPECT_EQ(frame.right.type(), CV_8UC1);
  EXPECT_EQ(frame.gray.at<uint8_t>(0, 0), 20);
  EXPECT_EQ(frame.right.at<uint8_t>(0, 0), 21);
  EXPECT_TRUE(frame.depth.empty());
  ASSERT_TRUE(sequence.ground_truth());
  EXPECT_NEAR(sequence.ground_truth()->at(2).T_world_camera.translation().z(), 0.2, 1e-9);

  const KittiCalibration calibration = read_kitti_calibration(dir / "calib.txt");
  EXPECT_DOUBLE_EQ(calibration.fx, 500.0);
  EXPECT_DOUBLE_EQ(calibration.fy, 510.0);
  EXPECT_DOUBLE_EQ(calibration.cx, 320.0);
  EXPECT_DOUBLE_EQ(calibration.cy, 240.0);
  EXPECT_DOUBLE_EQ(calibration.baseline, 0.12);

  // The run's config comes from calib.txt and the images.
  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  EXPECT_EQ(setup.config.camera.type, SensorType::stereo);
  EXPECT_EQ(setup.config.camera.pinhole.width, 8);
  EXPECT_EQ(setup.config.camera.pinhole.height, 6);
  EXPECT_DOUBLE_EQ(setup.config.camera.baseline, 0.12);
  EXPECT_NEAR(setup.config.camera.fps, 10.0, 1e-9);
  EXPECT_NEAR(setup.config.camera.depth_threshold, 4.8, 1e-12);
  EXPECT_EQ(
      error_of([&] { open_sequence_with_config(dir, std::nullopt, nullptr, SensorType::rgbd); }),
      "--sensor rgbd: " + dir.string() + " is a KITTI odometry sequence (stereo)");
}

TEST(KittiSequence, MissingImagesAreCountedOnceAndTheirFramesSkipped) {
  const fs::path dir = make_kitti("kitti_missing", 4);
  fs::remove(dir / "image_1" / "000001.png");
  fs::remove(dir / "image_0" / "000003.png");
  fs::remove(dir / "image_1" / "000003.png");
  std::ostringstream warnings;
  SequenceOptions options;
  options.warnings = &warnings;
  fs::remove(dir / "poses.txt");
  const KittiSequence sequence = KittiSequence::open(dir, options);
  EXPECT_EQ(sequence.size(), 2u);
  EXPECT_EQ(sequence.missing_files(), 3u);
  EXPECT_EQ(sequence.skipped_frames(), 2u);
  EXPECT_EQ(warnings.str(), "warning: " + dir.string() +
                                ": 3 listed files are missing; skipped 2 frames (first: "
                                "image_1/000001.png)\n");
}

TEST(KittiSequence, MalformedFilesNameFileAndLine) {
  const fs::path dir = make_kitti("kitti_bad");
  write_text(dir / "times.txt", "0.0\n0.1 x\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "times.txt").string() + ":2: expected one timestamp, got 2 fields");
  write_text(dir / "times.txt", "0.0\n0.1\n0.1\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "times.txt").string() + ":3: timestamp 0.1 does not increase");
  write_text(dir / "times.txt", "0.0\nabc\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "times.txt").string() + ":2: timestamp 'abc' is not a number");
  write_text(dir / "times.txt", "0.0\n0.1\n0.2\n");
  write_text(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "poses.txt").string() + ":2: expected 12 numbers (3x4 pose, row-major), got 11");
  write_text(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "poses.txt").string() + ":2: the rotation is not orthonormal");
  write_text(dir / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(error_of([&] { KittiSequence::open(dir, quiet()); }),
            (dir / "poses.txt").string() + ": 1 poses for 3 timestamps in times.txt");
  fs::remove(dir / "poses.txt");

  write_text(dir / "calib.txt", "P0: 500 0 320 0 0 510 240 0 0 0 1\n");
  EXPECT_EQ(error_of([&] { read_kitti_calibration(dir / "calib.txt"); }),
            (dir / "calib.txt").string() + ":1: P0: expected 12 numbers, got 11");
  write_text(dir / "calib.txt", "P0: 500 0 320 0 0 510 240 0 0 0 1 0\n");
  EXPECT_EQ(
      error_of([&] { read_kitti_calibration(dir / "calib.txt"); }),
      (dir / "calib.txt").string() + ": no 'P1:' line (the right camera's projection matrix)");
  write_text(dir / "calib.txt",
             "P0: 500 0 320 0 0 510 240 0 0 0 1 0\nP1: 500 0 320 60 0 510 240 0 0 0 1 0\n");
  EXPECT_EQ(error_of([&] { read_kitti_calibration(dir / "calib.txt"); }),
            (dir / "calib.txt").string() +
                ":2: P1 must put the right camera at a positive baseline (P1[0][3] = -fx * "
                "baseline < 0), got P1[0][3] = 60.000000");
  write_text(dir / "calib.txt",
             "P0: 500 0 320 0 0 510 240 0 0 0 1 0\nP1: 501 0 320 -60 0 510 240 0 0 0 1 0\n");
  EXPECT_EQ(error_of([&] { read_kitti_calibration(dir / "calib.txt"); }),
            (dir / "calib.txt").string() +
                ":2: P1 fx 501.000000 differs from P0's 500.000000: not a rectified pair");

  const fs::path empty = testing::make_temp_dir("kitti_empty");
  EXPECT_EQ(error_of([&] { KittiSequence::open(empty, quiet()); }),
            empty.string() +
                ": no times.txt (a KITTI odometry sequence needs times.txt, calib.txt and "
                "image_0/, and image_1/ for stereo)");
}

TEST(KittiTrajectory, WriteReadRoundTrip) {
  const fs::path dir = testing::make_temp_dir("kitti_traj");
  Trajectory trajectory;
  for (int i = 0; i < 3; ++i) {
    Pose pose = Pose::Identity();
    pose.linear() = Eigen::AngleAxisd(0.3 * i, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
    pose.translation() = Eigen::Vector3d(i, -0.5 * i, 2.0);
    trajectory.push_back({1.0 + i, pose});
  }
  write_kitti_trajectory(dir / "poses.txt", trajectory);
  std::ifstream in(dir / "poses.txt");
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first,
            "1.000000000e+00 0.000000000e+00 0.000000000e+00 0.000000000e+00 0.000000000e+00 "
            "1.000000000e+00 0.000000000e+00 0.000000000e+00 0.000000000e+00 0.000000000e+00 "
            "1.000000000e+00 2.000000000e+00");
  const Trajectory back = read_kitti_trajectory(dir / "poses.txt", {1.0, 2.0, 3.0});
  ASSERT_EQ(back.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_DOUBLE_EQ(back[i].timestamp, trajectory[i].timestamp);
    EXPECT_TRUE(back[i].T_world_camera.isApprox(trajectory[i].T_world_camera, 1e-8));
  }
}

// A stereo sequence in TUM layout: rgb.txt (left) + right.txt.
TEST(StereoTumSequence, ReadsLeftAndRightLists) {
  const fs::path dir = testing::make_temp_dir("stereo_tum");
  fs::create_directories(dir / "rgb");
  fs::create_directories(dir / "right");
  std::string rgb = "# left\n", right = "# right\n";
  for (int i = 0; i < 2; ++i) {
    const std::string name = std::to_string(i) + ".png";
    cv::imwrite((dir / "rgb" / name).string(), cv::Mat(4, 5, CV_8UC3, cv::Scalar(1, 2, 3)));
    cv::imwrite((dir / "right" / name).string(), cv::Mat(4, 5, CV_8UC1, cv::Scalar(7 + i)));
    rgb += std::to_string(i) + " rgb/" + name + "\n";
    right += std::to_string(i) + " right/" + name + "\n";
  }
  write_text(dir / "rgb.txt", rgb);
  SequenceOptions options = quiet();
  options.sensor = SensorType::stereo;
  EXPECT_EQ(error_of([&] { TumSequence::open(dir, options); }),
            dir.string() +
                ": no right.txt (a stereo sequence in TUM layout needs rgb.txt and "
                "right.txt)");
  write_text(dir / "right.txt", right);
  const TumSequence sequence = TumSequence::open(dir, options);
  ASSERT_EQ(sequence.size(), 2u);
  const InputFrame frame = sequence.load(1);
  EXPECT_EQ(frame.right.at<uint8_t>(0, 0), 8);
  EXPECT_TRUE(frame.depth.empty());
  cv::imwrite((dir / "right" / "1.png").string(), cv::Mat(3, 5, CV_8UC1, cv::Scalar(0)));
  EXPECT_EQ(error_of([&] { sequence.load(1); }), (dir / "rgb/1.png").string() + " is 5x4 but " +
                                                     (dir / "right/1.png").string() + " is 5x3");
}

}  // namespace
}  // namespace pspslam
