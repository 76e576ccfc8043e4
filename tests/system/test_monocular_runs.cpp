// KITTI and EuRoC folders with the left camera's images alone (the right camera's deleted from
// what `pspslam synth --layout kitti|euroc --stereo B` writes) run monocular end to end: every
// frame gets a pose, within millimetres of the ground truth after a Sim(3) alignment.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pspslam/eval/ate.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

SynthOptions stereo_layout(SynthOptions::Layout layout) {
  SynthOptions options;
  options.frames = 60;
  options.bodies = 0;
  options.seed = 2;
  options.stereo_baseline = 0.1;
  options.layout = layout;
  return options;
}

void expect_monocular_run_tracks(SynthOptions::Layout layout, const fs::path& right_camera) {
  const fs::path dir = testing::make_temp_dir("mono_run_" + right_camera.filename().string());
  const SynthOptions options = stereo_layout(layout);
  write_sequence(options, dir / "seq");
  ASSERT_TRUE(fs::remove_all(dir / "seq" / right_camera) > 0);
  std::string output;
  ASSERT_EQ(testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --sequence " +
                                   (dir / "seq").string() + " --dynamic off --loop-closing off" +
                                   " --out " + (dir / "out").string(),
                               &output),
            0)
      << output;
  EXPECT_TRUE(testing::contains(output, ", monocular, 640x480")) << output;
  EXPECT_TRUE(testing::contains(output, "frames:       60 processed, 60 tracked, 0 without pose"))
      << output;
  EXPECT_TRUE(testing::contains(testing::read_text(dir / "out" / "stats.json"),
                                "\"sensor\": \"monocular\""));
  const Trajectory estimate = read_tum_trajectory(dir / "out" / "trajectory.txt");
  ASSERT_EQ(estimate.size(), 60u);
  AteOptions sim3;
  sim3.sim3 = true;
  const AteResult ate = compute_ate(SyntheticScene(options).ground_truth(), estimate, sim3);
  EXPECT_EQ(ate.pairs.size(), 60u);
  std::printf("%s, monocular, 60 frames: ATE %.5f m after Sim(3)\n", right_camera.string().c_str(),
              ate.error.rmse);
  EXPECT_LT(ate.error.rmse, 0.01);
}

TEST(MonocularRun, KittiLeftImagesAlone) {
  expect_monocular_run_tracks(SynthOptions::Layout::kitti, "image_1");
}

TEST(MonocularRun, EurocCam0Alone) {
  expect_monocular_run_tracks(SynthOptions::Layout::euroc, fs::path("mav0") / "cam1");
}

}  // namespace
}  // namespace pspslam
