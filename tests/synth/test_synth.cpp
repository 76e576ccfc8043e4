#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "pspslam/config/config.h"
#include "pspslam/core/error.h"
#include "pspslam/synth/motion.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

namespace fs = std::filesystem;

SynthOptions small_options(int bodies = 3) {
  SynthOptions options;
  options.frames = 300;
  options.bodies = bodies;
  options.seed = 1;
  options.threads = 2;
  return options;
}

// Building a scene (drawing ~250 textures) costs more than rendering a few frames; tests that
// only read the default scenes share them (SyntheticScene is immutable after construction).
const SyntheticScene& default_scene(int bodies) {
  static const SyntheticScene with_people(small_options(3));
  static const SyntheticScene without_people(small_options(0));
  return bodies == 0 ? without_people : with_people;
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return std::nan("");
  const size_t k = std::min(values.size() - 1, static_cast<size_t>(fraction * values.size()));
  std::nth_element(values.begin(), values.begin() + static_cast<long>(k), values.end());
  return values[k];
}

struct Reprojection {
  std::vector<double> depth_error_m;  // |interpolated depth in frame b - depth of the moved point|
  std::vector<double> grey_error;     // |grey level in frame b - grey level in frame a|
};

// Moves every static pixel of frame a into frame b with the ground-truth poses and compares it
// with what frame b rendered there. Only points whose 4 neighbouring pixels in b all show the
// same (static) box face are used: that face is then visible in both frames (not occluded) and
// its inverse depth is an affine function of the pixel coordinates (1/z = n.(x_n, y_n, 1) / d
// for a plane n.X = d), so bilinear interpolation of 1/z is exact up to float rounding. Any
// error of the poses, the camera model or the depth rendering shows up in full.
Reprojection reproject(const SyntheticScene& scene, const SynthFrame& a, const SynthFrame& b) {
  const PinholeCamera& camera = scene.camera();
  const Pose T_b_a = b.T_world_camera.inverse() * a.T_world_camera;
  cv::Mat grey_a, grey_b;
  cv::cvtColor(a.bgr, grey_a, cv::COLOR_BGR2GRAY);
  cv::cvtColor(b.bgr, grey_b, cv::COLOR_BGR2GRAY);
  Reprojection result;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const float z = a.depth.at<float>(v, u);
      const uint16_t surface = a.surface_ids.at<uint16_t>(v, u);
      if (a.labels.at<uint8_t>(v, u) != kSynthLabelStatic || z <= 0.0f) continue;
      const Eigen::Vector3d p_b = T_b_a * camera.unproject(Eigen::Vector2d(u, v), z);
      if (p_b.z() < 0.1) continue;
      const Eigen::Vector2d uv = camera.project(p_b);
      if (uv.x() < 0 || uv.y() < 0 || uv.x() >= camera.width - 1 || uv.y() >= camera.height - 1) {
        continue;
      }
      const int x0 = static_cast<int>(uv.x()), y0 = static_cast<int>(uv.y());
      bool same_face = true;
      for (int dy = 0; dy < 2 && same_face; ++dy) {
        for (int dx = 0; dx < 2 && same_face; ++dx) {
          same_face = b.surface_ids.at<uint16_t>(y0 + dy, x0 + dx) == surface &&
                      b.labels.at<uint8_t>(y0 + dy, x0 + dx) == kSynthLabelStatic;
        }
      }
      if (!same_face) continue;
      const double fx = uv.x() - x0, fy = uv.y() - y0;
      const auto bilinear = [&](auto value) {
        return (value(x0, y0) * (1 - fx) + value(x0 + 1, y0) * fx) * (1 - fy) +
               (value(x0, y0 + 1) * (1 - fx) + value(x0 + 1, y0 + 1) * fx) * fy;
      };
      const double inverse_depth =
          bilinear([&](int x, int y) { return 1.0 / b.depth.at<float>(y, x); });
      result.depth_error_m.push_back(std::abs(1.0 / inverse_depth - p_b.z()));
      const double grey = bilinear([&](int x, int y) { return double(grey_b.at<uint8_t>(y, x)); });
      result.grey_error.push_back(std::abs(grey - grey_a.at<uint8_t>(v, u)));
    }
  }
  return result;
}

TEST(SynthScene, GroundTruthDepthAndPosesAreSelfConsistent) {
  const SyntheticScene& scene = default_scene(3);
  for (const size_t start : {0u, 100u, 200u}) {
    const SynthFrame a = scene.render(start);
    for (const size_t k : {1u, 5u}) {
      const SynthFrame b = scene.render(start + k);
      const Reprojection r = reproject(scene, a, b);
      const double median = percentile(r.depth_error_m, 0.5);
      const double p95 = percentile(r.depth_error_m, 0.95);
      std::cout << "[ stats    ] frames " << start << " -> " << start + k << ": "
                << r.depth_error_m.size() << " points, depth error median " << median * 1e3
                << " mm, p95 " << p95 * 1e3 << " mm; grey error median "
                << percentile(r.grey_error, 0.5) << "\n";
      SCOPED_TRACE("frames " + std::to_string(start) + " -> " + std::to_string(start + k) + ": " +
                   std::to_string(r.depth_error_m.size()) + " points, median " +
                   std::to_string(median * 1e3) + " mm, p95 " + std::to_string(p95 * 1e3) +
                   " mm, grey median " + std::to_string(percentile(r.grey_error, 0.5)));
      // Most of the image is static and stays visible over 1/6 s.
      EXPECT_GT(r.depth_error_m.size(), 100000u);
      EXPECT_LT(median, 1e-3);
      EXPECT_LT(p95, 1e-3);
      // Textures live on the surfaces: the same point has (almost) the same grey level in both
      // frames; what is left comes from resampling and the mip level changing with distance.
      EXPECT_LT(percentile(r.grey_error, 0.5), 6.0);
    }
  }
}

bool same_bytes(const cv::Mat& a, const cv::Mat& b) {
  return a.type() == b.type() && a.size() == b.size() && a.isContinuous() && b.isContinuous() &&
         std::equal(a.datastart, a.dataend, b.datastart);
}

TEST(SynthScene, SameSeedGivesIdenticalFramesOnAnyThreadCount) {
  SynthOptions one_thread = small_options();
  one_thread.threads = 1;
  const SyntheticScene first(one_thread);
  const SyntheticScene& second = default_scene(3);
  SynthOptions other_seed_options = small_options();
  other_seed_options.seed = 2;
  const SyntheticScene other_seed(other_seed_options);
  for (const size_t index : {0u, 17u, 150u}) {
    const SynthFrame a = first.render(index);
    const SynthFrame b = second.render(index);
    EXPECT_TRUE(same_bytes(a.bgr, b.bgr)) << "frame " << index;
    EXPECT_TRUE(same_bytes(a.depth, b.depth)) << "frame " << index;
    EXPECT_TRUE(same_bytes(a.depth_sensor, b.depth_sensor)) << "frame " << index;
    EXPECT_TRUE(same_bytes(a.labels, b.labels)) << "frame " << index;
    EXPECT_TRUE(a.T_world_camera.isApprox(b.T_world_camera, 0.0));
    EXPECT_FALSE(same_bytes(a.bgr, other_seed.render(index).bgr)) << "frame " << index;
  }
}

std::string file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(SynthSequence, SameSeedWritesByteIdenticalFiles) {
  SynthOptions options = small_options();
  options.frames = 3;
  const fs::path dir_a = testing::make_temp_dir("synth_a");
  const fs::path dir_b = testing::make_temp_dir("synth_b");
  write_sequence(options, dir_a);
  options.threads = 1;
  write_sequence(options, dir_b);
  size_t files = 0;
  for (const auto& entry : fs::recursive_directory_iterator(dir_a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path relative = fs::relative(entry.path(), dir_a);
    ASSERT_TRUE(fs::exists(dir_b / relative)) << relative;
    EXPECT_EQ(file_bytes(entry.path()), file_bytes(dir_b / relative)) << relative;
    ++files;
  }
  // rgb/depth/mask per frame; 4 lists, config, info, README, people.txt
  EXPECT_EQ(files, 3u * 3u + 8u);
}

TEST(SynthScene, StaticTwinHasNoDynamicPixelsAndMatchesTheDynamicSequence) {
  const SyntheticScene& dynamic_scene = default_scene(3);
  const SyntheticScene& static_scene = default_scene(0);
  for (size_t index = 0; index < 300; index += 25) {
    const SynthFrame s = static_scene.render(index);
    const SynthFrame d = dynamic_scene.render(index);
    EXPECT_EQ(cv::countNonZero(s.labels), 0) << "frame " << index;
    EXPECT_TRUE(s.T_world_camera.isApprox(d.T_world_camera, 0.0));
    // Wherever no person is in front, both show the very same static surface.
    cv::Mat static_in_dynamic = d.labels == kSynthLabelStatic;
    cv::Mat colour_differs, depth_differs;
    cv::compare(s.depth, d.depth, depth_differs, cv::CMP_NE);
    cv::Mat colour_diff;
    cv::absdiff(s.bgr, d.bgr, colour_diff);
    cv::cvtColor(colour_diff, colour_diff, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(colour_diff & static_in_dynamic), 0) << "frame " << index;
    EXPECT_EQ(cv::countNonZero(depth_differs & static_in_dynamic), 0) << "frame " << index;
  }
}

TEST(SynthScene, PeopleAndTheCarriedBoxAreOftenButNotAlwaysInView) {
  const SyntheticScene& scene = default_scene(3);
  int frames = 0, with_people = 0, with_large_people = 0, with_carried_box = 0;
  double largest_fraction = 0.0;
  SynthFrame frame;
  for (size_t index = 0; index < scene.frame_count(); index += 5) {
    scene.render(index, frame, 2);
    ++frames;
    const int pixels = static_cast<int>(frame.labels.total());
    const int person_pixels = cv::countNonZero(frame.labels == kSynthLabelPerson);
    const int carried_pixels = cv::countNonZero(frame.labels == kSynthLabelCarried);
    const int static_pixels = cv::countNonZero(frame.labels == kSynthLabelStatic);
    EXPECT_EQ(person_pixels + carried_pixels + static_pixels, pixels)
        << "unexpected label values in frame " << index;
    const double person = person_pixels / static_cast<double>(pixels);
    const double carried = carried_pixels / static_cast<double>(pixels);
    const double dynamic = person + carried;
    largest_fraction = std::max(largest_fraction, dynamic);
    with_people += dynamic > 0.01;
    with_large_people += dynamic > 0.15;
    with_carried_box += carried > 0.0;
  }
  std::cout << "[ stats    ] " << with_people << "/" << frames << " frames with people, "
            << with_large_people << " with > 15%, " << with_carried_box
            << " with the carried box, largest " << largest_fraction << "\n";
  SCOPED_TRACE(std::to_string(with_people) + "/" + std::to_string(frames) +
               " frames with people, " + std::to_string(with_large_people) + " with > 15%, " +
               std::to_string(with_carried_box) + " with the carried box, largest " +
               std::to_string(largest_fraction));
  EXPECT_GE(with_people, frames * 3 / 10);
  EXPECT_LE(with_people, frames * 95 / 100);
  EXPECT_GE(with_large_people, 3);
  EXPECT_GE(with_carried_box, 2);
  EXPECT_GT(largest_fraction, 0.3);
}

TEST(SynthMotion, PeopleWalkAtHumanSpeedsAndAreAboutOnePointSevenMetresTall) {
  const synth::RoomLayout room;
  for (const bool in_sector : {false, true}) {
    for (int index = 0; index < 6; ++index) {
      const synth::WalkingBody body(index, 7, index == 0, room,
                                    in_sector ? std::optional<double>(0.7) : std::nullopt);
      std::vector<synth::BodyPartPose> parts;
      double top = 0.0;
      for (double t = 0.0; t < 30.0; t += 0.25) {
        body.pose_parts(t, parts);
        const Eigen::Vector3d torso_before = parts[0].T_world_part.translation();
        body.pose_parts(t + 0.04, parts);
        const Eigen::Vector3d torso_after = parts[0].T_world_part.translation();
        // Chord over 0.04 s: the path speed, up to the path's curvature (< 1% here).
        const double speed = (torso_after - torso_before).head<2>().norm() / 0.04;
        EXPECT_GT(speed, 0.5) << "body " << index << " t " << t;
        EXPECT_LT(speed, 1.5) << "body " << index << " t " << t;
        const Eigen::Vector3d head = parts[1].T_world_part.translation();
        top = std::max(top, head.z() + parts[1].half_extents.z());
        // Feet stay on (or just above) the floor while walking; people stay inside the room,
        // clear of the furniture along the walls (>= 0.8 m from the walls).
        for (const size_t leg : {4u, 5u}) {
          const Eigen::Vector3d foot =
              parts[leg].T_world_part * Eigen::Vector3d(0, 0, -parts[leg].half_extents.z());
          EXPECT_GT(foot.z(), -0.01);
          EXPECT_LT(foot.z(), 0.15);
        }
        EXPECT_GT(torso_after.x(), 0.8);
        EXPECT_LT(torso_after.x(), room.size.x() - 0.8);
        EXPECT_GT(torso_after.y(), 0.8);
        EXPECT_LT(torso_after.y(), room.size.y() - 0.8);
      }
      EXPECT_GT(top, 1.6);
      EXPECT_LT(top, 1.85);
    }
  }
}

TEST(SynthMotion, APersonWhoStandsFirstStaysPutThenWalksTheSameLap) {
  const synth::RoomLayout room;
  const synth::WalkingBody walker(1, 7, false, room, 0.7);
  const synth::WalkingBody stander(1, 7, false, room, 0.7, 2.0);
  std::vector<synth::BodyPartPose> start, now, walking;
  stander.pose_parts(0.0, start);
  for (const double t : {0.5, 1.0, 2.0}) {
    stander.pose_parts(t, now);
    EXPECT_TRUE(now[0].T_world_part.isApprox(start[0].T_world_part)) << "t " << t;
  }
  // After standing, the same lap as the walker's, two seconds later.
  for (const double walked : {0.5, 3.0}) {
    stander.pose_parts(2.0 + walked, now);
    walker.pose_parts(walked, walking);
    EXPECT_TRUE(now[0].T_world_part.isApprox(walking[0].T_world_part)) << "walked " << walked;
  }
  stander.pose_parts(2.5, now);
  EXPECT_GT((now[0].T_world_part.translation() - start[0].T_world_part.translation()).norm(), 0.2);
}

TEST(SynthMotion, CameraMovesSmoothlyAndTheLoopRevisitsItsStart) {
  for (const SynthTrajectory kind : {SynthTrajectory::kHandheld, SynthTrajectory::kLoop}) {
    SynthOptions options = small_options(0);
    options.trajectory = kind;
    const SyntheticScene scene(options);
    const Trajectory gt = scene.ground_truth();
    ASSERT_EQ(gt.size(), 300u);
    double path_length = 0.0;
    for (size_t i = 1; i < gt.size(); ++i) {
      const Pose step = gt[i - 1].T_world_camera.inverse() * gt[i].T_world_camera;
      const double angle = Eigen::AngleAxisd(step.linear()).angle();
      EXPECT_LT(step.translation().norm(), 0.03) << to_string(kind) << " frame " << i;
      EXPECT_LT(angle, 2.0 * M_PI / 180.0) << to_string(kind) << " frame " << i;
      path_length += step.translation().norm();
    }
    if (kind == SynthTrajectory::kLoop) {
      EXPECT_GT(path_length, 5.0);
      double closest = 1e9, closest_angle = 0.0;
      for (size_t i = gt.size() * 85 / 100; i < gt.size(); ++i) {
        const Pose relative = gt[0].T_world_camera.inverse() * gt[i].T_world_camera;
        if (relative.translation().norm() < closest) {
          closest = relative.translation().norm();
          closest_angle = Eigen::AngleAxisd(relative.linear()).angle();
        }
      }
      EXPECT_LT(closest, 0.03);
      EXPECT_LT(closest_angle, 2.0 * M_PI / 180.0);
    }
  }
}

// One camera-frame cell grid count of FAST corners: ORB-SLAM needs corners everywhere.
TEST(SynthScene, TexturesGiveCornersAllOverTheImage) {
  for (const int bodies : {0, 3}) {
    const SyntheticScene& scene = default_scene(bodies);
    for (const size_t index : {0u, 120u, 240u}) {
      const SynthFrame frame = scene.render(index);
      cv::Mat grey;
      cv::cvtColor(frame.bgr, grey, cv::COLOR_BGR2GRAY);
      std::vector<cv::KeyPoint> corners;
      cv::FAST(grey, corners, 20, true);
      int cells_with_corners = 0;
      std::vector<int> per_cell(48, 0);
      for (const cv::KeyPoint& corner : corners) {
        ++per_cell[static_cast<size_t>(static_cast<int>(corner.pt.y / 80) * 8 +
                                       static_cast<int>(corner.pt.x / 80))];
      }
      for (const int count : per_cell) cells_with_corners += count >= 3;
      std::vector<cv::KeyPoint> orb_keypoints;
      cv::ORB::create(1000)->detect(grey, orb_keypoints);
      std::cout << "[ stats    ] bodies " << bodies << " frame " << index << ": " << corners.size()
                << " FAST corners, " << cells_with_corners << "/48 cells, " << orb_keypoints.size()
                << " ORB keypoints\n";
      SCOPED_TRACE("bodies " + std::to_string(bodies) + " frame " + std::to_string(index) + ": " +
                   std::to_string(corners.size()) + " FAST corners, " +
                   std::to_string(cells_with_corners) + "/48 cells, " +
                   std::to_string(orb_keypoints.size()) + " ORB keypoints");
      EXPECT_GE(corners.size(), 500u);
      EXPECT_GE(cells_with_corners, 40);
      EXPECT_GE(orb_keypoints.size(), 900u);
    }
  }
}

std::vector<std::vector<std::string>> read_list(const fs::path& file) {
  std::ifstream in(file);
  EXPECT_TRUE(in.good()) << file;
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::vector<std::string> row;
    for (std::string field; fields >> field;) row.push_back(field);
    rows.push_back(row);
  }
  return rows;
}

TEST(SynthSequence, WrittenFilesLoadBackAsTumLayout) {
  SynthOptions options = small_options();
  options.frames = 5;
  options.seed = 3;
  const SyntheticScene scene(options);
  const fs::path dir = testing::make_temp_dir("synth_files");
  size_t last_progress = 0;
  write_sequence(scene, dir, [&](size_t done) {
    EXPECT_GT(done, last_progress);
    last_progress = done;
  });
  EXPECT_EQ(last_progress, 5u);

  const auto rgb = read_list(dir / "rgb.txt");
  const auto depth = read_list(dir / "depth.txt");
  const auto mask = read_list(dir / "mask.txt");
  const auto gt = read_list(dir / "groundtruth.txt");
  ASSERT_EQ(rgb.size(), 5u);
  ASSERT_EQ(depth.size(), 5u);
  ASSERT_EQ(mask.size(), 5u);
  ASSERT_EQ(gt.size(), 5u);
  double previous = 0.0;
  for (size_t i = 0; i < 5; ++i) {
    ASSERT_EQ(rgb[i].size(), 2u);
    ASSERT_EQ(gt[i].size(), 8u);
    EXPECT_EQ(rgb[i][0], depth[i][0]);
    EXPECT_EQ(rgb[i][0], mask[i][0]);
    EXPECT_EQ(rgb[i][0], gt[i][0]);
    EXPECT_EQ(rgb[i][0].size(), std::string("1000000.000000").size());
    EXPECT_EQ(rgb[i][1], "rgb/" + rgb[i][0] + ".png");
    const double stamp = std::stod(rgb[i][0]);
    if (i == 0) {
      EXPECT_EQ(stamp, 1000000.0);
    } else {
      EXPECT_NEAR(stamp - previous, 1.0 / 30.0, 2e-6);
    }
    previous = stamp;

    const SynthFrame frame = scene.render(i);
    const cv::Mat colour = cv::imread((dir / rgb[i][1]).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat depth16 = cv::imread((dir / depth[i][1]).string(), cv::IMREAD_UNCHANGED);
    const cv::Mat labels = cv::imread((dir / mask[i][1]).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(colour.type(), CV_8UC3);
    ASSERT_EQ(depth16.type(), CV_16UC1);
    ASSERT_EQ(labels.type(), CV_8UC1);
    EXPECT_TRUE(same_bytes(colour, frame.bgr));
    EXPECT_TRUE(same_bytes(labels, frame.labels));
    cv::Mat metres;
    depth16.convertTo(metres, CV_32F, 1.0 / 5000.0);
    EXPECT_LT(cv::norm(metres, frame.depth_sensor, cv::NORM_INF), 1e-6);

    const Pose pose = scene.camera_pose(i);
    const Eigen::Quaterniond q(std::stod(gt[i][7]), std::stod(gt[i][4]), std::stod(gt[i][5]),
                               std::stod(gt[i][6]));
    EXPECT_NEAR(std::stod(gt[i][1]), pose.translation().x(), 1e-8);
    EXPECT_NEAR(std::stod(gt[i][2]), pose.translation().y(), 1e-8);
    EXPECT_NEAR(std::stod(gt[i][3]), pose.translation().z(), 1e-8);
    EXPECT_NEAR(q.norm(), 1.0, 1e-8);
    EXPECT_LT((q.toRotationMatrix() - pose.linear()).norm(), 1e-7);
  }

  const SystemConfig config = load_config(dir / "config.yaml");
  EXPECT_EQ(config.camera.name, "synthetic");
  EXPECT_EQ(config.camera.pinhole.fx, 525.0);
  EXPECT_EQ(config.camera.pinhole.fy, 525.0);
  EXPECT_EQ(config.camera.pinhole.cx, 319.5);
  EXPECT_EQ(config.camera.pinhole.cy, 239.5);
  EXPECT_FALSE(config.camera.pinhole.has_distortion());
  EXPECT_EQ(config.camera.fps, 30.0);
  EXPECT_EQ(config.camera.depth_factor, 5000.0);
  EXPECT_EQ(config.camera.depth_threshold, 4.0);
  EXPECT_NE(file_bytes(dir / "info.yaml").find("seed: 3\n"), std::string::npos);
}

TEST(SynthSensor, DepthNoiseGrowsWithDistanceAndHolesAreFew) {
  const SyntheticScene& noisy = default_scene(3);
  SynthOptions exact_options = small_options();
  exact_options.depth_noise = false;
  const SyntheticScene exact(exact_options);
  std::vector<double> near_errors, far_errors;
  double hole_fraction = 0.0;
  for (const size_t index : {0u, 60u, 120u}) {
    const SynthFrame frame = noisy.render(index);
    const SynthFrame exact_frame = exact.render(index);
    EXPECT_TRUE(same_bytes(frame.depth, exact_frame.depth));
    EXPECT_EQ(cv::countNonZero(exact_frame.depth_sensor == 0), 0);
    EXPECT_LT(cv::norm(exact_frame.depth_sensor, exact_frame.depth, cv::NORM_INF),
              1.0 / 10000 + 1e-6);
    hole_fraction += cv::countNonZero(frame.depth_sensor == 0) / double(frame.depth.total()) / 3.0;
    for (int v = 0; v < frame.depth.rows; ++v) {
      for (int u = 0; u < frame.depth.cols; ++u) {
        const float z = frame.depth.at<float>(v, u), measured = frame.depth_sensor.at<float>(v, u);
        if (measured == 0.0f) {
          continue;
        }
        if (z > 0.8f && z < 1.5f) near_errors.push_back(std::abs(measured - z));
        if (z > 3.5f && z < 4.5f) far_errors.push_back(std::abs(measured - z));
        EXPECT_LE(z, 5.0f);  // beyond the maximum range there is no reading
      }
    }
  }
  // sigma(z) = 1.2 mm + 1.9 mm (z - 0.4)^2: median |error| = 0.674 sigma.
  const double near_median = percentile(near_errors, 0.5), far_median = percentile(far_errors, 0.5);
  std::cout << "[ stats    ] holes " << hole_fraction << ", median |error| at 0.8-1.5 m "
            << near_median * 1e3 << " mm, at 3.5-4.5 m " << far_median * 1e3 << " mm\n";
  SCOPED_TRACE("holes " + std::to_string(hole_fraction) + ", median |error| near " +
               std::to_string(near_median * 1e3) + " mm, far " + std::to_string(far_median * 1e3) +
               " mm");
  EXPECT_GT(hole_fraction, 0.005);
  EXPECT_LT(hole_fraction, 0.25);
  EXPECT_GT(near_median, 0.0005);
  EXPECT_LT(near_median, 0.003);
  EXPECT_GT(far_median, 0.008);
  EXPECT_LT(far_median, 0.03);
}

TEST(SynthOptions, InvalidValuesAreRejectedNamingTheFlag) {
  const auto message_of = [](const auto& action) {
    try {
      action();
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  SynthOptions options;
  options.bodies = -1;
  EXPECT_NE(message_of([&] { options.validate(); }).find("--bodies must be in [0, 200], got -1"),
            std::string::npos);
  options = SynthOptions{};
  options.frames = 0;
  EXPECT_NE(message_of([&] { options.validate(); }).find("--frames must be >= 1, got 0"),
            std::string::npos);
  options = SynthOptions{};
  options.stand_seconds = -1.0;
  EXPECT_NE(message_of([&] {
              options.validate();
            }).find("--stand-seconds must be in [0, 3600], got -1.000000"),
            std::string::npos);
  EXPECT_NE(message_of([] {
              parse_synth_trajectory("circle");
            }).find("--trajectory expects 'handheld' or 'loop', got 'circle'"),
            std::string::npos);
  EXPECT_EQ(parse_synth_trajectory("loop"), SynthTrajectory::kLoop);
  SynthOptions two_frames;
  two_frames.frames = 2;
  two_frames.bodies = 0;
  const SyntheticScene scene(two_frames);
  EXPECT_NE(message_of([&] { scene.render(2); }).find("frame index 2 is past the sequence end"),
            std::string::npos);
  // More carriers than people: every person carries one, nobody else appears.
  two_frames.bodies = 1;
  two_frames.carried_objects = 4;
  EXPECT_EQ(SyntheticScene(two_frames).options().carried_objects, 1);
}

TEST(SynthSequence, RefusesAnOutputPathThatIsAFile) {
  const fs::path dir = testing::make_temp_dir("synth_file_out");
  const fs::path file = dir / "not_a_dir";
  std::ofstream(file) << "x";
  SynthOptions options = small_options(0);
  options.frames = 1;
  try {
    write_sequence(options, file);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("exists and is not a directory"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos);
  }
}

}  // namespace
}  // namespace pspslam
