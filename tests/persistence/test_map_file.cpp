#include <gtest/gtest.h>

#include "support/test_support.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/persistence/map_file.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "pspslam/system/system.h"
#include "support/input_frames.h"

namespace pspslam {
namespace {

struct StoredFrame {
  Timestamp timestamp = 0.0;
  cv::Mat gray;
  cv::Mat depth;
};

// One SLAM run on a short static synthetic sequence (exact depth), its trajectory and its saved
// map, shared by the tests below; the rendered frames are kept to localise on them again.
class MapFileTest : public ::testing::Test {
 protected:
  static constexpr size_t kFrames = 90;

  static void SetUpTestSuite() {
    SynthOptions synth;
    synth.frames = kFrames;
    synth.bodies = 0;
    synth.seed = 2;
    synth.threads = 1;
    synth.depth_noise = false;
    const SyntheticScene scene(synth);
    frames_ = new std::vector<StoredFrame>();
    trajectory_ = new Trajectory();
    directory_ = new std::filesystem::path(testing::make_temp_dir("map_file"));
    System system(synthetic_system_config());
    SynthFrame frame;
    for (size_t i = 0; i < kFrames; ++i) {
      scene.render(i, frame, 1);
      StoredFrame stored{scene.timestamp(i), {}, frame.depth_sensor.clone()};
      cv::cvtColor(frame.bgr, stored.gray, cv::COLOR_BGR2GRAY);
      const FrameReport report =
          system.process(grey_depth_frame(stored.timestamp, stored.gray, stored.depth));
      ASSERT_TRUE(report.tracking.T_world_camera) << "frame " << i;
      frames_->push_back(std::move(stored));
    }
    system.shutdown();
    *trajectory_ = system.refined_trajectory();
    const auto [keyframes, points] = system.save_map(map_file());
    keyframes_saved_ = keyframes;
    points_saved_ = points;
    // The live map, to compare the loaded one with.
    for (const auto& point : system.map().map_points())
      live_first_keyframe_[point->id()] = point->first_keyframe_id;
    for (const auto& keyframe : system.map().keyframes()) {
      live_keyframes_.push_back(
          {keyframe->id(), keyframe->T_camera_world(), keyframe->size(),
           keyframe->tracked_map_points(1), keyframe->covisibles().size(),
           keyframe->parent() ? static_cast<int>(keyframe->parent()->id()) : -1});
    }
  }
  static void TearDownTestSuite() {
    delete frames_;
    delete trajectory_;
    delete directory_;
  }

  static std::filesystem::path map_file() { return *directory_ / "map.pspmap"; }
  static std::string read_bytes(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }
  static std::filesystem::path write_bytes(const std::string& name, const std::string& bytes) {
    const std::filesystem::path file = *directory_ / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return file;
  }
  // Loads into a fresh map with the synthetic camera; returns the error message ("" if none).
  static std::string load_error(const std::filesystem::path& file, double fx_change = 0.0) {
    const SystemConfig config = synthetic_system_config();
    CameraModel camera = CameraModel::from_config(config.camera, 0.08);
    camera.pinhole.fx += fx_change;
    Map map;
    try {
      load_map(file, map, std::make_shared<const CameraModel>(camera),
               std::make_shared<const ScalePyramid>(
                   ScalePyramid::from_config(read_orb_config(config.orb))));
    } catch (const Error& e) {
      EXPECT_EQ(map.num_keyframes(), 0u) << "a failed load must leave the map untouched";
      return e.what();
    }
    return "";
  }

  struct LiveKeyFrame {
    std::uint64_t id;
    Pose T_camera_world;
    int keypoints;
    int points;
    size_t covisibles;
    int parent;
  };
  static inline std::vector<StoredFrame>* frames_ = nullptr;
  static inline Trajectory* trajectory_ = nullptr;
  static inline std::filesystem::path* directory_ = nullptr;
  static inline size_t keyframes_saved_ = 0;
  static inline size_t points_saved_ = 0;
  static inline std::vector<LiveKeyFrame> live_keyframes_;
  static inline std::map<std::uint64_t, std::uint64_t> live_first_keyframe_;  // by point id
};

TEST_F(MapFileTest, LoadRebuildsTheSameKeyframesPointsAndGraph) {
  const SystemConfig config = synthetic_system_config();
  Map map;
  const MapFileSummary summary = load_map(
      map_file(), map,
      std::make_shared<const CameraModel>(CameraModel::from_config(config.camera, 0.08)),
      std::make_shared<const ScalePyramid>(ScalePyramid::from_config(read_orb_config(config.orb))));
  EXPECT_EQ(summary.keyframes, keyframes_saved_);
  EXPECT_EQ(summary.map_points, points_saved_);
  EXPECT_EQ(summary.bytes, std::filesystem::file_size(map_file()));
  const auto keyframes = map.keyframes();
  ASSERT_EQ(keyframes.size(), live_keyframes_.size());
  ASSERT_GE(keyframes.size(), 3u);
  EXPECT_EQ(map.num_map_points(), points_saved_);
  // Keyframes and points made after loading get new ids.
  EXPECT_GT(map.next_keyframe_id(), keyframes.back()->id());
  std::uint64_t max_point_id = 0;
  for (const auto& point : map.map_points()) max_point_id = std::max(max_point_id, point->id());
  // Each point keeps the id of the keyframe that made it, even one culled before saving.
  size_t first_keyframe_culled = 0;
  for (const auto& point : map.map_points()) {
    ASSERT_TRUE(live_first_keyframe_.contains(point->id())) << "point " << point->id();
    EXPECT_EQ(point->first_keyframe_id, live_first_keyframe_.at(point->id()))
        << "point " << point->id();
    if (!map.keyframe(point->first_keyframe_id)) ++first_keyframe_culled;
  }
  std::cout << "points whose first keyframe was culled: " << first_keyframe_culled << "\n";
  EXPECT_GT(map.next_map_point_id(), max_point_id);
  for (size_t k = 0; k < keyframes.size(); ++k) {
    const LiveKeyFrame& live = live_keyframes_[k];
    // Ids as saved (the live map has gaps where local mapping culled keyframes).
    EXPECT_EQ(keyframes[k]->id(), live.id) << "keyframe " << k;
    EXPECT_TRUE(keyframes[k]->T_camera_world().isApprox(live.T_camera_world, 1e-12))
        << "keyframe " << k;
    EXPECT_EQ(keyframes[k]->size(), live.keypoints) << "keyframe " << k;
    EXPECT_EQ(keyframes[k]->tracked_map_points(1), live.points) << "keyframe " << k;
    EXPECT_EQ(keyframes[k]->covisibles().size(), live.covisibles) << "keyframe " << k;
    EXPECT_EQ(keyframes[k]->parent() == nullptr, live.parent < 0) << "keyframe " << k;
  }
  for (const auto& point : map.map_points()) {
    ASSERT_GE(point->num_observations(), 1);
    EXPECT_GT(point->max_distance(), 0.0);
  }
}

TEST_F(MapFileTest, TruncatedFilesNameTheFileAndTheProblem) {
  const std::string bytes = read_bytes(map_file());
  const std::string header_cut = load_error(write_bytes("header_cut.pspmap", bytes.substr(0, 20)));
  EXPECT_NE(header_cut.find("header_cut.pspmap"), std::string::npos) << header_cut;
  EXPECT_NE(header_cut.find("truncated"), std::string::npos) << header_cut;
  const std::string half =
      load_error(write_bytes("half.pspmap", bytes.substr(0, bytes.size() / 2)));
  EXPECT_NE(half.find("half.pspmap"), std::string::npos) << half;
  EXPECT_NE(half.find("truncated"), std::string::npos) << half;
  const std::string missing = load_error(*directory_ / "missing.pspmap");
  EXPECT_NE(missing.find("missing.pspmap': cannot open"), std::string::npos) << missing;
}

TEST_F(MapFileTest, BadMagicWrongVersionAndBadChecksumAreReported) {
  std::string bytes = read_bytes(map_file());
  std::string magic = bytes;
  magic[0] = 'X';
  EXPECT_NE(load_error(write_bytes("magic.pspmap", magic)).find("bad magic"), std::string::npos);
  std::string version = bytes;
  version[8] = 7;  // u32 version, little-endian
  const std::string version_error = load_error(write_bytes("version.pspmap", version));
  EXPECT_NE(version_error.find("unsupported format version 7"), std::string::npos) << version_error;
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(flipped[bytes.size() / 2] ^ 0x10);
  const std::string checksum_error = load_error(write_bytes("flipped.pspmap", flipped));
  EXPECT_NE(checksum_error.find("checksum mismatch"), std::string::npos) << checksum_error;
  EXPECT_NE(checksum_error.find("flipped.pspmap"), std::string::npos) << checksum_error;
}

TEST_F(MapFileTest, AnotherCameraIsRefused) {
  const std::string error = load_error(map_file(), 10.0);
  EXPECT_NE(error.find("made with fx = "), std::string::npos) << error;
}

// Save -> load -> localise on the same sequence reproduces the trajectory within 1 cm.
TEST_F(MapFileTest, LocalisationInTheLoadedMapReproducesTheTrajectory) {
  SystemOptions options;
  options.map_file = map_file();
  options.localization_only = true;
  System system(synthetic_system_config(), options);
  ASSERT_EQ(system.map().num_keyframes(), keyframes_saved_);
  ASSERT_EQ(trajectory_->size(), kFrames);
  double max_difference = 0.0;
  for (size_t i = 0; i < kFrames; ++i) {
    const StoredFrame& frame = (*frames_)[i];
    const FrameReport report =
        system.process(grey_depth_frame(frame.timestamp, frame.gray, frame.depth));
    ASSERT_TRUE(report.tracking.T_world_camera) << "frame " << i << " not localised";
    if (i == 0) {
      EXPECT_EQ(report.tracking.method, TrackingMethod::kRelocalisation);
    }
    EXPECT_FALSE(report.tracking.keyframe_inserted) << "frame " << i;
    const double difference = (report.tracking.T_world_camera->translation() -
                               (*trajectory_)[i].T_world_camera.translation())
                                  .norm();
    max_difference = std::max(max_difference, difference);
  }
  system.shutdown();
  EXPECT_LT(max_difference, 0.01) << "largest distance to the SLAM run's pose";
  EXPECT_EQ(system.map().num_keyframes(), keyframes_saved_) << "localisation changed the map";
}

}  // namespace
}  // namespace pspslam
