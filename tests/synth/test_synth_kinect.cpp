// pspslam synth --sensor kinect: every fault changes what it models and nothing else.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/io/trajectory_io.h"
#include "pspslam/io/tum_sequence.h"
#include "pspslam/synth/kinect.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::equal(a.datastart, a.dataend, b.datastart);
}

SynthOptions kinect_options(int bodies = 3) {
  SynthOptions options;
  options.frames = 120;
  options.bodies = bodies;
  options.seed = 1;
  options.threads = 2;
  options.sensor = SynthSensor::kKinect;
  return options;
}

SynthOptions no_faults(int bodies = 3) {
  SynthOptions options = kinect_options(bodies);
  for (const std::string& name : synth::KinectFaults::names()) options.faults.set(name, false);
  return options;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + static_cast<long>(values.size() / 2),
                   values.end());
  return values[values.size() / 2];
}

// Kinect with every fault off is the ideal sensor with exact depth, byte for byte: the faults
// are additions to the one renderer, not a second renderer.
TEST(SynthKinect, AllFaultsOffIsTheIdealSensorWithExactDepth) {
  SynthOptions ideal_options = kinect_options();
  ideal_options.sensor = SynthSensor::kIdeal;
  ideal_options.depth_noise = false;
  const SyntheticScene ideal(ideal_options), kinect(no_faults());
  for (const size_t index : {0u, 77u}) {
    const SynthFrame a = ideal.render(index), b = kinect.render(index);
    EXPECT_TRUE(same(a.bgr, b.bgr));
    EXPECT_TRUE(same(a.depth_sensor, b.depth_sensor));
    EXPECT_TRUE(same(a.labels, b.labels));
    EXPECT_TRUE(a.T_world_camera.isApprox(b.T_world_camera, 0.0));
  }
}

// Each fault alone, against all faults off: which images it changes.
TEST(SynthKinect, EachFaultChangesWhatItModelsAndNothingElse) {
  const SyntheticScene base_scene(no_faults());
  const size_t index = 45;
  const SynthFrame base = base_scene.render(index);
  struct Expect {
    std::string fault;
    bool colour, labels, depth;
  };
  const std::vector<Expect> expectations = {
      {"depth-noise", false, false, true}, {"holes", false, false, true},
      {"sync-offset", false, false, true}, {"rolling-shutter", true, true, false},
      {"motion-blur", true, false, false}, {"exposure", true, false, false},
      {"distortion", true, true, true},    {"handheld-motion", true, true, true},
      {"marker", false, false, false},
  };
  for (const Expect& expect : expectations) {
    SCOPED_TRACE(expect.fault);
    SynthOptions options = no_faults();
    options.faults.set(expect.fault, true);
    const SyntheticScene scene(options);
    const SynthFrame frame = scene.render(index);
    EXPECT_EQ(!same(frame.bgr, base.bgr), expect.colour);
    EXPECT_EQ(!same(frame.labels, base.labels), expect.labels);
    EXPECT_EQ(!same(frame.depth_sensor, base.depth_sensor), expect.depth);
    EXPECT_EQ(!frame.T_world_camera.isApprox(base.T_world_camera, 0.0),
              expect.fault == "handheld-motion");
    if (expect.fault == "holes") {
      // Holes only remove readings: every reading left is the exact one.
      const cv::Mat kept = frame.depth_sensor != 0;
      EXPECT_EQ(cv::norm(frame.depth_sensor, base.depth_sensor, cv::NORM_INF, kept), 0.0);
      const double hole_fraction = 1.0 - cv::countNonZero(kept) / double(kept.total());
      std::cout << "[ stats    ] kinect holes alone, frame " << index << ": " << hole_fraction
                << " of the pixels\n";
      EXPECT_GT(hole_fraction, 0.01);
      EXPECT_LT(hole_fraction, 0.35);
    }
    if (expect.fault == "exposure") {
      // One gain for the whole image: unsaturated pixels scale by it (to rounding).
      const double gain = synth::kinect_exposure_gain(options.seed, index / 30.0);
      std::vector<double> ratios;
      for (int y = 0; y < base.bgr.rows; y += 7) {
        for (int x = 0; x < base.bgr.cols; x += 7) {
          const int before = base.bgr.at<cv::Vec3b>(y, x)[1];
          const int after = frame.bgr.at<cv::Vec3b>(y, x)[1];
          if (before > 60 && after < 250) ratios.push_back(double(after) / before);
        }
      }
      EXPECT_NEAR(median(ratios), gain, 0.01);
    }
    if (expect.fault == "rolling-shutter") {
      // The middle rows are read at the frame's instant, the top and bottom 15 ms off it.
      cv::Mat diff;
      cv::absdiff(frame.bgr, base.bgr, diff);
      const double top = cv::mean(diff.rowRange(0, 40))[1];
      const double middle = cv::mean(diff.rowRange(228, 252))[1];
      EXPECT_GT(top, 3.0 * middle + 0.5) << "top " << top << ", middle " << middle;
    }
  }
}

// sigma_z = 1.425e-3 z^2: 9 x larger at 3 m than at 1 m.
TEST(SynthKinect, DepthNoiseGrowsWithTheSquareOfDepth) {
  const synth::KinectDepthModel model(7, 525.0);
  synth::KinectDepthModel::Switches noise_only;
  noise_only.quantisation = noise_only.holes = false;
  const cv::Mat cos_ones(480, 640, CV_32F, cv::Scalar(1.0f));
  const cv::Mat grey(480, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  double stds[2];
  for (const int k : {0, 1}) {
    const float z = k == 0 ? 1.0f : 3.0f;
    const cv::Mat exact(480, 640, CV_32F, cv::Scalar(z));
    cv::Mat out;
    model.apply(exact, cos_ones, grey, 3, noise_only, out);
    cv::Scalar mean, stddev;
    cv::meanStdDev(out - z, mean, stddev);
    stds[k] = stddev[0];
    EXPECT_NEAR(stddev[0], 1.425e-3 * z * z, 0.02 * 1.425e-3 * z * z);
    EXPECT_NEAR(mean[0], 0.0, 0.01 * 1.425e-3 * z * z);
  }
  EXPECT_NEAR(stds[1] / stds[0], 9.0, 0.3);
}

// Quantised in disparity: b f / z lands on 1/8 px steps, so far depths come in coarse levels.
TEST(SynthKinect, DepthIsQuantisedInOneEighthPixelDisparitySteps) {
  const double focal = 525.0, bf = synth::kKinectBaseline_m * focal;
  const synth::KinectDepthModel model(7, focal);
  synth::KinectDepthModel::Switches quantise_only;
  quantise_only.noise = quantise_only.holes = false;
  cv::Mat ramp(1, 1000, CV_32F);
  for (int i = 0; i < ramp.cols; ++i) ramp.at<float>(0, i) = 1.0f + 2.5f * i / ramp.cols;
  const cv::Mat cos_ones(1, 1000, CV_32F, cv::Scalar(1.0f));
  const cv::Mat grey(1, 1000, CV_8UC3, cv::Scalar(128, 128, 128));
  cv::Mat out;
  model.apply(ramp, cos_ones, grey, 0, quantise_only, out);
  std::set<float> levels_near, levels_far;
  for (int i = 0; i < ramp.cols; ++i) {
    const double z = out.at<float>(0, i);
    const double steps = bf / z * 8.0;
    EXPECT_NEAR(steps, std::round(steps), 1e-3) << z;
    // Rounding the disparity moves depth by at most half a step, z^2 / (b f) / 16.
    const double exact = ramp.at<float>(0, i);
    EXPECT_LE(std::abs(z - exact), exact * exact / bf / 16.0 * 1.01 + 1e-6);
    (exact < 1.5 ? levels_near : levels_far).insert(out.at<float>(0, i));
  }
  // Levels are 3.2 mm apart at 1 m and 29 mm at 3 m: the 0.5 m from 1 m hold 105 levels, the
  // 2 m beyond 1.5 m only 120.
  EXPECT_NEAR(double(levels_near.size()), bf * 8.0 * (1.0 / 1.0 - 1.0 / 1.5), 2.0);
  EXPECT_NEAR(double(levels_far.size()), bf * 8.0 * (1.0 / 1.5 - 1.0 / 3.5), 2.0);
}

// A foreground edge casts the projector's shadow on the background to its left, as wide as the
// baseline makes it: f b (1/z_near - 1/z_far) = 26 px for 1 m in front of 3 m.
TEST(SynthKinect, HolesFollowDepthEdgesDarkAndGrazingSurfaces) {
  const synth::KinectDepthModel model(7, 525.0);
  synth::KinectDepthModel::Switches holes_only;
  holes_only.noise = holes_only.quantisation = false;
  cv::Mat exact(40, 200, CV_32F, cv::Scalar(3.0f));
  exact.colRange(100, 200).setTo(1.0f);
  cv::Mat cos_map(40, 200, CV_32F, cv::Scalar(1.0f));
  cv::Mat bgr(40, 200, CV_8UC3, cv::Scalar(128, 128, 128));
  bgr(cv::Rect(150, 0, 20, 10)).setTo(cv::Scalar(10, 15, 20));  // a dark patch
  cos_map(cv::Rect(150, 20, 20, 10)).setTo(0.1f);               // a grazing patch
  cv::Mat out;
  model.apply(exact, cos_map, bgr, 0, holes_only, out);
  const double expected = model.shadow_width_px(1.0, 3.0);
  EXPECT_NEAR(expected, 26.25, 1e-9);
  for (int y = 0; y < 40; ++y) {
    int hole_begin = 100;
    while (hole_begin > 0 && out.at<float>(y, hole_begin - 1) == 0.0f) --hole_begin;
    EXPECT_NEAR(100 - hole_begin, expected, 1.0) << "row " << y;
    EXPECT_EQ(out.at<float>(y, hole_begin - 1), 3.0f);
    EXPECT_EQ(out.at<float>(y, 100), 0.0f);  // the mixed pixel on the near side of the edge
    EXPECT_EQ(out.at<float>(y, 101), 1.0f);  // no shadow on the near side
    EXPECT_EQ(out.at<float>(y, 160) == 0.0f, y < 10 || (y >= 20 && y < 30));
  }
}

// The depth of frame i is captured at t_i + offset_i: back-projected with the camera pose of that
// instant its pixels lie on the room's walls, floor and ceiling; with the colour instant's they
// miss them by the motion in up to 16 ms.
TEST(SynthKinect, SyncOffsetRendersDepthAtTheOffsetPose) {
  SynthOptions options = no_faults(0);
  options.faults.sync_offset = true;
  const SyntheticScene scene(options);
  size_t index = 0;
  while (std::abs(scene.depth_time_offset(index)) < 0.010) ++index;
  ASSERT_LT(index, options.frames);
  EXPECT_LE(std::abs(scene.depth_time_offset(index)), 0.016);
  const SynthFrame frame = scene.render(index);
  const double t = index / 30.0;
  const Pose at_depth = scene.camera_pose_at(t + scene.depth_time_offset(index));
  const Pose at_colour = scene.camera_pose(index);
  const Eigen::Vector3d room(7.0, 6.0, 2.8);
  const auto on_room_fraction = [&](const Pose& T_world_camera) {
    int on = 0, total = 0;
    for (int v = 0; v < 480; v += 4) {
      for (int u = 0; u < 640; u += 4) {
        const float z = frame.depth.at<float>(v, u);
        const Eigen::Vector3d p =
            T_world_camera * scene.camera().unproject(Eigen::Vector2d(u, v), z);
        double distance = 1e9;
        for (int a = 0; a < 3; ++a) {
          distance = std::min({distance, std::abs(p[a]), std::abs(p[a] - room[a])});
        }
        on += distance < 2e-4;
        ++total;
      }
    }
    return double(on) / total;
  };
  const double right = on_room_fraction(at_depth), wrong = on_room_fraction(at_colour);
  EXPECT_GT(right, 0.5);
  EXPECT_LT(wrong, 0.5 * right);
  // Colour is still rendered at the frame's own instant.
  EXPECT_TRUE(same(frame.bgr, SyntheticScene(no_faults(0)).render(index).bgr));
}

// The Bonn crowd clip's ground truth moves at a median 12.7 deg/s and 0.085 m/s frame to frame
// (bench/trajectory_error_bands.py's loader on groundtruth.txt, 404 poses): the kinect hand-held
// path matches both within 15 %; the ideal one turns a little faster and moves about twice as fast.
TEST(SynthKinect, HandheldMotionHasTheBonnClipsSpeeds) {
  const auto speeds = [](const SynthOptions& options) {
    std::vector<double> rotation, translation;
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      SynthOptions o = options;
      o.seed = seed;
      o.bodies = 0;
      o.frames = 400;
      const SyntheticScene scene(o);
      for (size_t i = 1; i < o.frames; ++i) {
        const Pose a = scene.camera_pose(i - 1), b = scene.camera_pose(i);
        rotation.push_back(Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 30.0 *
                           180.0 / M_PI);
        translation.push_back((b.translation() - a.translation()).norm() * 30.0);
      }
    }
    return std::pair{median(rotation), median(translation)};
  };
  const auto [kinect_rotation, kinect_translation] = speeds(kinect_options(0));
  std::cout << "[ stats    ] kinect hand-held median " << kinect_rotation << " deg/s, "
            << kinect_translation << " m/s\n";
  EXPECT_NEAR(kinect_rotation, 12.7, 0.15 * 12.7);
  EXPECT_NEAR(kinect_translation, 0.085, 0.15 * 0.085);
  SynthOptions ideal = kinect_options(0);
  ideal.sensor = SynthSensor::kIdeal;
  const auto [ideal_rotation, ideal_translation] = speeds(ideal);
  std::cout << "[ stats    ] ideal hand-held median " << ideal_rotation << " deg/s, "
            << ideal_translation << " m/s\n";
  EXPECT_GT(ideal_translation, 1.8 * kinect_translation);
  EXPECT_GT(ideal_rotation, kinect_rotation);
}

// Written files: groundtruth.txt is the marker body; body_to_camera.txt moves it onto the camera
// exactly (as `pspslam eval --gt-body-to-camera` does); config.yaml carries the distortion that
// `pspslam run` reads with load_config; same seed, same bytes.
TEST(SynthKinect, WrittenSequenceHasMarkerGroundTruthDistortionAndIsDeterministic) {
  SynthOptions options = kinect_options();
  options.frames = 4;
  const SyntheticScene scene(options);
  const fs::path dir = testing::make_temp_dir("synth_kinect_a");
  write_sequence(scene, dir);

  const Pose T_body_camera = read_rigid_transform(dir / "body_to_camera.txt");
  EXPECT_NEAR(T_body_camera.translation().norm(), 0.084, 0.001);  // a few cm off the lens
  EXPECT_TRUE(T_body_camera.isApprox(scene.T_body_camera(), 1e-8));
  const Trajectory marker = read_tum_trajectory(dir / "groundtruth.txt");
  const Trajectory camera = body_to_camera(marker, T_body_camera);
  ASSERT_EQ(camera.size(), 4u);
  for (size_t i = 0; i < camera.size(); ++i) {
    const Pose expected = scene.camera_pose(i);
    EXPECT_LT((camera[i].T_world_camera.translation() - expected.translation()).norm(), 1e-8);
    EXPECT_LT(Eigen::AngleAxisd(camera[i].T_world_camera.linear().transpose() * expected.linear())
                  .angle(),
              1e-8);
    // The marker itself is where the transform puts it, centimetres from the camera.
    EXPECT_NEAR((marker[i].T_world_camera.translation() - expected.translation()).norm(), 0.084,
                0.001);
  }

  const SystemConfig config = load_config(dir / "config.yaml");
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_DOUBLE_EQ(config.camera.pinhole.distortion[k], synth::kKinectDistortion[k]);
  }
  EXPECT_TRUE(config.camera.pinhole.has_distortion());

  options.threads = 1;
  const fs::path other = testing::make_temp_dir("synth_kinect_b");
  write_sequence(options, other);
  size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), dir);
    std::ifstream a(entry.path(), std::ios::binary), b(other / relative, std::ios::binary);
    const std::string bytes_a{std::istreambuf_iterator<char>(a), {}};
    const std::string bytes_b{std::istreambuf_iterator<char>(b), {}};
    EXPECT_EQ(bytes_a, bytes_b) << relative;
    ++files;
  }
  EXPECT_EQ(files, 4u * 3u + 9u);  // + body_to_camera.txt, people.txt
}

// depth.txt stamps (and names) each depth image with its own capture instant, as a Kinect driver
// does and as the Bonn recordings show; colour, masks and ground truth keep the colour instant.
// The pairs still associate one to one (|offset| <= 16 ms < half a frame interval).
TEST(SynthKinect, DepthListCarriesTheDepthCaptureInstant) {
  SynthOptions options = no_faults(3);
  options.frames = 6;
  options.faults.sync_offset = true;
  const SyntheticScene scene(options);
  const fs::path dir = testing::make_temp_dir("synth_kinect_stamps");
  write_sequence(scene, dir);
  const auto read_stamps = [](const fs::path& list) {
    std::ifstream in(list);
    std::vector<std::pair<double, std::string>> rows;
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      const size_t space = line.find(' ');
      rows.emplace_back(std::stod(line.substr(0, space)), line.substr(space + 1));
    }
    return rows;
  };
  const auto colour = read_stamps(dir / "rgb.txt");
  const auto depth = read_stamps(dir / "depth.txt");
  ASSERT_EQ(colour.size(), 6u);
  ASSERT_EQ(depth.size(), 6u);
  int offset_frames = 0;
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_NEAR(colour[i].first, scene.timestamp(i), 1e-6);
    EXPECT_NEAR(depth[i].first - colour[i].first, scene.depth_time_offset(i), 1.5e-6) << i;
    EXPECT_TRUE(fs::exists(dir / depth[i].second)) << depth[i].second;
    offset_frames += std::abs(scene.depth_time_offset(i)) > 1e-3;
  }
  EXPECT_GE(offset_frames, 4);  // the offset is drawn per frame within +-16 ms

  const TumSequence sequence = TumSequence::open(dir);
  ASSERT_EQ(sequence.size(), 6u);
  for (size_t i = 0; i < 6; ++i) {
    const InputFrame frame = sequence.load(i);
    EXPECT_NEAR(frame.depth_timestamp - frame.timestamp, scene.depth_time_offset(i), 1.5e-6);
  }
}

TEST(SynthKinect, ExposureDriftsSlowlyAndStepsSometimes) {
  int steps = 0;
  double low = 10.0, high = 0.0;
  for (int i = 1; i < 30 * 60; ++i) {
    const double before = synth::kinect_exposure_gain(1, (i - 1) / 30.0);
    const double now = synth::kinect_exposure_gain(1, i / 30.0);
    steps += std::abs(now / before - 1.0) > 0.01;
    low = std::min(low, now), high = std::max(high, now);
    EXPECT_LT(std::abs(now / before - 1.0), 0.3);  // a step moves between levels in +-12 %
  }
  EXPECT_GE(steps, 3);   // one 2 s segment in three jumps: ~10 in a minute
  EXPECT_LE(steps, 20);  // but no flicker
  EXPECT_GT(low, 0.75);
  EXPECT_LT(high, 1.25);
  EXPECT_GT(high - low, 0.12);
}

TEST(SynthKinect, FaultNamesAreCheckedAndDescribed) {
  synth::KinectFaults faults;
  EXPECT_EQ(faults.describe(),
            "depth-noise,holes,sync-offset,rolling-shutter,motion-blur,exposure,distortion,"
            "handheld-motion,marker");
  faults.set("rolling-shutter", false);
  EXPECT_FALSE(faults.is_on("rolling-shutter"));
  EXPECT_TRUE(faults.is_on("motion-blur"));
  try {
    faults.set("blur", false);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "synth: flag --no-fault: unknown fault 'blur'");
  }
  EXPECT_EQ(parse_synth_sensor("kinect"), SynthSensor::kKinect);
  EXPECT_THROW(parse_synth_sensor("kinect2"), Error);
}

}  // namespace
}  // namespace pspslam
