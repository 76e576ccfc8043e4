#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <sstream>
#include <tuple>

#include "pspslam/core/shared_paths.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/point_cloud_ply.h"
#include "pspslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

struct Result {
  int status = 0;
  std::string output;
};

Result pspslam(const std::string& arguments) {
  Result result;
  result.status =
      testing::run_shell(std::string(PSPSLAM_CLI_PATH) + " " + arguments, &result.output);
  return result;
}

// The same, run from `folder` (relative paths are the user's, not the source tree's).
Result pspslam_in(const std::filesystem::path& folder, const std::string& arguments) {
  Result result;
  result.status = testing::run_shell(
      "cd '" + folder.string() + "' && " + std::string(PSPSLAM_CLI_PATH) + " " + arguments,
      &result.output);
  return result;
}

using testing::contains;
using testing::read_text;

size_t count_of(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

// Ground truth: 1 m/s along x with a z wave, 5 s at 30 Hz. est.txt: x at `speed` m/s (a pure
// translation drift of speed - 1 m/s), shifted 2 m in y. scaled.txt: the whole ground truth
// scaled by 1.1 (a monocular-style scale error) and shifted.
void write_trajectories(const std::filesystem::path& dir, double speed) {
  Trajectory gt, estimate, scaled;
  for (int i = 0; i <= 150; ++i) {
    StampedPose p;
    p.timestamp = 200.0 + i / 30.0;
    const Eigen::Vector3d position(i / 30.0, 0.0, 0.5 * std::sin(i / 20.0));
    p.T_world_camera.translation() = position;
    gt.push_back(p);
    p.T_world_camera.translation() = Eigen::Vector3d(speed * i / 30.0, 2.0, position.z());
    estimate.push_back(p);
    p.T_world_camera.translation() = 1.1 * position + Eigen::Vector3d(0.0, 2.0, 0.0);
    scaled.push_back(p);
  }
  write_tum_trajectory(dir / "gt.txt", gt);
  write_tum_trajectory(dir / "est.txt", estimate);
  write_tum_trajectory(dir / "scaled.txt", scaled);
}

std::filesystem::path make_sequence(const std::string& tag, bool with_config) {
  const auto dir = testing::make_temp_dir(tag);
  std::filesystem::create_directories(dir / "rgb");
  std::filesystem::create_directories(dir / "depth");
  std::ofstream rgb(dir / "rgb.txt"), depth(dir / "depth.txt"), gt(dir / "groundtruth.txt");
  for (int i = 0; i < 3; ++i) {
    const std::string stamp = std::to_string(10 + i) + ".5";
    cv::imwrite((dir / "rgb" / (stamp + ".png")).string(),
                cv::Mat(6, 8, CV_8UC3, cv::Scalar(1, 2, 3)));
    cv::imwrite((dir / "depth" / (stamp + ".png")).string(),
                cv::Mat(6, 8, CV_16UC1, cv::Scalar(5000)));
    rgb << stamp << " rgb/" << stamp << ".png\n";
    depth << stamp << " depth/" << stamp << ".png\n";
    gt << stamp << " 0 0 " << i << " 0 0 0 1\n";
  }
  if (with_config) {
    std::ofstream(dir / "config.yaml")
        << "camera:\n  width: 8\n  height: 6\n  fx: 10\n  fy: 10\n  cx: 4\n  cy: 3\n"
           "  distortion: [0, 0, 0, 0]\n  fps: 1\n  depth_factor: 5000\n  depth_threshold: 3\n";
  }
  return dir;
}

TEST(CliEval, MissingRequiredFlag) {
  const Result r = pspslam("eval --est x.txt");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: pspslam eval: --gt is required (see 'pspslam eval --help')\n");
}

TEST(CliEval, UnknownFlag) {
  const Result r = pspslam("eval --gt a --est b --plots out");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam eval: The following arguments were not expected: out --plots (did you "
            "mean --plot?) (see 'pspslam eval --help')\n");
}

TEST(CliEval, HelpListsFlags) {
  const Result r = pspslam("eval --help");
  EXPECT_EQ(r.status, 0);
  for (const char* flag : {"--gt", "--est", "--max-dt", "--offset", "--sim3", "--rpe-delta",
                           "--rpe-unit", "--json", "--plot"}) {
    EXPECT_TRUE(contains(r.output, flag)) << flag;
  }
}

TEST(CliEval, BadValuesAndFiles) {
  const auto dir = testing::make_temp_dir("cli");
  write_trajectories(dir, 1.0);
  const std::string files =
      " --gt " + (dir / "gt.txt").string() + " --est " + (dir / "est.txt").string();
  Result r = pspslam("eval" + files + " --rpe-unit m");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam eval: --rpe-unit: m not in {s,f} (see 'pspslam eval --help')\n");
  r = pspslam("eval" + files + " --max-dt fast");
  EXPECT_EQ(r.output,
            "error: pspslam eval: --max-dt: must be a number in [1e-09, 1e+09], got 'fast' (see "
            "'pspslam eval --help')\n");
  r = pspslam("eval --gt " + (dir / "none.txt").string() + " --est " + (dir / "est.txt").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: " + (dir / "none.txt").string() + ": cannot open trajectory file\n");
  std::ofstream(dir / "bad.txt") << "# estimate\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n";
  r = pspslam("eval --gt " + (dir / "gt.txt").string() + " --est " + (dir / "bad.txt").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: " + (dir / "bad.txt").string() +
                          ":3: expected 8 fields 'timestamp tx ty tz qx qy qz qw', got 7\n");
}

TEST(CliEval, TableJsonAndPlots) {
  const auto dir = testing::make_temp_dir("cli");
  write_trajectories(dir, 1.1);  // 0.1 m/s translation drift
  const std::string files =
      " --gt " + (dir / "gt.txt").string() + " --est " + (dir / "est.txt").string();
  Result r = pspslam("eval" + files);
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "alignment:    SE(3), scale 1.000000")) << r.output;
  EXPECT_TRUE(contains(r.output, "  RPE translation        m         120     0.1000     0.1000"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "  RPE translation rate   m/s       120     0.1000")) << r.output;
  EXPECT_TRUE(contains(r.output, "  ATE                    m         151 ")) << r.output;

  r = pspslam("eval --gt " + (dir / "gt.txt").string() + " --est " + (dir / "scaled.txt").string() +
              " --json --sim3 --plot " + (dir / "plots").string());
  EXPECT_EQ(r.status, 0) << r.output;
  // stdout is one JSON document (the plot list goes to stderr, which r.output also holds).
  const nlohmann::json report = nlohmann::json::parse(r.output.substr(0, r.output.rfind("}") + 1));
  EXPECT_EQ(report["ate"]["alignment"], "sim3");
  EXPECT_EQ(report["ate"]["max_dt_s"], 0.02);
  EXPECT_EQ(report["rpe"]["delta"], 1.0);
  EXPECT_EQ(report["rpe"]["delta_unit"], "s");
  // With scale the 1.1x copy fits exactly: scale 1/1.1 written so that it reads back exactly.
  EXPECT_NEAR(report["ate"]["scale"].get<double>(), 1.0 / 1.1, 1e-12);
  EXPECT_TRUE(contains(r.output, "\"scale\": 0.90909090909")) << r.output;
  EXPECT_EQ(report["ate"]["error_m"]["count"], 151);
  EXPECT_LT(report["ate"]["error_m"]["rmse"].get<double>(), 1e-9);
  for (const char* name : {"trajectory_top_view", "ate_over_time", "position_over_time",
                           "orientation_over_time", "rpe_over_time"}) {
    const auto png = dir / "plots" / (std::string(name) + ".png");
    EXPECT_FALSE(cv::imread(png.string()).empty()) << png;
    EXPECT_TRUE(contains(r.output, png.string())) << r.output;
    const std::string svg = read_text(dir / "plots" / (std::string(name) + ".svg"));
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u) << name;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << name;
  }
  // No stats.json beside the estimate and no --title: titles carry no run name.
  EXPECT_TRUE(contains(read_text(dir / "plots" / "trajectory_top_view.svg"),
                       ">top view (x-z plane), estimate after Sim(3) alignment, coloured by "
                       "ATE</text>"));
}

// Plot titles name the run: from the stats.json `pspslam run` writes beside its trajectories,
// or from --title, which wins.
TEST(CliEval, PlotTitlesNameSequenceAndMode) {
  const auto dir = testing::make_temp_dir("cli_titles");
  write_trajectories(dir, 1.1);
  std::ofstream(dir / "stats.json")
      << R"({"sequence": "/data/sets/bonn_crowd_dev/", "mode": "geometry", "frames": 151})";
  const std::string files =
      " --gt " + (dir / "gt.txt").string() + " --est " + (dir / "est.txt").string();
  Result r = pspslam("eval" + files + " --plot " + (dir / "a").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(read_text(dir / "a" / "trajectory_top_view.svg"),
                       ">bonn_crowd_dev, mode geometry: top view (x-z plane), estimate after "
                       "SE(3) alignment, coloured by ATE</text>"));
  EXPECT_TRUE(contains(read_text(dir / "a" / "rpe_over_time.svg"),
                       ">bonn_crowd_dev, mode geometry: translational RPE over 1 s: RMSE "));
  EXPECT_TRUE(contains(read_text(dir / "a" / "position_over_time.svg"), ">x [m]</text>"));
  EXPECT_TRUE(contains(read_text(dir / "a" / "orientation_over_time.svg"), ">yaw [deg]</text>"));

  r = pspslam("eval" + files + " --rpe-delta 10 --rpe-unit f --title 'fr3 walking, run 2' --plot " +
              (dir / "b").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(read_text(dir / "b" / "ate_over_time.svg"),
                       ">fr3 walking, run 2: ATE over time (SE(3) alignment): RMSE "));
  EXPECT_TRUE(contains(read_text(dir / "b" / "rpe_over_time.svg"),
                       ">fr3 walking, run 2: translational RPE over 10 frames: RMSE "));

  // A stats.json that is not JSON only costs the name, with a warning.
  std::ofstream(dir / "stats.json") << "{ not json";
  r = pspslam("eval" + files + " --plot " + (dir / "c").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, (dir / "stats.json").string() + ": not read for the plot titles"))
      << r.output;
  EXPECT_TRUE(contains(read_text(dir / "c" / "trajectory_top_view.svg"), ">top view (x-z plane)"));
}

// --gt-body-to-camera moves the ground truth onto the camera. The camera turns on a circle; the
// marker sits 0.3 m beside it, so no alignment can explain the marker's positions by the
// camera's (ATE > 0.1 m) until the marker is moved onto the camera (ATE 0).
TEST(CliEval, GroundTruthBodyToCamera) {
  const auto dir = testing::make_temp_dir("cli_body");
  Pose T_marker_camera = Pose::Identity();
  T_marker_camera.translation() = Eigen::Vector3d(0.3, 0.0, 0.0);
  Trajectory camera, marker;
  for (int i = 0; i < 120; ++i) {
    StampedPose pose;
    pose.timestamp = 100.0 + i / 30.0;
    const double angle = 2.0 * M_PI * i / 120.0;
    pose.T_world_camera.linear() =
        Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    pose.T_world_camera.translation() = Eigen::Vector3d(std::cos(angle), std::sin(angle), 1.0);
    camera.push_back(pose);
    pose.T_world_camera = pose.T_world_camera * T_marker_camera.inverse();
    marker.push_back(pose);
  }
  write_tum_trajectory(dir / "camera.txt", camera);
  write_tum_trajectory(dir / "marker.txt", marker);
  std::ofstream(dir / "marker_to_camera.txt") << "# 4x4\n1 0 0 0.3\n0 1 0 0\n0 0 1 0\n0 0 0 1\n";
  const std::string files =
      " --json --gt " + (dir / "marker.txt").string() + " --est " + (dir / "camera.txt").string();
  Result r = pspslam("eval" + files);
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_GT(nlohmann::json::parse(r.output)["ate"]["error_m"]["rmse"].get<double>(), 0.1);
  r = pspslam("eval" + files + " --gt-body-to-camera " + (dir / "marker_to_camera.txt").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const nlohmann::json report = nlohmann::json::parse(r.output);
  EXPECT_EQ(report["gt_body_to_camera"], (dir / "marker_to_camera.txt").string());
  EXPECT_LT(report["ate"]["error_m"]["max"].get<double>(), 1e-6);
}

TEST(CliRun, MissingSequenceFlagAndConfig) {
  Result r = pspslam("run");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --sequence (or --camera or --video) is required (see 'pspslam run "
            "--help')\n");
  const auto dir = make_sequence("cli", false);
  r = pspslam("run --sequence " + dir.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: " + dir.string() + ": no camera config: --config was not given and " +
                          (dir / "config.yaml").string() +
                          " does not exist (pass a preset, e.g. --config config/bonn.yaml)\n");
  r = pspslam("run --sequence " + (dir / "absent").string());
  EXPECT_EQ(r.output, "error: " + (dir / "absent").string() + ": sequence directory not found\n");
}

TEST(CliRun, EightBitDepthStopsWithTheFileName) {
  const auto dir = make_sequence("cli", true);
  // The first frame, so the error comes from loading it, before any SLAM work.
  cv::imwrite((dir / "depth" / "10.5.png").string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(9)));
  const Result r = pspslam("run --sequence " + dir.string() + " --out " + (dir / "out").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: " + (dir / "depth" / "10.5.png").string() +
                                     ": depth image must be 16-bit single-channel (got 8-bit, 1 "
                                     "channel)\n"))
      << r.output;
}

TEST(CliRun, ConfigOfWrongImageSize) {
  const auto dir = make_sequence("cli", false);
  const Result r = pspslam("run --sequence " + dir.string() + " --out " + (dir / "out").string() +
                           " --config " + (source_dir() / "config" / "bonn.yaml").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(
      r.output, "error: " + (dir / "rgb" / "10.5.png").string() + " is 8x6 but the config " +
                    (source_dir() / "config" / "bonn.yaml").string() + " says camera 640x480\n"))
      << r.output;
}

TEST(CliRun, BonnCrowdDevSequenceReport) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const auto dir = shared / "data" / "bonn_crowd_dev";
  const auto out = testing::make_temp_dir("cli");
  // One frame is enough to check what `run` reports about the input before SLAM starts.
  const Result r =
      pspslam("run --max-frames 1 --sequence " + dir.string() + " --out " + out.string() +
              " --config " + (source_dir() / "config" / "bonn.yaml").string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_EQ(count_of(r.output, "warning:"), 1u) << r.output;
  EXPECT_TRUE(contains(r.output, "warning: " + dir.string() +
                                     ": 2 listed files are missing; skipped 0 frames (first: "
                                     "depth/1548339819.85514.png)\n"));
  EXPECT_TRUE(contains(r.output,
                       "frames:       400 (400 colour and 403 depth files listed, associated "
                       "within 0.02 s; 2 listed files missing, 0 frames skipped)"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "time span:    13.374 s")) << r.output;
  EXPECT_TRUE(contains(r.output, "ground truth: yes (404 poses in groundtruth.txt)")) << r.output;
  // Whatever SLAM made of one frame, the trajectory file is a valid TUM file.
  EXPECT_NO_THROW(read_tum_trajectory(out / "trajectory.txt"));
}

// --sensor kinect --no-fault NAME switches single faults off (named in info.yaml, and without
// distortion config.yaml has none); --no-fault needs the kinect sensor and a known fault name.
TEST(CliSynth, KinectSensorFaultSwitches) {
  const auto dir = testing::make_temp_dir("cli_kinect");
  Result r =
      pspslam("synth --out " + (dir / "seq").string() +
              " --frames 2 --bodies 1 --sensor kinect --no-fault distortion --no-fault marker");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(read_text(dir / "seq" / "info.yaml"),
                       "faults: depth-noise,holes,sync-offset,rolling-shutter,motion-blur,exposure,"
                       "handheld-motion\n"));
  EXPECT_TRUE(contains(read_text(dir / "seq" / "config.yaml"), "distortion: [0, 0, 0, 0, 0]"));
  EXPECT_TRUE(contains(read_text(dir / "seq" / "body_to_camera.txt"),
                       "\n0.000000000 0.000000000 "
                       "0.000000000 0.000000000 "
                       "0.000000000 0.000000000 "
                       "1.000000000\n"));
  r = pspslam("synth --out " + (dir / "b").string() + " --frames 2 --no-fault holes");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: synth: flag --no-fault needs --sensor kinect\n");
  r = pspslam("synth --out " + (dir / "c").string() +
              " --frames 2 --sensor kinect --no-fault blur");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: pspslam synth: --no-fault: blur not in {depth-noise,"))
      << r.output;
}

// --keyframe-ratio reaches the keyframe policy: on the same sequence, ORB-SLAM2's sparser 0.5
// makes fewer keyframes than 0.95; out-of-range values are errors.
TEST(CliRun, KeyframeRatioSetsTheKeyframeDensity) {
  const auto dir = testing::make_temp_dir("cli_keyframes");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 60 --bodies 0 --seed 2");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const auto keyframes = [&](const std::string& ratio) {
    const auto out = dir / ("out" + ratio);
    const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " + out.string() +
                             " --dynamic off --keyframe-ratio " + ratio);
    EXPECT_EQ(r.status, 0) << r.output;
    return read_tum_trajectory(out / "keyframes.txt").size();
  };
  const size_t sparse = keyframes("0.5"), dense = keyframes("0.95");
  EXPECT_GE(sparse, 1u);
  EXPECT_GT(dense, sparse);
  for (const std::string bad : {"0", "1.5"}) {
    const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " +
                             (dir / "bad").string() + " --keyframe-ratio " + bad);
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(contains(r.output,
                         "error: pspslam run: --keyframe-ratio: must be a number in "
                         "[0.01, 1], got '" +
                             bad + "'"))
        << r.output;
  }
}

// --ba-tracking-factors: local BA keeps tracking's relative poses between keyframes; the summary
// and stats.json say so, the run stays accurate, and local BA's CPU time is reported beside its
// wall time (never above it: Ceres runs on the local mapping thread).
TEST(CliRun, TrackingFactorsJoinLocalBundleAdjustment) {
  const auto dir = testing::make_temp_dir("cli_tracking_factors");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 90 --bodies 0 --seed 4");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " +
                           (dir / "out").string() + " --dynamic off --ba-tracking-factors 0.5");
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output,
                       "local BA window: every covisible keyframe, with tracking's "
                       "factors (weight 0.5)\n"))
      << r.output;
  std::ifstream in(dir / "out" / "stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_EQ(stats["scheduling"]["ba_tracking_factors"].get<double>(), 0.5);
  const nlohmann::json& timing = stats["timing_ms"];
  EXPECT_GT(timing["local_mapping_cpu"]["count"].get<int>(), 3);
  EXPECT_EQ(timing["local_mapping_cpu"]["count"], timing["local_mapping"]["count"]);
  EXPECT_LE(timing["local_mapping_cpu"]["median"].get<double>(),
            timing["local_mapping"]["median"].get<double>() + 0.5);
  EXPECT_LT(compute_ate(read_tum_trajectory(dir / "seq" / "groundtruth.txt"),
                        read_tum_trajectory(dir / "out" / "trajectory.txt"))
                .error.rmse,
            0.01);
}

// --start-frame skips the frames before it: the run tracks the rest, from a map started there,
// and the frames keep their sequence positions; a start beyond the sequence is an error.
TEST(CliRun, StartFrameSkipsTheFramesBeforeIt) {
  const auto dir = testing::make_temp_dir("cli_start_frame");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 45 --bodies 0 --seed 2");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const std::string run = "run --sequence " + (dir / "seq").string() + " --dynamic off";
  Result r = pspslam(run + " --start-frame 20 --out " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.output;
  EXPECT_TRUE(contains(r.output, "start:        frame 20 (--start-frame; 20 frames skipped)"))
      << r.output;
  const Trajectory online = read_tum_trajectory(dir / "out" / "trajectory.txt");
  const Trajectory truth = read_tum_trajectory(dir / "seq" / "groundtruth.txt");
  ASSERT_EQ(online.size(), 25u);
  EXPECT_DOUBLE_EQ(online.front().timestamp, truth[20].timestamp);
  EXPECT_DOUBLE_EQ(online.back().timestamp, truth[44].timestamp);
  EXPECT_LT(compute_ate(truth, online).error.rmse, 0.01);
  const nlohmann::json stats = nlohmann::json::parse(read_text(dir / "out" / "stats.json"));
  EXPECT_EQ(stats["frames"], 25) << stats.dump();

  r = pspslam(run + " --start-frame 45 --out " + (dir / "beyond").string());
  EXPECT_EQ(r.status, 2) << r.output;
  EXPECT_TRUE(contains(r.output, "error: --start-frame 45: " + (dir / "seq").string() +
                                     " holds 45 frames (0 .. 44)"))
      << r.output;
}

// Every run writes the config it used: OUT/run_config.yaml repeats the run exactly (here with a
// geometry: section and a --sensor override, which it carries), and stats.json names the config
// file and the binary's version.
TEST(CliRun, RunConfigRepeatsTheRun) {
  const auto dir = testing::make_temp_dir("cli_run_config");
  ASSERT_EQ(
      pspslam("synth --out " + (dir / "seq").string() + " --frames 30 --bodies 1 --seed 3").status,
      0);
  std::ofstream(dir / "tuned.yaml")
      << read_text(dir / "seq" / "config.yaml") << "geometry:\n  search:\n    band_width_px: 60\n";
  const Result first =
      pspslam("run --sequence " + (dir / "seq").string() + " --config " +
              (dir / "tuned.yaml").string() + " --dynamic geometry --out " + (dir / "a").string());
  ASSERT_EQ(first.status, 0) << first.output;
  const std::string used = read_text(dir / "a" / "run_config.yaml");
  EXPECT_TRUE(contains(used, "band_width_px: 60")) << used;
  const Result again = pspslam("run --sequence " + (dir / "seq").string() + " --config " +
                               (dir / "a" / "run_config.yaml").string() +
                               " --dynamic geometry --out " + (dir / "b").string());
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_EQ(read_text(dir / "a" / "trajectory.txt"), read_text(dir / "b" / "trajectory.txt"));
  const nlohmann::json stats = nlohmann::json::parse(read_text(dir / "a" / "stats.json"));
  EXPECT_EQ(stats["config"], (dir / "tuned.yaml").string());
  EXPECT_EQ(stats["version"].get<std::string>().rfind("pspslam 0.1.0 (git ", 0), 0u) << stats;

  const Result mono = pspslam("run --sequence " + (dir / "seq").string() +
                              " --sensor monocular --dynamic off --out " + (dir / "m").string());
  ASSERT_EQ(mono.status, 0) << mono.output;
  EXPECT_TRUE(contains(read_text(dir / "m" / "run_config.yaml"), "type: monocular"));
}

// --motion-prior reaches the pose-only optimisation: a prior of 1 mm / 0.05° makes the online
// positions follow the constant-velocity prediction, so their second differences (frame-to-frame
// changes of the velocity) shrink; σ ≤ 0 is an error.
TEST(CliRun, MotionPriorSmoothsTheOnlineTrajectory) {
  const auto dir = testing::make_temp_dir("cli_motion_prior");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 40 --bodies 0 --seed 3");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const auto roughness = [&](const std::string& name, const std::string& flags) {
    const auto out = dir / name;
    const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " + out.string() +
                             " --dynamic off --loop-closing off" + flags);
    EXPECT_EQ(r.status, 0) << r.output;
    const Trajectory online = read_tum_trajectory(out / "trajectory.txt");
    EXPECT_EQ(online.size(), 40u);
    double sum = 0.0;
    for (size_t i = 2; i < online.size(); ++i)
      sum += (online[i].T_world_camera.translation() -
              2.0 * online[i - 1].T_world_camera.translation() +
              online[i - 2].T_world_camera.translation())
                 .squaredNorm();
    return std::sqrt(sum / static_cast<double>(online.size() - 2));
  };
  const double free = roughness("free", "");
  const double smooth = roughness("prior", " --motion-prior 1 0.05");
  EXPECT_LT(smooth, 0.5 * free) << "second differences " << smooth << " vs " << free << " m";
  const Result bad = pspslam("run --sequence " + (dir / "seq").string() + " --out " +
                             (dir / "bad").string() + " --motion-prior 0 1");
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.output, "error: pspslam run: --motion-prior: must be a number in"))
      << bad.output;
}

// A sequence whose depth images are all empty never starts a map: `run` says why after a second
// of frames (the sequence's fps) and again at the end, and exits with status 3, leaving a valid
// (empty) trajectory and stats.json.
TEST(CliRun, SequenceWithoutDepthSaysWhyNoMapStarts) {
  const auto dir = testing::make_temp_dir("cli_no_depth");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 40 --bodies 0 --seed 2");
  ASSERT_EQ(synth.status, 0) << synth.output;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "seq" / "depth"))
    cv::imwrite(entry.path().string(), cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)));
  const auto out = dir / "out";
  const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " + out.string() +
                           " --dynamic off");
  EXPECT_EQ(r.status, 3) << r.output;
  const std::string why =
      " keypoints with a depth reading, 500 are needed to start one (are the depth images listed "
      "in depth.txt empty?)\n";
  EXPECT_TRUE(contains(r.output, "warning: no map after 30 frames: the best frame had 0" + why))
      << r.output;
  EXPECT_TRUE(contains(r.output, "error: no map after 40 frames: the best frame had 0" + why))
      << r.output;
  EXPECT_TRUE(read_tum_trajectory(out / "trajectory.txt").empty());
  EXPECT_TRUE(std::filesystem::exists(out / "stats.json"));
}

// --export-map / --export-dense on a rendered room: the map PLY holds exactly the map points
// the run reports, and the dense cloud, carried into the renderer's world with the first ground
// truth pose (SLAM's world is the first camera), lies inside the 7 x 6 x 2.8 m room.
TEST(CliRun, ExportsStaticMapAndDenseCloudAsPly) {
  const auto dir = testing::make_temp_dir("cli_export");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 40 --bodies 2 --seed 3");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const Result r =
      pspslam("run --sequence " + (dir / "seq").string() + " --out " + (dir / "out").string() +
              " --dynamic geometry --export-map " + (dir / "map.ply").string() +
              " --export-dense " + (dir / "dense.ply").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<ColoredPoint> map = read_point_cloud_ply(dir / "map.ply");
  const std::vector<ColoredPoint> dense = read_point_cloud_ply(dir / "dense.ply");
  EXPECT_TRUE(contains(r.output, " map points;")) << r.output;
  EXPECT_TRUE(contains(r.output, ", " + std::to_string(map.size()) + " map points;")) << r.output;
  EXPECT_TRUE(contains(r.output, "(" + std::to_string(map.size()) + " points)")) << r.output;
  EXPECT_GT(map.size(), 300u);
  EXPECT_GT(dense.size(), 5000u);
  const Trajectory truth = read_tum_trajectory(dir / "seq" / "groundtruth.txt");
  ASSERT_FALSE(truth.empty());
  const Pose T_room_slam = truth.front().T_world_camera;
  size_t outside = 0;
  for (const ColoredPoint& point : dense) {
    const Eigen::Vector3d p = T_room_slam * point.position.cast<double>();
    if (p.x() < -0.1 || p.y() < -0.1 || p.z() < -0.1 || p.x() > 7.1 || p.y() > 6.1 || p.z() > 2.9)
      ++outside;
  }
  EXPECT_LT(outside, dense.size() / 200) << outside << " of " << dense.size();
}

}  // namespace
}  // namespace pspslam

namespace pspslam {
namespace {

// Output paths are checked before anything is read: an --out below a regular file is a clear
// error with status 2 even though the sequence does not exist either.
TEST(CliRun, OutputUnderAFileIsRefusedBeforeAnyWork) {
  const auto dir = testing::make_temp_dir("cli_out_file");
  std::ofstream(dir / "plain") << "not a folder";
  Result r = pspslam("run --sequence " + (dir / "absent").string() + " --out " +
                     (dir / "plain" / "run").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: --out '" + (dir / "plain" / "run").string() + "': '" +
                          (dir / "plain").string() + "' is a file, not a folder\n");
  r = pspslam("run --sequence " + (dir / "absent").string() + " --out " + (dir / "ok").string() +
              " --save-map " + (dir / "plain" / "room.map").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: --save-map '" + (dir / "plain").string() + "': '" +
                          (dir / "plain").string() + "' is a file, not a folder\n");
}

// Flag values are checked by the parser, before the sequence is read (it does not exist here).
TEST(CliRun, FlagValuesAreCheckedBeforeAnyWork) {
  const std::string run = "run --sequence /nonexistent/sequence ";
  Result r = pspslam(run + "--dynamic foo");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --dynamic: must be one of off | semantic | geometry | full | "
            "exhaustive | auto, got 'foo' (see 'pspslam run --help')\n");
  r = pspslam(run + "--mask-margin 1000000000");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --mask-margin: must be an integer in [0, 100], got '1000000000' "
            "(see 'pspslam run --help')\n");
  r = pspslam(run + "--localization");
  EXPECT_EQ(r.output,
            "error: pspslam run: --localization: needs --load-map (a map to localise in) (see "
            "'pspslam run --help')\n");
  r = pspslam(run + "--blackout 3");
  EXPECT_EQ(r.output,
            "error: pspslam run: --blackout: --blackout expects FROM:COUNT (frame index and a "
            "positive number of frames), got '3' (see 'pspslam run --help')\n");
  r = pspslam(run + "--semantic-delay-ms random:300:100");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --semantic-delay-ms: expects MS or "
            "random:MIN:MAX (whole milliseconds, 0-10000, MIN <= MAX), got 'random:300:100' "
            "(see 'pspslam run --help')\n");
  r = pspslam(run + "--semantic-delay-seed 4");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --semantic-delay-seed: needs --semantic-delay-ms (see 'pspslam "
            "run --help')\n");
  r = pspslam(run + "--ba-tracking-factors -1");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --ba-tracking-factors: must be a number in [0, 1e+06], got '-1' "
            "(see 'pspslam run --help')\n");
  r = pspslam(run + "--new-map-after -1");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --new-map-after: must be a number in [0, 3600], got '-1' (see "
            "'pspslam run --help')\n");
  r = pspslam(run + "--local-ba-fixed-keyframes -3");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --local-ba-fixed-keyframes: must be an integer in [0, 1000], got "
            "'-3' (see 'pspslam run --help')\n");
  r = pspslam(run + "--max-frames -1");
  EXPECT_EQ(r.output,
            "error: pspslam run: --max-frames: must be an integer in [0, 1000000000], got '-1' "
            "(see 'pspslam run --help')\n");
  r = pspslam(run + "--realtme");
  EXPECT_EQ(r.output,
            "error: pspslam run: The following argument was not expected: --realtme (did you mean "
            "--realtime?) (see 'pspslam run --help')\n");
}

// A path the user types is relative to the current folder, not to the source tree.
TEST(CliRun, UserPathsAreRelativeToTheCurrentFolder) {
  const auto dir = make_sequence("cli_relative", true);
  std::ofstream(dir / "badvoc") << "not a vocabulary";
  Result r = pspslam_in(dir,
                        "run --sequence . --out out --dynamic off --loop-closing on "
                        "--vocabulary badvoc");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: vocabulary file 'badvoc': ")) << r.output;
  r = pspslam_in(dir, "run --sequence . --out out --dynamic full --model m.yaml");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output,
                       "error: --dynamic full: segmentation model not usable: cannot open "
                       "segmenter metadata 'm.yaml'"))
      << r.output;
}

// stats.json is JSON whatever the sequence path holds: quotes, backslashes, non-ASCII.
TEST(CliRun, StatsJsonEscapesTheSequencePath) {
  const auto base = make_sequence("cli_quotes", true);
  const auto dir = base.parent_path() / "bonn \"quoted\" back\\slash caf\xc3\xa9";
  std::filesystem::remove_all(dir);
  std::filesystem::rename(base, dir);
  const Result r = pspslam("run --sequence '" + dir.string() + "' --out '" +
                           (dir / "out").string() + "' --dynamic off");
  ASSERT_TRUE(std::filesystem::exists(dir / "out" / "stats.json")) << r.output;
  std::ifstream in(dir / "out" / "stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_EQ(stats["sequence"].get<std::string>(), dir.string());
  EXPECT_EQ(stats["mode"], "off");
  EXPECT_EQ(stats["frames"], 3);
}

// stats.json `live_masks`: a live run says how many frames ran on a stale mask and, per level of
// the semantic pace (the shipped network, the smaller one, then every 2nd and 3rd frame), how
// many frames ran while the thread was there; the frames add up to the frames with a level. A
// deterministic run has no such member and never steps down. An injected delay makes stale
// masks likely, but how many depends on the machine: only the bookkeeping is checked.
TEST(CliRun, LiveRunSaysWhatTheSemanticThreadSteppedDownTo) {
  const auto dir = testing::make_temp_dir("cli_live_masks");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 40 --bodies 2 --seed 4");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const std::string run = "run --sequence " + (dir / "seq").string() +
                          " --dynamic full --loop-closing off --semantic-delay-ms 100 --out ";
  const Result live = pspslam(run + (dir / "live").string() + " --realtime --semantic-pace on");
  ASSERT_EQ(live.status, 0) << live.output;
  EXPECT_TRUE(contains(live.output, "live masks:   ")) << live.output;
  EXPECT_TRUE(contains(live.output,
                       geteuid() == 0
                           ? "priority:     tracking at nice -10 (above busy programs of normal "
                             "priority)\n"
                           : ": raising it to -10 needs root or CAP_SYS_NICE, so busy programs "
                             "beside the run can make it drop frames (--priority 0 stops asking)"))
      << live.output;
  EXPECT_TRUE(contains(live.output, "semantic pace: frames at each level: 0 pspnet.yaml ("))
      << live.output;
  std::ifstream in(dir / "live" / "stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  const nlohmann::json& masks = stats["live_masks"];
  EXPECT_EQ(masks["stale_after_frames"].get<int>(), 2);
  EXPECT_EQ(masks["stale_masks"].get<std::string>(), "homography");
  EXPECT_LE(masks["frames_on_stale_mask"].get<int>(), stats["frames"].get<int>());
  // A live run's mask always arrives after its frame was tracked (a frame is announced when it
  // begins), so each frame a used mask was made for is judged when it arrives.
  EXPECT_TRUE(masks["cull_with_late_masks"].get<bool>());
  EXPECT_TRUE(contains(live.output, "culling by exact masks only: on (")) << live.output;
  ASSERT_GT(stats["mask_latency"]["frames"]["count"].get<int>(), 0) << live.output;
  EXPECT_GT(masks["late_frames_judged"].get<int>(), 0) << live.output;
  EXPECT_LE(masks["late_frames_judged"].get<int>(), stats["frames"].get<int>());
  EXPECT_LE(masks["culled_by_late_masks"].get<int>(),
            stats["dynamic"]["culled_map_points"].get<int>());
  // On a stale mask, poses are solved on the judged map points first; each pose that set newer
  // matches aside set at least one aside.
  EXPECT_TRUE(masks["judged_points_first"].get<bool>());
  // The mover guard is opt-in: no pose is held.
  EXPECT_EQ(masks["frames_pose_held"].get<int>(), 0);
  EXPECT_TRUE(contains(live.output, " 0 poses held at the motion model\n")) << live.output;
  EXPECT_TRUE(contains(live.output, "judged points first: on (")) << live.output;
  EXPECT_LE(masks["poses_judged_first"].get<int>(), stats["frames"].get<int>());
  EXPECT_GE(masks["unjudged_matches_set_aside"].get<int>(), masks["poses_judged_first"].get<int>());
  const nlohmann::json& levels = masks["pace"]["levels"];
  ASSERT_EQ(levels.size(), 4u);
  EXPECT_EQ(levels[1]["network"].get<std::string>(), "pspnet_288x192.yaml (288x192)");
  EXPECT_EQ(levels[3]["stride"].get<int>(), 3);
  int frames = 0;
  for (const nlohmann::json& level : levels) frames += level["frames"].get<int>();
  EXPECT_GT(frames, 0);
  EXPECT_LE(frames, stats["frames"].get<int>());
  EXPECT_EQ(masks["pace"]["frames_stepped_down"].get<int>(),
            stats["frames"].get<int>() - levels[0]["frames"].get<int>());

  const Result deterministic = pspslam(run + (dir / "deterministic").string());
  ASSERT_EQ(deterministic.status, 0) << deterministic.output;
  EXPECT_FALSE(contains(deterministic.output, "live masks:")) << deterministic.output;
  EXPECT_FALSE(contains(deterministic.output, "priority:")) << deterministic.output;
  std::ifstream in_deterministic(dir / "deterministic" / "stats.json");
  EXPECT_FALSE(nlohmann::json::parse(in_deterministic).contains("live_masks"));
}

// stats.json `latency`: with --realtime every processed frame has its arrival-to-pose time
// (the real-time figures); a deterministic run has no arrival times and reports none.
// `scheduling`: a real-time run lowers the background threads (nice 10), gives OpenCV one thread
// and local BA the best 10 covisible keyframes; a deterministic run changes none of them (the
// whole covisible window: 0); --background-nice / --opencv-threads / --local-ba-keyframes
// override. Both keep BLAS on one thread.
TEST(CliRun, RealtimeRunReportsArrivalToPoseLatency) {
  const auto dir = testing::make_temp_dir("cli_latency");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 30 --bodies 0 --seed 3");
  ASSERT_EQ(synth.status, 0) << synth.output;
  // The summary says which local BA window ran.
  const auto latency = [&](const std::string& name, const std::string& flags,
                           const std::string& window) {
    const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " +
                             (dir / name).string() + " --dynamic off " + flags);
    EXPECT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find(" local BAs cut short; local BA window: " + window + "\n"),
              std::string::npos)
        << r.output;
    std::ifstream in(dir / name / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(in);
    return std::tuple{stats["latency"], stats["frames"].get<int>(), stats["scheduling"]};
  };
  // timing.csv: each frame's arrival to pose, empty without an arrival, then the map's size and
  // the resident memory.
  const auto arrival_column = [&](const std::string& name) {
    std::ifstream in(dir / name / "timing.csv");
    std::string header;
    std::getline(in, header);
    EXPECT_TRUE(header.ends_with(",arrival_to_pose_ms,keyframes_in_map,map_points,rss_mib"))
        << header;
    std::vector<std::string> values;
    for (std::string row; std::getline(in, row);) {
      std::vector<std::string> fields;
      std::stringstream stream(row);
      for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
      EXPECT_EQ(fields.size(), 25u) << row;
      if (fields.size() != 25u) continue;
      EXPECT_GT(std::stod(fields[24]), 1.0) << row;  // resident memory, MiB
      values.push_back(fields[21]);
    }
    return values;
  };
  const auto [realtime, processed, live_scheduling] =
      latency("realtime", "--realtime", "the best 10 covisible keyframes");
  const std::vector<std::string> live_arrivals = arrival_column("realtime");
  ASSERT_EQ(live_arrivals.size(), static_cast<size_t>(processed));
  for (const std::string& value : live_arrivals) EXPECT_GT(std::stod(value), 0.0);
  EXPECT_EQ(live_scheduling["background_thread_nice"].get<int>(), 10);
  // Tracking asks for nice -10; only root (or CAP_SYS_NICE) gets it, and the others are told.
  if (geteuid() == 0) {
    EXPECT_EQ(live_scheduling["tracking_nice"].get<int>(), -10);
  } else {
    EXPECT_GE(live_scheduling["tracking_nice"].get<int>(), 0);
  }
  EXPECT_EQ(live_scheduling["opencv_threads"].get<int>(), 1);
  EXPECT_EQ(live_scheduling["local_ba_keyframes"].get<int>(), 10);
  EXPECT_EQ(realtime["arrival_to_pose_ms"]["count"].get<int>(), processed);
  const double median = realtime["arrival_to_pose_ms"]["median"].get<double>();
  EXPECT_GT(median, 0.0);
  EXPECT_GE(realtime["arrival_to_pose_ms"]["p99"].get<double>(), median);
  EXPECT_GE(realtime["arrival_to_pose_ms"]["max"].get<double>(),
            realtime["arrival_to_pose_ms"]["p99"].get<double>());
  const auto [deterministic, frames, scheduling] =
      latency("deterministic", "", "every covisible keyframe");
  EXPECT_EQ(frames, 30);
  EXPECT_EQ(deterministic["arrival_to_pose_ms"]["count"].get<int>(), 0);
  EXPECT_EQ(arrival_column("deterministic"), std::vector<std::string>(30, ""));
  EXPECT_EQ(scheduling["background_thread_nice"].get<int>(), 0);
  EXPECT_EQ(scheduling["tracking_nice"].get<int>(), getpriority(PRIO_PROCESS, 0));  // untouched
  EXPECT_EQ(scheduling["opencv_threads"].get<int>(), cv::getNumThreads());
  EXPECT_EQ(scheduling["local_ba_keyframes"].get<int>(), 0);
  // Every run keeps OpenBLAS on one thread (0: the BLAS is another one, with no threads to set).
  for (const nlohmann::json* run : {&live_scheduling, &scheduling}) {
    EXPECT_GE((*run)["blas_threads"].get<int>(), 0);
    EXPECT_LE((*run)["blas_threads"].get<int>(), 1);
  }
  const auto [chosen_latency, chosen_frames, chosen] =
      latency("chosen", "--realtime --background-nice 3 --opencv-threads 2 --local-ba-keyframes 0",
              "every covisible keyframe");
  EXPECT_EQ(chosen["background_thread_nice"].get<int>(), 3);
  EXPECT_EQ(chosen["opencv_threads"].get<int>(), 2);
  EXPECT_EQ(chosen["local_ba_keyframes"].get<int>(), 0);
}

// --segment-every: only every n-th frame goes to the network; the frames
// between use the newest mask moved by the homographies, so a deterministic run's mask ages are
// 0, 1, 0, 1, ... and the network runs on half the frames.
TEST(CliRun, SegmentEveryOtherFrameWarpsTheNewestMaskToTheRest) {
  const auto dir = testing::make_temp_dir("cli_segment_every");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 12 --bodies 2 --seed 5");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const Result r = pspslam("run --sequence " + (dir / "seq").string() + " --out " +
                           (dir / "out").string() + " --dynamic semantic --segment-every 2");
  ASSERT_EQ(r.status, 0) << r.output;
  std::ifstream in(dir / "out" / "stats.json");
  const nlohmann::json stats = nlohmann::json::parse(in);
  EXPECT_EQ(stats["scheduling"]["segment_every"].get<int>(), 2);
  EXPECT_EQ(stats["timing_ms"]["semantic"]["count"].get<int>(), 6);
  std::ifstream timing(dir / "out" / "timing.csv");
  std::string header;
  std::getline(timing, header);
  const auto columns = [](const std::string& line) {
    std::vector<std::string> fields;
    std::stringstream stream(line);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    return fields;
  };
  const std::vector<std::string> names = columns(header);
  const auto mask_age = std::find(names.begin(), names.end(), "mask_age") - names.begin();
  ASSERT_LT(mask_age, static_cast<std::ptrdiff_t>(names.size())) << header;
  std::vector<std::string> ages;
  for (std::string row; std::getline(timing, row);) ages.push_back(columns(row)[mask_age]);
  EXPECT_EQ(ages,
            (std::vector<std::string>{"0", "1", "0", "1", "0", "1", "0", "1", "0", "1", "0", "1"}));
  const Result bad = pspslam("run --sequence x --segment-every 0");
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.output,
            "error: pspslam run: --segment-every: must be an integer in [1, 30], got '0' (see "
            "'pspslam run --help')\n");
}

// Monocular loop closing: a colour-only run around a synthetic loop (1.25 turns in
// 480 frames, static room) closes the loop with a similarity, says by how much it resized the
// map, the trajectory gains from it and a second run is identical. The corrected map, saved,
// serves a localisation run, whose summary reports the loaded map instead of a two-view start.
TEST(CliRun, MonocularLoopIsClosedWithASimilarity) {
  const auto dir = testing::make_temp_dir("cli_mono_loop");
  const Result synth = pspslam("synth --out " + (dir / "seq").string() +
                               " --frames 480 --bodies 0 --trajectory loop --loop-turns 1.25 "
                               "--seed 1");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const auto out = dir / "out";
  const auto map_file = dir / "loop.map";
  const Result run = pspslam("run --sequence " + (dir / "seq").string() +
                             " --sensor monocular --dynamic off --out " + out.string() +
                             " --save-map " + map_file.string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(run.output, "loop closing: on\n")) << run.output;
  EXPECT_TRUE(contains(run.output, " closed (last moved its keyframe ")) << run.output;
  EXPECT_TRUE(contains(run.output, " map units, resized it x")) << run.output;
  const nlohmann::json stats = nlohmann::json::parse(read_text(out / "stats.json"));
  EXPECT_GE(stats["loops"]["closed"].get<int>(), 1);
  const double resized = stats["loops"]["last_correction"]["resized"].get<double>();
  EXPECT_GT(resized, 0.8);
  EXPECT_LT(resized, 1.25);
  EXPECT_NE(resized, 1.0) << "a monocular loop must estimate its scale";
  EXPECT_GE(stats["monocular"]["tracked_since_initialisation"].get<int>(), 470) << run.output;
  // The run must gain from loop closing in every file (Sim(3)). Deterministic since the tracker
  // waits for loop closing and the global BA (two runs byte-identical): keyframes.txt 4.7 mm,
  // trajectory_refined.txt 5.4 mm, trajectory.txt 9.1 mm, against 12.6 / 12.3 / 13.0 mm with
  // --loop-closing off. Before that wait, the frames tracked between the correction and the
  // global BA's write-back made the final file 6.4-15.8 mm from run to run.
  AteOptions sim3;
  sim3.sim3 = true;
  const AteResult keyframes = compute_ate(read_tum_trajectory(dir / "seq" / "groundtruth.txt"),
                                          read_tum_trajectory(out / "keyframes.txt"), sim3);
  EXPECT_LT(keyframes.error.rmse, 0.008) << run.output;
  EXPECT_LT(stats["ate_refined"]["rmse"].get<double>(), 0.008) << run.output;
  EXPECT_LT(stats["ate"]["rmse"].get<double>(), 0.0115) << run.output;
  // The same input gives the same run, loop and global BA included, whatever the load.
  const auto again_out = dir / "again";
  const Result repeated = pspslam("run --sequence " + (dir / "seq").string() +
                                  " --sensor monocular --dynamic off --out " + again_out.string());
  ASSERT_EQ(repeated.status, 0) << repeated.output;
  for (const char* file : {"trajectory.txt", "trajectory_refined.txt", "keyframes.txt"})
    EXPECT_EQ(read_text(out / file), read_text(again_out / file)) << file;

  const auto localised = dir / "localised";
  const Result again = pspslam("run --sequence " + (dir / "seq").string() +
                               " --sensor monocular --dynamic off --max-frames 120 --load-map " +
                               map_file.string() + " --localization --out " + localised.string());
  ASSERT_EQ(again.status, 0) << again.output;
  EXPECT_TRUE(contains(again.output,
                       "monocular:    map loaded (no two-view start); 120 of 120 frames tracked "
                       "(100.0 %)\n"))
      << again.output;
  const nlohmann::json localised_stats = nlohmann::json::parse(read_text(localised / "stats.json"));
  EXPECT_EQ(localised_stats["monocular"]["map_loaded"], true);
  EXPECT_LT(localised_stats["ate"]["rmse"].get<double>(), 0.010) << again.output;
}

// Monocular: the frames between the two views that start the map (matched with the first view
// while parallax grew) are placed in the new map, so every frame gets a pose: in time order
// ahead of the frame that started it, none left in lost_frames.txt, about as accurate as the
// frames tracked after (deterministic; this sequence starts at frame 12, the placed frames are at
// 3.1 mm RMS, max 4.7 mm, the rest at 3.6 mm, after one Sim(3) alignment of all 60).
TEST(CliRun, MonocularFramesBeforeTheMapStartArePlacedInIt) {
  const auto dir = testing::make_temp_dir("cli_mono_earlier");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 60 --bodies 0 --seed 2");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const auto out = dir / "out";
  const Result run = pspslam("run --sequence " + (dir / "seq").string() +
                             " --sensor monocular --dynamic off --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  const nlohmann::json stats = nlohmann::json::parse(read_text(out / "stats.json"));
  const int started = stats["monocular"]["initialised_at_frame"].get<int>();
  ASSERT_GE(started, 5) << "too early a start leaves nothing to place";
  EXPECT_EQ(stats["monocular"]["placed_before_initialisation"].get<int>(), started);
  EXPECT_EQ(stats["lost_frames"].get<int>(), 0);
  EXPECT_TRUE(contains(run.output, "frames:       60 processed, 60 tracked, 0 without pose"))
      << run.output;
  EXPECT_TRUE(contains(run.output, "monocular:    map started at frame " + std::to_string(started) +
                                       " (" + std::to_string(started) +
                                       " frames before it placed in the first map); "))
      << run.output;
  EXPECT_EQ(read_text(out / "lost_frames.txt"),
            "# frames without a pose (tracking not initialised or lost): index timestamp state\n");

  const Trajectory estimate = read_tum_trajectory(out / "trajectory.txt");
  const Trajectory ground_truth = read_tum_trajectory(dir / "seq" / "groundtruth.txt");
  ASSERT_EQ(estimate.size(), 60u);
  for (size_t i = 0; i < estimate.size(); ++i)
    EXPECT_NEAR(estimate[i].timestamp, ground_truth[i].timestamp, 1e-6) << "pose " << i;
  AteOptions sim3;
  sim3.sim3 = true;
  const AteResult ate = compute_ate(ground_truth, estimate, sim3);
  double placed_sum = 0.0, placed_max = 0.0, rest_sum = 0.0;
  for (const AtePair& pair : ate.pairs) {
    const bool placed = pair.est_index < static_cast<size_t>(started);
    (placed ? placed_sum : rest_sum) += pair.error * pair.error;
    if (placed) placed_max = std::max(placed_max, pair.error);
  }
  const double placed_rms = std::sqrt(placed_sum / started);
  const double rest_rms = std::sqrt(rest_sum / (60 - started));
  EXPECT_LT(placed_rms, 0.0045) << "the frames tracked after: " << rest_rms;
  EXPECT_LT(placed_rms, 1.25 * rest_rms);
  EXPECT_LT(placed_max, 0.008) << "the frames tracked after: " << rest_rms;
}

// The atlas, on a loop that turns 1.5 times (450 frames): one turn is frames 0-299, and from
// frame 300 the camera sees the start again. Per sensor:
// - two sessions: the first maps frames 0-149 and saves the map; the second loads it and starts at
//   frame 220, which the first never saw. Relocalisation fails for a second, a new map starts,
//   places the frames of that second (RGB-D: 228 of 230 with a pose; monocular: 208), and merges
//   into the loaded one when the camera reaches its area. The merged trajectory is in the loaded
//   map's frame, as accurate as a single session over the same frames (measured: RGB-D 4.2
//   against 6.8 mm, monocular 4.9 against 6.0 mm);
// - one session with frames 150-219 black: relocalisation gives up, a second map starts at frame
//   220 and merges back (RGB-D 10.7 mm, monocular 6.9 mm over the 380 frames with a pose).
TEST(CliRun, AtlasStartsNewMapsThatMergeWhenTheCameraReturns) {
  const auto dir = testing::make_temp_dir("cli_atlas");
  const std::string sequence = (dir / "seq").string();
  const Result synth = pspslam("synth --out " + sequence +
                               " --frames 450 --bodies 0 --trajectory loop --loop-turns 1.5 "
                               "--seed 2");
  ASSERT_EQ(synth.status, 0) << synth.output;
  for (const std::string sensor : {"rgbd", "monocular"}) {
    SCOPED_TRACE(sensor);
    const std::string run = "run --sequence " + sequence + " --dynamic off" +
                            (sensor == "monocular" ? " --sensor monocular" : "") + " --out ";
    const auto out = [&](const char* name) { return dir / (sensor + "_" + name); };
    const auto stats_of = [&](const char* name) {
      return nlohmann::json::parse(read_text(out(name) / "stats.json"));
    };
    const auto first_map = out("first.map");
    Result r =
        pspslam(run + out("first").string() + " --max-frames 150 --save-map " + first_map.string());
    ASSERT_EQ(r.status, 0) << r.output;
    r = pspslam(run + out("second").string() + " --start-frame 220 --load-map " +
                first_map.string() + " --save-map " + out("atlas.map").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_TRUE(
        contains(r.output, "atlas:        2 maps, 1 merge(s); the final files are in map 0"))
        << r.output;
    const nlohmann::json second = stats_of("second");
    EXPECT_EQ(second["atlas"]["maps_tracked_in"], 2);
    EXPECT_EQ(second["atlas"]["merges"][0]["from"], 1);
    EXPECT_EQ(second["atlas"]["merges"][0]["into"], 0);
    EXPECT_EQ(second["atlas"]["maps_at_end"], nlohmann::json({0}));
    EXPECT_EQ(second["atlas"]["other_map_poses"], 0);
    // The frames without a pose are those of the second spent relocalising before the new map
    // that it could not place.
    EXPECT_LE(second["lost_frames"].get<int>(), sensor == "monocular" ? 30 : 5);
    EXPECT_EQ(second["atlas"]["main_map_poses"].get<int>() + second["lost_frames"].get<int>(), 230);
    r = pspslam(run + out("single").string() + " --start-frame 220");
    ASSERT_EQ(r.status, 0) << r.output;
    const double single = stats_of("single")["ate_refined"]["rmse"].get<double>();
    EXPECT_LE(second["ate_refined"]["rmse"].get<double>(), 1.5 * single) << "single " << single;
    // The saved atlas holds the merged map alone; localising in it from the start needs no new map.
    r = pspslam(run + out("again").string() + " --max-frames 60 --localization --load-map " +
                out("atlas.map").string());
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_EQ(stats_of("again")["lost_frames"], 0) << r.output;

    r = pspslam(run + out("blackout").string() + " --blackout 150:70");
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json blackout = stats_of("blackout");
    EXPECT_EQ(blackout["atlas"]["maps_tracked_in"], 2) << r.output;
    EXPECT_EQ(blackout["atlas"]["merge_count"], 1) << r.output;
    EXPECT_EQ(blackout["atlas"]["maps"][1]["first_frame"], 220) << r.output;
    EXPECT_EQ(blackout["lost_frames"], 70);
    EXPECT_EQ(blackout["atlas"]["main_map_poses"], 380);
    EXPECT_LT(blackout["ate_refined"]["rmse"].get<double>(), 0.02) << r.output;
  }
}

// --video: a synthetic sequence's colour images encoded as MJPG (OpenCV's own
// encoder, in every build) run monocular to a trajectory timed by the video (1/30 s apart from
// 0); `eval` next to the run's stats.json aligns it with Sim(3) by itself and says why.
TEST(CliRun, VideoFileRunsMonocularAndEvalAlignsWithSim3) {
  const auto dir = testing::make_temp_dir("cli_video");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 120 --bodies 0 --seed 3");
  ASSERT_EQ(synth.status, 0) << synth.output;
  cv::VideoWriter writer((dir / "seq.avi").string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         30.0, cv::Size(640, 480));
  ASSERT_TRUE(writer.isOpened());
  std::ifstream list(dir / "seq" / "rgb.txt");
  int written = 0;
  for (std::string line; std::getline(list, line);) {
    if (line.empty() || line[0] == '#') continue;
    const std::string file = line.substr(line.find(' ') + 1);
    writer.write(cv::imread((dir / "seq" / file).string()));
    ++written;
  }
  writer.release();
  ASSERT_EQ(written, 120);

  const auto out = dir / "out";
  const Result run =
      pspslam("run --video " + (dir / "seq.avi").string() + " --config " +
              (dir / "seq" / "config.yaml").string() + " --dynamic off --out " + out.string());
  ASSERT_EQ(run.status, 0) << run.output;
  EXPECT_TRUE(contains(
      run.output, "video:        " + (dir / "seq.avi").string() + " (file, 120 frames, 30 fps"))
      << run.output;
  // Monocular loops are closed with a similarity (Sim(3)); a map without a metric unit reports
  // its corrections in map units.
  EXPECT_TRUE(contains(run.output, "loop closing: on\n")) << run.output;
  EXPECT_TRUE(contains(run.output, "loops:        0 closed, ")) << run.output;
  const Trajectory trajectory = read_tum_trajectory(out / "trajectory.txt");
  // The map starts within the first 30 frames and every frame after is tracked.
  ASSERT_GE(trajectory.size(), 90u) << run.output;
  for (size_t i = 1; i < trajectory.size(); ++i)
    EXPECT_NEAR(trajectory[i].timestamp - trajectory[i - 1].timestamp, 1.0 / 30.0, 1e-3);
  EXPECT_NEAR(trajectory.back().timestamp, 119.0 / 30.0, 1e-3);
  const nlohmann::json stats = nlohmann::json::parse(read_text(out / "stats.json"));
  EXPECT_EQ(stats["sensor"], "monocular");
  EXPECT_EQ(stats["monocular"]["map_restarts"], 0);
  EXPECT_LE(stats["monocular"]["initialised_at_frame"].get<int>(), 30);

  // The synthetic ground truth starts at t = 1000000 s, the video at 0.
  Trajectory ground_truth = read_tum_trajectory(dir / "seq" / "groundtruth.txt");
  const Timestamp start = ground_truth.front().timestamp;
  for (StampedPose& pose : ground_truth) pose.timestamp -= start;
  write_tum_trajectory(dir / "gt.txt", ground_truth);
  const std::string files =
      " --gt " + (dir / "gt.txt").string() + " --est " + (out / "trajectory.txt").string();
  const Result table = pspslam("eval" + files);
  ASSERT_EQ(table.status, 0) << table.output;
  EXPECT_TRUE(contains(table.output,
                       "alignment:    Sim(3) (the run's stats.json says sensor monocular), scale "))
      << table.output;
  const Result json = pspslam("eval" + files + " --json");
  ASSERT_EQ(json.status, 0) << json.output;
  const nlohmann::json report =
      nlohmann::json::parse(json.output.substr(0, json.output.rfind("}") + 1));
  EXPECT_EQ(report["ate"]["alignment"], "sim3");
  EXPECT_EQ(report["ate"]["alignment_reason"], "the run's stats.json says sensor monocular");
  EXPECT_LT(report["ate"]["error_m"]["rmse"].get<double>(), 0.05);

  // The same frames from the folder, colour only. Without the atlas (--new-map-after 0), black
  // frames two frames after the map started lose a map of a few keyframes: it is started again
  // after them rather than relocalised into.
  const Result folder = pspslam("run --sequence " + (dir / "seq").string() +
                                " --sensor monocular --dynamic off --out " + (dir / "f").string());
  ASSERT_EQ(folder.status, 0) << folder.output;
  const nlohmann::json folder_stats = nlohmann::json::parse(read_text(dir / "f" / "stats.json"));
  const int started = folder_stats["monocular"]["initialised_at_frame"];
  // The frames before the start that the first map placed (its first view and those between).
  const size_t first_placed = folder_stats["monocular"]["placed_before_initialisation"];
  const Result blackout = pspslam(
      "run --sequence " + (dir / "seq").string() + " --sensor monocular --dynamic off --blackout " +
      std::to_string(started + 2) + ":10 --new-map-after 0 --out " + (dir / "b").string());
  ASSERT_EQ(blackout.status, 0) << blackout.output;
  const nlohmann::json restarted = nlohmann::json::parse(read_text(dir / "b" / "stats.json"));
  EXPECT_EQ(restarted["monocular"]["map_restarts"], 1) << blackout.output;
  // The black frames lose the first map: one stretch, ended by the new map, in the summary too.
  EXPECT_EQ(restarted["lost_stretches"]["count"], 1) << blackout.output;
  EXPECT_EQ(restarted["lost_stretches"]["longest"]["first_frame"], started + 2);
  EXPECT_EQ(restarted["lost_stretches"]["longest"]["end"], "map_restarted");
  EXPECT_TRUE(contains(blackout.output,
                       "lost:         1 stretch after the map started; the longest: frames " +
                           std::to_string(started + 2) + "-"))
      << blackout.output;
  EXPECT_GT(restarted["monocular"]["initialised_at_frame"].get<int>(), started + 11);
  EXPECT_EQ(restarted["monocular"]["tracked_since_initialisation"],
            restarted["monocular"]["frames_since_initialisation"]);
  // The poses of the first map (another world frame and scale) left trajectory.txt: the frames
  // it placed at its start and the two it tracked. The new map's poses begin with the frames it
  // placed at its own start.
  const int restarted_at = restarted["monocular"]["initialised_at_frame"];
  const size_t placed_again = restarted["monocular"]["placed_before_initialisation"];
  ASSERT_LE(placed_again, static_cast<size_t>(restarted_at - (started + 12)));
  const Trajectory after = read_tum_trajectory(dir / "b" / "trajectory.txt");
  ASSERT_FALSE(after.empty());
  EXPECT_NEAR(after.front().timestamp,
              1000000.0 + static_cast<double>(restarted_at - static_cast<int>(placed_again)) / 30.0,
              1e-3);
  EXPECT_EQ(after.size(),
            restarted["monocular"]["tracked_since_initialisation"].get<size_t>() + placed_again);
  EXPECT_EQ(restarted["lost_frames"].get<size_t>(), 120 - after.size());
  EXPECT_EQ(count_of(read_text(dir / "b" / "lost_frames.txt"), " restarted\n"), first_placed + 2);

  // Errors: no intrinsics, a file that is not there, another sensor.
  Result bad =
      pspslam("run --video " + (dir / "seq.avi").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.output, "needs --config (the camera's intrinsics)")) << bad.output;
  bad = pspslam("run --video " + (dir / "missing.avi").string() + " --config " +
                (dir / "seq" / "config.yaml").string() + " --out " + (dir / "bad").string());
  EXPECT_NE(bad.status, 0);
  EXPECT_TRUE(
      contains(bad.output, "--video " + (dir / "missing.avi").string() + ": file not found"))
      << bad.output;
  bad = pspslam("run --video " + (dir / "seq.avi").string() + " --config " +
                (dir / "seq" / "config.yaml").string() + " --sensor stereo --out " +
                (dir / "bad").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.output, "is monocular; --sensor stereo needs a sequence folder"))
      << bad.output;
}

// A mistyped config key is named, with the key it probably meant.
TEST(CliRun, MistypedConfigKeyIsNamedWithASuggestion) {
  const auto dir = make_sequence("cli_typo", false);
  std::ofstream(dir / "typo.yaml")
      << "camera:\n  widht: 8\n  height: 6\n  fx: 10\n  fy: 10\n  cx: 4\n  cy: 3\n";
  const Result r = pspslam("run --sequence " + dir.string() + " --out " + (dir / "out").string() +
                           " --config " + (dir / "typo.yaml").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: " + (dir / "typo.yaml").string() +
                          ":2: unknown key 'camera.widht' (did you mean 'camera.width'?)\n");
}

TEST(Cli, VersionQuietAndLogLevel) {
  Result r = pspslam("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.output.rfind("pspslam 0.1.0 (git ", 0), 0u) << r.output;
  const auto dir = make_sequence("cli_quiet", true);
  r = pspslam("--quiet run --sequence " + dir.string() + " --out " + (dir / "q").string() +
              " --dynamic off");
  EXPECT_FALSE(contains(r.output, "slam [")) << r.output;  // no progress bar
  EXPECT_FALSE(contains(r.output, "debug: ")) << r.output;
  r = pspslam("run --log-level debug --sequence " + dir.string() + " --out " +
              (dir / "d").string() + " --dynamic off");
  EXPECT_TRUE(contains(r.output, "debug: frame 0 ")) << r.output;
  r = pspslam("--log-level chatty run --sequence x");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: pspslam run: --log-level: chatty not in {trace,debug,info,warn,error,off} (see "
            "'pspslam run --help')\n");
  r = pspslam("");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "commands:\n  run ")) << r.output;
  r = pspslam("evl --gt a");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output.substr(0, r.output.find('\n')),
            "error: pspslam: unknown command 'evl' (did you mean eval?)");
}

}  // namespace
}  // namespace pspslam

namespace pspslam {
namespace {

// Lines "timestamp path" of a TUM list, comments skipped.
std::vector<std::string> listed_files(const std::filesystem::path& list) {
  std::vector<std::string> files;
  std::ifstream in(list);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    files.push_back(line.substr(line.find(' ') + 1));
  }
  return files;
}

// --save-masks writes each processed frame's final dynamic mask, named after its colour image,
// and it lies on the people of the synthetic ground truth; --save-overlays a picture per frame.
TEST(CliRun, SaveMasksAndOverlaysPerProcessedFrame) {
  const auto dir = testing::make_temp_dir("cli_masks");
  const Result synth =
      pspslam("synth --out " + (dir / "seq").string() + " --frames 30 --bodies 2 --seed 5");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const Result r =
      pspslam("run --sequence " + (dir / "seq").string() + " --out " + (dir / "out").string() +
              " --dynamic full --max-frames 24 --save-masks " + (dir / "masks").string() +
              " --save-overlays " + (dir / "pictures" / "overlays").string());
  ASSERT_EQ(r.status, 0) << r.output;
  const std::vector<std::string> rgb = listed_files(dir / "seq" / "rgb.txt");
  const std::vector<std::string> truth = listed_files(dir / "seq" / "mask.txt");
  ASSERT_EQ(rgb.size(), 30u);
  ASSERT_EQ(truth.size(), 30u);
  const auto count_files = [](const std::filesystem::path& folder) {
    return std::distance(std::filesystem::directory_iterator(folder),
                         std::filesystem::directory_iterator());
  };
  EXPECT_EQ(count_files(dir / "masks"), 24);
  EXPECT_EQ(count_files(dir / "pictures" / "overlays"), 24);
  size_t intersection = 0, united = 0, truth_pixels = 0;
  for (size_t i = 0; i < 24; ++i) {
    const std::string name = std::filesystem::path(rgb[i]).stem().string() + ".png";
    const cv::Mat mask = cv::imread((dir / "masks" / name).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(mask.empty()) << name;
    ASSERT_EQ(mask.type(), CV_8UC1) << name;
    ASSERT_EQ(mask.size(), cv::Size(640, 480)) << name;
    EXPECT_EQ(cv::countNonZero(mask == 0) + cv::countNonZero(mask == 255), 640 * 480) << name;
    const cv::Mat labels = cv::imread((dir / "seq" / truth[i]).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(labels.size(), mask.size());
    const cv::Mat people = labels != 0;
    intersection += static_cast<size_t>(cv::countNonZero(mask & people));
    united += static_cast<size_t>(cv::countNonZero(mask | people));
    truth_pixels += static_cast<size_t>(cv::countNonZero(people));
    const cv::Mat overlay =
        cv::imread((dir / "pictures" / "overlays" / name).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(overlay.type(), CV_8UC3) << name;
    EXPECT_EQ(overlay.size(), cv::Size(640, 480)) << name;
  }
  ASSERT_GT(truth_pixels, 24u * 2000u);  // people are in view
  const double iou = static_cast<double>(intersection) / static_cast<double>(united);
  std::cout << "mask IoU with the ground truth over 24 frames: " << iou << "\n";
  EXPECT_GT(iou, 0.5);
}

// `--semantic-masks DIR` stands in for the network: a synthetic sequence's own person labels go
// in, and the run's saved masks are exactly those labels (semantic mode, no margin); the saved
// masks read back by a second run give the same trajectory.
TEST(CliRun, SemanticMasksFromAFolderReplaceTheNetwork) {
  const auto dir = testing::make_temp_dir("cli_semantic_masks");
  const auto seq = dir / "seq";
  const Result synth = pspslam("synth --out " + seq.string() + " --frames 30 --bodies 2 --seed 5");
  ASSERT_EQ(synth.status, 0) << synth.output;
  const std::string common =
      " --dynamic semantic --max-frames 12 --mask-margin 0 --loop-closing off";
  const Result first = pspslam("run --sequence " + seq.string() + " --out " + (dir / "a").string() +
                               common + " --semantic-masks " + (seq / "mask").string() +
                               " --save-masks " + (dir / "saved").string());
  ASSERT_EQ(first.status, 0) << first.output;
  EXPECT_TRUE(contains(first.output, "dynamic:      semantic (semantic masks from " +
                                         (seq / "mask").string() + "), deterministic"))
      << first.output;
  const std::vector<std::string> rgb = listed_files(seq / "rgb.txt");
  const std::vector<std::string> truth = listed_files(seq / "mask.txt");
  int person_pixels = 0;
  for (size_t i = 0; i < 12; ++i) {
    const std::string name = std::filesystem::path(rgb[i]).stem().string() + ".png";
    const cv::Mat saved = cv::imread((dir / "saved" / name).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat labels = cv::imread((seq / truth[i]).string(), cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(saved.empty()) << name;
    ASSERT_EQ(saved.size(), labels.size()) << name;
    EXPECT_EQ(cv::countNonZero(saved != ((labels != 0) & 255)), 0) << name;
    person_pixels += cv::countNonZero(labels);
  }
  EXPECT_GT(person_pixels, 12 * 2000);  // people are in view
  const Result second =
      pspslam("run --sequence " + seq.string() + " --out " + (dir / "b").string() + common +
              " --semantic-masks " + (dir / "saved").string());
  ASSERT_EQ(second.status, 0) << second.output;
  EXPECT_EQ(read_text(dir / "b" / "trajectory.txt"), read_text(dir / "a" / "trajectory.txt"));
}

TEST(CliRun, SemanticMasksThatDoNotFitAreClearErrors) {
  const auto dir = testing::make_temp_dir("cli_semantic_masks_bad");
  const auto seq = dir / "seq";
  const Result synth = pspslam("synth --out " + seq.string() + " --frames 3 --bodies 1 --seed 5");
  ASSERT_EQ(synth.status, 0) << synth.output;
  std::filesystem::create_directories(dir / "masks");
  const std::string run = "run --sequence " + seq.string() + " --out " + (dir / "out").string() +
                          " --semantic-masks " + (dir / "masks").string();
  Result r = pspslam(run + " --dynamic geometry");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output,
            "error: --semantic-masks replaces the network's masks, but --dynamic geometry uses "
            "none (use semantic, full or exhaustive)\n");

  const std::string first = listed_files(seq / "rgb.txt")[0];
  const auto expected_file =
      dir / "masks" / (std::filesystem::path(first).stem().string() + ".png");
  r = pspslam(run);
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: " + expected_file.string() +
                                     ": no semantic mask for frame " + first +
                                     " (--semantic-masks: an 8-bit PNG per frame, named after "
                                     "its colour image)\n"))
      << r.output;
  EXPECT_TRUE(contains(r.output, "dynamic:      full (semantic masks from")) << r.output;

  ASSERT_TRUE(cv::imwrite(expected_file.string(), cv::Mat(10, 12, CV_8UC1, cv::Scalar(0))));
  r = pspslam(run);
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: " + expected_file.string() +
                                     ": the mask is 12x10 but "
                                     "frame " +
                                     first + " is 640x480\n"))
      << r.output;
  // The run stopped at its first frame: its trajectory file is there, header only.
  EXPECT_TRUE(read_tum_trajectory(dir / "out" / "trajectory.txt").empty());

  r = pspslam("run --sequence " + seq.string() + " --out " + (dir / "out").string() +
              " --semantic-masks " + (dir / "absent").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "--semantic-masks: must be an existing folder, got '" +
                                     (dir / "absent").string() + "'"))
      << r.output;
}

TEST(CliRun, SaveMasksUnderAFileIsRefusedBeforeTheRun) {
  const auto dir = testing::make_temp_dir("cli_masks_file");
  std::ofstream(dir / "plain") << "not a folder";
  Result r = pspslam("run --sequence " + (dir / "absent").string() + " --out " +
                     (dir / "out").string() + " --save-masks " + (dir / "plain" / "m").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.output, "error: --save-masks '" + (dir / "plain" / "m").string() + "': '" +
                          (dir / "plain").string() + "' is a file, not a folder\n");
  r = pspslam("run --sequence " + (dir / "absent").string() + " --out " + (dir / "out").string() +
              " --save-overlays " + (dir / "plain").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.output, "error: --save-overlays '" + (dir / "plain").string() + "'"))
      << r.output;
}

}  // namespace
}  // namespace pspslam
