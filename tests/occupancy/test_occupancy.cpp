#include <gtest/gtest.h>
#include <octomap/OcTree.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "pspslam/core/error.h"
#include "pspslam/occupancy/occupancy_grid.h"
#include "pspslam/occupancy/occupancy_map.h"
#include "pspslam/occupancy/occupancy_options.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

// A camera at the origin looking along +z (y down) at a wall 3 m away over a floor 1 m below it.
constexpr double kWall = 3.0, kFloorBelow = 1.02;

cv::Mat room_depth(const PinholeCamera& camera) {
  cv::Mat depth(camera.height, camera.width, CV_32F);
  for (int y = 0; y < camera.height; ++y) {
    const double yn = (y - camera.cy) / camera.fy;
    const double floor = yn > 0.0 ? kFloorBelow / yn : kWall;
    depth.row(y).setTo(static_cast<float>(std::min(kWall, floor)));
  }
  return depth;
}

// The same view with a person-sized block 1.5 m away in the middle of the image.
cv::Mat with_person(const cv::Mat& room, cv::Mat* mask) {
  cv::Mat depth = room.clone();
  const cv::Rect person(280, 120, 80, 200);
  depth(person).setTo(1.5f);
  if (mask != nullptr) {
    *mask = cv::Mat::zeros(room.size(), CV_8U);
    (*mask)(person).setTo(255);
  }
  return depth;
}

OccupancyOptions fast_options() {
  OccupancyOptions options;
  options.resolution_m = 0.1;
  options.pixel_stride = 4;
  return options;
}

const Eigen::Vector3d kPersonPoint(0.0, 0.0, 1.55);

TEST(Occupancy, LaterRaysClearWherePeopleStood) {
  const PinholeCamera camera;
  const cv::Mat room = room_depth(camera);
  for (const bool clearing : {true, false}) {
    OccupancyOptions options = fast_options();
    options.clearing = clearing;
    OccupancyMap map(options);
    map.insert(make_keyframe_scan(0, camera, with_person(room, nullptr), {}, options),
               Pose::Identity());
    EXPECT_TRUE(map.occupied_at(kPersonPoint).value_or(false));
    for (int k = 1; k < 6; ++k)
      map.insert(make_keyframe_scan(k, camera, room, {}, options), Pose::Identity());
    EXPECT_EQ(map.occupied_at(kPersonPoint).value_or(false), !clearing) << "clearing " << clearing;
    EXPECT_TRUE(map.occupied_at({0.0, 0.0, kWall + 0.05}).value_or(false));
    if (clearing) {
      std::vector<std::pair<const KeyframeScan*, Pose>> none;
      EXPECT_TRUE(map.seen_through(none).empty());
    }
  }
}

TEST(Occupancy, MaskedPixelsStayOutOfTheMap) {
  const PinholeCamera camera;
  cv::Mat mask;
  const cv::Mat depth = with_person(room_depth(camera), &mask);
  for (const bool use_masks : {true, false}) {
    OccupancyOptions options = fast_options();
    options.use_masks = use_masks;
    OccupancyMap map(options);
    map.insert(make_keyframe_scan(0, camera, depth, mask, options), Pose::Identity());
    EXPECT_EQ(map.occupied_at(kPersonPoint).value_or(false), !use_masks);
  }
}

TEST(Occupancy, SeenThroughCountsOccupiedVoxelsLaterRaysPass) {
  const PinholeCamera camera;
  OccupancyOptions options = fast_options();
  options.clearing = false;
  OccupancyMap map(options);
  const KeyframeScan person =
      make_keyframe_scan(0, camera, with_person(room_depth(camera), nullptr), {}, options);
  const KeyframeScan empty = make_keyframe_scan(1, camera, room_depth(camera), {}, options);
  map.insert(person, Pose::Identity());
  map.insert(empty, Pose::Identity());
  const auto seen = map.seen_through({{&person, Pose::Identity()}, {&empty, Pose::Identity()}});
  EXPECT_GT(seen.size(), 10u);
  for (const Eigen::Vector3d& centre : seen) EXPECT_NEAR(centre.z(), 1.5, 0.11);
}

TEST(Occupancy, BinaryFileRoundTripsThroughOctomapsReader) {
  const PinholeCamera camera;
  const OccupancyOptions options = fast_options();
  OccupancyMap map(options);
  map.insert(make_keyframe_scan(0, camera, room_depth(camera), {}, options), Pose::Identity());
  const auto dir = testing::make_temp_dir("occupancy_bt");
  map.write_binary(dir / "map.bt");

  std::unique_ptr<octomap::OcTree> read(new octomap::OcTree(0.5));
  ASSERT_TRUE(read->readBinary((dir / "map.bt").string()));
  EXPECT_DOUBLE_EQ(read->getResolution(), options.resolution_m);
  size_t occupied = 0, agree = 0;
  map.for_each_voxel([&](const Eigen::Vector3d& centre, bool is_occupied) {
    const octomap::OcTreeNode* node =
        read->search(static_cast<float>(centre.x()), static_cast<float>(centre.y()),
                     static_cast<float>(centre.z()));
    occupied += is_occupied;
    agree += node != nullptr && read->isNodeOccupied(node) == is_occupied;
  });
  EXPECT_GT(occupied, 100u);
  size_t voxels = 0;
  map.for_each_voxel([&](const Eigen::Vector3d&, bool) { ++voxels; });
  EXPECT_EQ(agree, voxels);
  EXPECT_THROW(map.write_binary(dir / "missing" / "map.bt"), Error);
}

TEST(Occupancy, FloorIsFoundBelowTheCameras) {
  const PinholeCamera camera;
  OccupancyOptions options = fast_options();
  OccupancyMap map(options);
  map.insert(make_keyframe_scan(0, camera, room_depth(camera), {}, options), Pose::Identity());
  const FloorPlane floor = find_floor(map, {Eigen::Vector3d::Zero()}, GridOptions{});
  EXPECT_TRUE(floor.from_map);
  EXPECT_NEAR(floor.height, -kFloorBelow, options.resolution_m);
  EXPECT_GT(floor.up.dot(-Eigen::Vector3d::UnitY()), 0.99);
  GridOptions given;
  given.floor_height_m = -0.7;
  EXPECT_DOUBLE_EQ(find_floor(map, {}, given).height, -0.7);
  EXPECT_FALSE(find_floor(map, {}, given).from_map);
}

// What map_server (ROS 1 map_server, nav2's map_io) does with a map YAML: read the keys, load
// the image relative to the YAML, turn each pixel into a trinary occupancy with the thresholds,
// flip the rows (the image's top row is the grid's last).
struct NavigationMap {
  double resolution = 0.0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  int width = 0, height = 0;
  std::vector<int> data;  // -1, 0, 100; row 0 at origin y

  int at_world(double x, double y) const {
    const int i = static_cast<int>(std::floor((x - origin.x()) / resolution));
    const int j = static_cast<int>(std::floor((y - origin.y()) / resolution));
    if (i < 0 || j < 0 || i >= width || j >= height) return -2;
    return data[static_cast<size_t>(j) * width + i];
  }
};

std::vector<unsigned char> read_pgm(const std::filesystem::path& file, int& width, int& height) {
  std::ifstream in(file, std::ios::binary);
  std::string magic;
  in >> magic;
  EXPECT_EQ(magic, "P5");
  const auto skip_comments = [&] {
    in >> std::ws;
    while (in.peek() == '#') {
      std::string comment;
      std::getline(in, comment);
      in >> std::ws;
    }
  };
  int maxval = 0;
  skip_comments();
  in >> width;
  skip_comments();
  in >> height;
  skip_comments();
  in >> maxval;
  in.get();  // the single whitespace before the raster
  EXPECT_EQ(maxval, 255);
  std::vector<unsigned char> pixels(static_cast<size_t>(width) * height);
  in.read(reinterpret_cast<char*>(pixels.data()), static_cast<std::streamsize>(pixels.size()));
  EXPECT_TRUE(in.good());
  return pixels;
}

NavigationMap load_like_map_server(const std::filesystem::path& yaml_file) {
  const YAML::Node doc = YAML::LoadFile(yaml_file.string());
  NavigationMap map;
  map.resolution = doc["resolution"].as<double>();
  const auto origin = doc["origin"].as<std::vector<double>>();
  EXPECT_EQ(origin.size(), 3u);
  map.origin = {origin[0], origin[1], origin[2]};
  const int negate = doc["negate"].as<int>();
  const double occupied_thresh = doc["occupied_thresh"].as<double>();
  const double free_thresh = doc["free_thresh"].as<double>();
  EXPECT_EQ(doc["mode"].as<std::string>(), "trinary");
  const auto pixels =
      read_pgm(yaml_file.parent_path() / doc["image"].as<std::string>(), map.width, map.height);
  map.data.resize(pixels.size());
  for (int row = 0; row < map.height; ++row) {
    for (int i = 0; i < map.width; ++i) {
      const double value = pixels[static_cast<size_t>(row) * map.width + i];
      const double occupancy = negate ? value / 255.0 : (255.0 - value) / 255.0;
      const int state = occupancy > occupied_thresh ? 100 : occupancy < free_thresh ? 0 : -1;
      map.data[static_cast<size_t>(map.height - 1 - row) * map.width + i] = state;
    }
  }
  return map;
}

TEST(Occupancy, GridFollowsTheMapServerFormat) {
  const PinholeCamera camera;
  const OccupancyOptions options = fast_options();
  OccupancyMap map(options);
  map.insert(make_keyframe_scan(0, camera, room_depth(camera), {}, options), Pose::Identity());
  const GridOptions band;
  const OccupancyGrid grid = make_grid(map, find_floor(map, {Eigen::Vector3d::Zero()}, band), band);
  const auto dir = testing::make_temp_dir("occupancy_grid");
  write_map_server(grid, dir / "grid.yaml");
  ASSERT_TRUE(std::filesystem::exists(dir / "grid.pgm"));

  const NavigationMap nav = load_like_map_server(dir / "grid.yaml");
  EXPECT_DOUBLE_EQ(nav.resolution, options.resolution_m);
  EXPECT_EQ(nav.width, grid.width);
  EXPECT_EQ(nav.height, grid.height);
  // The grid's y axis is the world's z (forward), x the world's x: free before the wall,
  // occupied at it, unknown behind it.
  EXPECT_EQ(nav.at_world(0.05, 1.5), 0);
  EXPECT_EQ(nav.at_world(0.05, kWall + 0.05), 100);
  EXPECT_EQ(nav.at_world(0.05, kWall + 0.5), -2);
  size_t same = 0;
  for (int row = 0; row < grid.height; ++row)
    for (int i = 0; i < grid.width; ++i)
      same += nav.data[static_cast<size_t>(row) * nav.width + i] == grid.at(i, row);
  EXPECT_EQ(same, grid.cells.size());
}

TEST(Occupancy, BadOptionsNameTheirFlag) {
  OccupancyOptions options;
  options.resolution_m = 0.0;
  EXPECT_TRUE(
      testing::contains(testing::error_of([&] { options.validate(); }), "--occupancy-resolution"));
  options.resolution_m = -1.0;
  EXPECT_THROW(options.validate(), Error);
  GridOptions grid;
  grid.min_height_m = 1.0;
  grid.max_height_m = 0.5;
  const std::string message = testing::error_of([&] { grid.validate(); });
  EXPECT_TRUE(testing::contains(message, "--grid-min-height")) << message;
  EXPECT_TRUE(testing::contains(message, "upside down")) << message;
}

}  // namespace
}  // namespace pspslam
