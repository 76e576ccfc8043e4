// KITTI and EuRoC folders as `pspslam synth --layout kitti|euroc --stereo B` writes them, with the
// right camera's images deleted (or kept, and `--sensor monocular` asked), open as monocular
// sequences: the left images alone, the calibration's camera, the left camera's ground truth.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/io/sequence_setup.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

using testing::error_of;

namespace fs = std::filesystem;

constexpr size_t kFrames = 6;

SynthOptions stereo_layout(SynthOptions::Layout layout) {
  SynthOptions options;
  options.frames = kFrames;
  options.bodies = 0;
  options.seed = 2;
  options.stereo_baseline = 0.1;
  options.layout = layout;
  return options;
}

// The folder written for `layout`, and the scene it was rendered from.
fs::path write_layout(SynthOptions::Layout layout, const std::string& tag) {
  const fs::path dir = testing::make_temp_dir(tag) / "seq";
  write_sequence(stereo_layout(layout), dir);
  return dir;
}

// What every monocular reading of a synthetic stereo folder must give.
void expect_monocular_left_camera(const SequenceSetup& setup, SynthOptions::Layout layout) {
  const SyntheticScene scene(stereo_layout(layout));
  const RecordedSequence& sequence = *setup.sequence;
  EXPECT_EQ(sequence.sensor(), SensorType::monocular);
  EXPECT_EQ(sequence.listed_depth(), 0u);
  EXPECT_EQ(sequence.missing_files(), 0u);
  ASSERT_EQ(sequence.size(), kFrames);
  const CameraConfig& camera = setup.config.camera;
  EXPECT_EQ(camera.type, SensorType::monocular);
  const PinholeCamera& truth = scene.camera();
  EXPECT_EQ(camera.pinhole.width, truth.width);
  EXPECT_EQ(camera.pinhole.height, truth.height);
  EXPECT_NEAR(camera.pinhole.fx, truth.fx, 1e-3);
  EXPECT_NEAR(camera.pinhole.fy, truth.fy, 1e-3);
  EXPECT_NEAR(camera.pinhole.cx, truth.cx, 1e-3);
  EXPECT_NEAR(camera.pinhole.cy, truth.cy, 1e-3);
  EXPECT_FALSE(camera.pinhole.has_distortion());
  EXPECT_NEAR(camera.fps, 30.0, 1e-3);
  for (size_t i = 0; i < kFrames; ++i) EXPECT_TRUE(sequence.files(i).depth_file.empty()) << i;
  const InputFrame frame = sequence.load(kFrames - 1);
  EXPECT_EQ(frame.bgr.size(), cv::Size(truth.width, truth.height));
  EXPECT_FALSE(frame.gray.empty());
  EXPECT_TRUE(frame.right.empty());
  EXPECT_TRUE(frame.depth.empty());
  ASSERT_TRUE(sequence.ground_truth());
  const Trajectory expected = scene.ground_truth();
  ASSERT_EQ(sequence.ground_truth()->size(), kFrames);
  for (size_t i = 0; i < kFrames; ++i) {
    const StampedPose& pose = sequence.ground_truth()->at(i);
    EXPECT_NEAR(pose.timestamp, expected[i].timestamp, 1e-6) << i;
    EXPECT_TRUE(pose.T_world_camera.isApprox(expected[i].T_world_camera, 1e-6)) << i;
  }
}

TEST(MonocularLayouts, KittiWithTheLeftImagesAloneOpensMonocular) {
  const fs::path dir = write_layout(SynthOptions::Layout::kitti, "mono_kitti");
  fs::remove_all(dir / "image_1");
  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  expect_monocular_left_camera(setup, SynthOptions::Layout::kitti);
  EXPECT_EQ(setup.sequence->layout(), SequenceLayout::kitti);
  const std::string summary = describe_sequence(setup);
  EXPECT_TRUE(testing::contains(summary,
                                "frames:       6 (6 left images listed in times.txt, "
                                "image_0/ alone; 0 listed files missing"))
      << summary;
  EXPECT_TRUE(testing::contains(summary, "ground truth: yes (6 poses in poses.txt)")) << summary;
  EXPECT_TRUE(testing::contains(summary, "(camera 'kitti', monocular, 640x480)")) << summary;
  EXPECT_EQ(
      error_of([&] { open_sequence_with_config(dir, std::nullopt, nullptr, SensorType::stereo); }),
      "--sensor stereo: " + dir.string() +
          " is a KITTI odometry sequence (monocular: image_0/ without image_1/)");
  // The left camera alone needs no P1.
  testing::write_text(dir / "calib.txt", "P0: 500 0 320 0 0 500 240 0 0 0 1 0\n");
  const SequenceSetup p0_only = open_sequence_with_config(dir, std::nullopt, nullptr);
  EXPECT_DOUBLE_EQ(p0_only.config.camera.pinhole.fx, 500.0);
  EXPECT_EQ(p0_only.config.camera.baseline, 0.0);
}

TEST(MonocularLayouts, EurocWithCam0AloneOpensMonocular) {
  const fs::path dir = write_layout(SynthOptions::Layout::euroc, "mono_euroc");
  fs::remove_all(dir / "mav0" / "cam1");
  const SequenceSetup setup = open_sequence_with_config(dir, std::nullopt, nullptr);
  expect_monocular_left_camera(setup, SynthOptions::Layout::euroc);
  EXPECT_EQ(setup.sequence->layout(), SequenceLayout::euroc);
  const std::string summary = describe_sequence(setup);
  EXPECT_TRUE(testing::contains(summary,
                                "frames:       6 (6 cam0 images listed in cam0/data.csv, "
                                "cam0 alone; 0 listed files missing"))
      << summary;
  EXPECT_TRUE(testing::contains(
      summary, "ground truth: yes (6 poses in state_groundtruth_estimate0/data.csv)"))
      << summary;
  EXPECT_EQ(
      error_of([&] { open_sequence_with_config(dir, std::nullopt, nullptr, SensorType::stereo); }),
      "--sensor stereo: " + dir.string() +
          " is a EuRoC MAV sequence (monocular: cam0 without cam1/data.csv)");
  // mav0 itself is the sequence folder too.
  const SequenceSetup mav0 = open_sequence_with_config(dir / "mav0", std::nullopt, nullptr);
  EXPECT_EQ(mav0.sequence->layout(), SequenceLayout::euroc);
  EXPECT_EQ(mav0.sequence->size(), kFrames);
}

// `--sensor monocular` on a complete stereo folder reads the left images only: a missing right
// image neither skips a frame nor counts as missing.
TEST(MonocularLayouts, SensorMonocularReadsTheLeftImagesOfAStereoFolder) {
  const fs::path kitti = write_layout(SynthOptions::Layout::kitti, "mono_flag_kitti");
  const fs::path euroc = write_layout(SynthOptions::Layout::euroc, "mono_flag_euroc");
  fs::remove(kitti / "image_1" / "000002.png");
  fs::remove(*fs::directory_iterator(euroc / "mav0" / "cam1" / "data"));
  for (const auto& [dir, layout] : {std::pair{kitti, SynthOptions::Layout::kitti},
                                    std::pair{euroc, SynthOptions::Layout::euroc}}) {
    SCOPED_TRACE(dir.string());
    const SequenceSetup stereo = open_sequence_with_config(dir, std::nullopt, nullptr);
    EXPECT_EQ(stereo.config.camera.type, SensorType::stereo);
    EXPECT_GT(stereo.sequence->missing_files(), 0u);
    const SequenceSetup setup =
        open_sequence_with_config(dir, std::nullopt, nullptr, SensorType::monocular);
    expect_monocular_left_camera(setup, layout);
    EXPECT_NE(error_of([&] {
                open_sequence_with_config(dir, std::nullopt, nullptr, SensorType::rgbd);
              }).find("(stereo)"),
              std::string::npos);
  }
}

}  // namespace
}  // namespace pspslam
