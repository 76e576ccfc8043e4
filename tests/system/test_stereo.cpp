#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "pspslam/eval/ate.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/map/map.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "pspslam/system/system.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

SynthOptions stereo_room(size_t frames, int bodies) {
  SynthOptions options;
  options.frames = frames;
  options.bodies = bodies;
  options.seed = 1;
  options.threads = 1;
  options.stereo_baseline = 0.1;
  return options;
}

// Frame i as the stereo camera delivers it (colour left, grey right); `rendered` keeps the
// rendering, ground-truth labels included.
InputFrame stereo_frame(const SyntheticScene& scene, size_t i, SynthFrame& rendered) {
  scene.render(i, rendered, 1);
  InputFrame frame;
  frame.index = i;
  frame.timestamp = scene.timestamp(i);
  frame.bgr = rendered.bgr;
  cv::Mat right;
  scene.render_right(i, right, 1);
  cv::cvtColor(right, frame.right, cv::COLOR_BGR2GRAY);
  return frame;
}

// Stereo through the System: every frame tracked from the rendered pair alone (no depth image),
// within a centimetre of the ground truth, and the map's points carry stereo depth.
TEST(Stereo, TracksAShortStaticSyntheticPairSequenceWithinOneCentimetre) {
  const SyntheticScene scene(stereo_room(60, 0));
  const SystemConfig config = scene.system_config();
  ASSERT_EQ(config.camera.type, SensorType::stereo);
  SystemOptions options;
  options.place.loop_closing = false;
  options.back_end_wait = BackEndWait::whole_back_end;
  System system(config, options);
  Trajectory estimate;
  SynthFrame rendered;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const FrameReport report = system.process(stereo_frame(scene, i, rendered));
    ASSERT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i << " lost";
    estimate.push_back({scene.timestamp(i), *report.tracking.T_world_camera});
  }
  system.shutdown();
  EXPECT_GT(system.map().num_map_points(), 300u);
  const AteResult ate = compute_ate(scene.ground_truth(), estimate);
  EXPECT_LT(ate.error.rmse, 0.01);
}

// The geometry stage on a stereo pair judges each keypoint by its own stereo depth, not by the
// dense depth at its pixel: block matching lends a near surface's disparity to the farther pixels
// next to a depth edge, where corners lie, and a static keypoint read that way lies in front of
// what its reference keyframes saw, a false "moved". Reading dense depth at the keypoints puts a
// large share of the geometry mask on static pixels; the keypoints' own depths keep it on the
// people (system/frame_builder.cpp).
TEST(Stereo, GeometryMaskStaysOnThePeople) {
  const SyntheticScene scene(stereo_room(120, 3));
  SystemOptions options;
  options.place.loop_closing = false;
  options.back_end_wait = BackEndWait::whole_back_end;
  options.dynamic.mode = DynamicMode::geometry;
  System system(scene.system_config(), options);
  SynthFrame rendered;
  double on_people = 0.0, on_static = 0.0, people = 0.0;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    const FrameReport report = system.process(stereo_frame(scene, i, rendered));
    ASSERT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i << " lost";
    const cv::Mat mask = system.last_dynamic_mask();
    const cv::Mat person = rendered.labels != kSynthLabelStatic;
    people += cv::countNonZero(person);
    if (mask.empty()) continue;
    const cv::Mat masked = mask != 0;
    on_people += cv::countNonZero(masked & person);
    on_static += cv::countNonZero(masked & ~person);
  }
  system.shutdown();
  ASSERT_GT(on_people + on_static, 0.0);
  const double precision = on_people / (on_people + on_static);
  const double recall = on_people / people;
  EXPECT_GT(precision, 0.9) << "recall " << recall;
  EXPECT_GT(recall, 0.3) << "precision " << precision;  // and it still finds them
  std::printf("stereo geometry mask, 120 frames: precision %.3f, recall %.3f\n", precision, recall);
}

// A deterministic run announces each frame before the one before it is processed, and the
// stereo builder starts the frame's right-image extraction and block matching then. The poses
// must be those of frames extracted on their own: here every frame announced ahead but every
// fifth (those start inline), and one more frame announced at the end that is never processed.
TEST(Stereo, FramesPreparedAheadGiveTheSameTrajectory) {
  const SyntheticScene scene(stereo_room(41, 2));  // the 41st is announced, never processed
  std::vector<InputFrame> frames;
  SynthFrame rendered;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    frames.push_back(stereo_frame(scene, i, rendered));
    frames.back().bgr = frames.back().bgr.clone();  // `rendered` is drawn over for the next
  }
  const auto run = [&](bool ahead) {
    SystemOptions options;
    options.place.loop_closing = false;
    options.back_end_wait = BackEndWait::whole_back_end;
    options.dynamic.mode = DynamicMode::geometry;  // the dense depth is used too
    System system(scene.system_config(), options);
    std::vector<Pose> poses;
    for (size_t i = 0; i + 1 < frames.size(); ++i) {
      if (ahead && i == 0) system.announce(frames[0]);
      if (ahead && (i + 1) % 5 != 0) system.announce(frames[i + 1]);
      const FrameReport report = system.process(frames[i]);
      EXPECT_TRUE(report.tracking.T_world_camera.has_value()) << "frame " << i;
      poses.push_back(report.tracking.T_world_camera.value_or(Pose::Identity()));
    }
    system.shutdown();
    return poses;
  };
  const std::vector<Pose> inline_poses = run(false), ahead_poses = run(true);
  ASSERT_EQ(inline_poses.size(), ahead_poses.size());
  for (size_t i = 0; i < inline_poses.size(); ++i) {
    EXPECT_TRUE(inline_poses[i].matrix() == ahead_poses[i].matrix()) << "frame " << i;
  }
}

TEST(Stereo, AFrameWithoutItsRightImageIsAnErrorNamingIt) {
  const SyntheticScene scene(stereo_room(1, 0));
  System system(scene.system_config());
  InputFrame frame;
  frame.bgr = scene.render(0).bgr;
  frame.name = "rgb/1.png";
  try {
    system.process(frame);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "stereo camera: frame rgb/1.png has no right image");
  }
}

int count_lines(const fs::path& file) {
  std::ifstream in(file);
  int lines = 0;
  for (std::string line; std::getline(in, line);) lines += !line.empty() && line[0] != '#';
  return lines;
}

// The same synthetic pair sequence in TUM-style and KITTI layouts runs end to end to the same
// trajectory (the geometry mode exercises the dense SGBM depth of the dynamic pipeline); the
// KITTI run also writes its trajectory in KITTI format.
TEST(Stereo, TumKittiAndEurocLayoutsGiveTheSameTrajectory) {
  const fs::path dir = testing::make_temp_dir("stereo_layouts");
  SynthOptions options = stereo_room(40, 1);
  write_sequence(options, dir / "tum");
  options.layout = SynthOptions::Layout::kitti;
  write_sequence(options, dir / "kitti");
  options.layout = SynthOptions::Layout::euroc;
  write_sequence(options, dir / "euroc");
  ASSERT_TRUE(fs::exists(dir / "kitti" / "calib.txt"));
  std::string output;
  for (const char* layout : {"tum", "kitti", "euroc"}) {
    const int status = testing::run_shell(
        std::string(PSPSLAM_CLI_PATH) + " run --sequence " + (dir / layout).string() +
            " --dynamic geometry --loop-closing off --trajectory-format kitti --out " +
            (dir / (std::string("out_") + layout)).string(),
        &output);
    ASSERT_EQ(status, 0) << output;
    EXPECT_NE(output.find("40 processed, 40 tracked, 0 without pose"), std::string::npos) << output;
  }
  const Trajectory tum = read_tum_trajectory(dir / "out_tum" / "trajectory_refined.txt");
  const Trajectory kitti = read_tum_trajectory(dir / "out_kitti" / "trajectory_refined.txt");
  ASSERT_EQ(tum.size(), kitti.size());
  for (size_t i = 0; i < tum.size(); ++i) {
    EXPECT_TRUE(tum[i].T_world_camera.isApprox(kitti[i].T_world_camera, 1e-9)) << "frame " << i;
  }
  EXPECT_EQ(count_lines(dir / "out_kitti" / "trajectory_refined_kitti.txt"), 40);
  // The online file in KITTI format holds the same poses as trajectory.txt, row by row.
  const Trajectory online = read_tum_trajectory(dir / "out_kitti" / "trajectory.txt");
  std::vector<Timestamp> stamps;
  for (const StampedPose& pose : online) stamps.push_back(pose.timestamp);
  const Trajectory online_kitti =
      read_kitti_trajectory(dir / "out_kitti" / "trajectory_kitti.txt", stamps);
  ASSERT_EQ(online_kitti.size(), online.size());
  for (size_t i = 0; i < online.size(); ++i) {
    EXPECT_TRUE(online_kitti[i].T_world_camera.isApprox(online[i].T_world_camera, 1e-6))
        << "frame " << i;
  }
  // EuRoC: the stamps are whole nanoseconds and the pair goes through cv::stereoRectify + remap
  // (the identity here, up to interpolation): the same ATE, not the same bytes.
  const Trajectory euroc = read_tum_trajectory(dir / "out_euroc" / "trajectory_refined.txt");
  ASSERT_EQ(euroc.size(), tum.size());
  const double ate_euroc =
      compute_ate(SyntheticScene(stereo_room(40, 1)).ground_truth(), euroc).error.rmse;
  const AteResult ate = compute_ate(SyntheticScene(stereo_room(40, 1)).ground_truth(), tum);
  EXPECT_LT(ate.error.rmse, 0.02);
  std::printf("40-frame ATE: TUM-style %.5f m, EuRoC layout %.5f m\n", ate.error.rmse, ate_euroc);
  EXPECT_NEAR(ate_euroc, ate.error.rmse, 0.002);
}

TEST(Stereo, SensorFlagOverridesTheConfig) {
  const fs::path dir = testing::make_temp_dir("stereo_sensor_flag");
  write_sequence(stereo_room(3, 0), dir / "seq");
  std::string output;
  // Monocular reads the left images (rgb.txt) alone; three frames of a slow camera give no
  // two-view parallax, and the summary says so. The geometry stage needs depth images: the
  // `geometry` mode runs nothing, and says so.
  EXPECT_EQ(testing::run_shell(
                std::string(PSPSLAM_CLI_PATH) + " run --sequence " + (dir / "seq").string() +
                    " --sensor monocular --dynamic geometry --out " + (dir / "out").string(),
                &output),
            0)
      << output;
  EXPECT_NE(output.find("(camera 'synthetic_stereo', monocular, "), std::string::npos) << output;
  EXPECT_NE(output.find("monocular:    the map never started"), std::string::npos) << output;
  EXPECT_NE(output.find("dynamic:      off, deterministic (waits for each mask); geometry runs "
                        "as off (monocular: the geometry stage needs depth images)"),
            std::string::npos)
      << output;
  const std::string stats = testing::read_text(dir / "out" / "stats.json");
  EXPECT_NE(stats.find("\"sensor\": \"monocular\""), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"mode_requested\": \"geometry\""), std::string::npos) << stats;
  EXPECT_NE(testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --sequence " +
                                   (dir / "seq").string() + " --sensor rgbd --out " +
                                   (dir / "out").string(),
                               &output),
            0);
  EXPECT_NE(output.find("--sensor rgbd: " + (dir / "seq" / "config.yaml").string() +
                        " describes a stereo camera (no depth_factor)"),
            std::string::npos)
      << output;
  // The RGB-D config of the same folder with --sensor rgbd runs the depth images.
  ASSERT_EQ(testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " run --sequence " +
                                   (dir / "seq").string() + " --config " +
                                   (dir / "seq" / "config_rgbd.yaml").string() +
                                   " --sensor rgbd --dynamic off --out " + (dir / "out").string(),
                               &output),
            0)
      << output;
}

}  // namespace
}  // namespace pspslam
