#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "pspslam/core/error.h"
#include "pspslam/session/atlas_report.h"

namespace pspslam {
namespace {

Trajectory poses_at(std::initializer_list<double> stamps) {
  Trajectory poses;
  for (const double t : stamps) poses.push_back({t, Pose::Identity()});
  return poses;
}

TEST(AtlasReport, TheMapWithTheMostPosesComesFirstAndKeepsTimeOrder) {
  const Trajectory poses = poses_at({1, 2, 3, 4, 5, 6});
  const std::vector<std::uint32_t> map_of{2, 2, 0, 0, 0, 3};
  const std::vector<MapTrajectory> maps = split_by_map(poses, map_of);
  ASSERT_EQ(maps.size(), 3u);
  EXPECT_EQ(maps[0].map_id, 0u);
  ASSERT_EQ(maps[0].poses.size(), 3u);
  EXPECT_EQ(maps[0].poses.front().timestamp, 3.0);
  EXPECT_EQ(maps[1].map_id, 2u);
  EXPECT_EQ(maps[2].map_id, 3u);
  // Among equals, the lowest id.
  EXPECT_EQ(split_by_map(poses_at({1, 2}), std::vector<std::uint32_t>{5, 1}).front().map_id, 1u);
  // No poses: one empty main map.
  EXPECT_EQ(split_by_map({}, {}).size(), 1u);
  EXPECT_THROW(split_by_map(poses, std::vector<std::uint32_t>{0}), Error);
}

TEST(AtlasReport, SummaryAndJsonSayWhichMapsMergedAndWhichFileHoldsTheOthers) {
  const std::vector<MapTrajectory> final_maps = {{0, poses_at({1, 2, 3})}, {2, poses_at({4})}};
  AtlasSummary atlas;
  atlas.new_map_after_seconds = 1.0;
  atlas.maps = {{0, {.frames = 2, .first_frame = 0, .last_frame = 1}},
                {1, {.frames = 1, .first_frame = 5, .last_frame = 5}},
                {2, {.frames = 1, .first_frame = 9, .last_frame = 9}}};
  atlas.merges = {{.from = 1, .into = 0, .current_keyframe = 7, .matched_keyframe = 2}};
  atlas.maps_at_end = {0, 2};
  atlas.final_maps = final_maps;
  std::ostringstream out;
  print_atlas(atlas, out);
  EXPECT_EQ(out.str(),
            "atlas:        3 maps, 1 merge(s); the final files are in map 0\n"
            "              map 0: 2 frames tracked (0-1)\n"
            "              map 1: 1 frames tracked (5-5), merged into map 0\n"
            "              map 2: 1 frames tracked (9-9), never merged with the main map: "
            "trajectory_refined_map2.txt\n");
  const nlohmann::ordered_json json = atlas_json(atlas);
  EXPECT_EQ(json["maps"][1]["final_map"], 0);
  EXPECT_EQ(json["maps"][2]["final_map"], 2);
  EXPECT_EQ(json["merges"][0]["matched_keyframe"], 2);
  EXPECT_EQ(json["final_trajectories"][0]["poses"], 3);
  EXPECT_EQ(json["maps_tracked_in"], 3);
  EXPECT_EQ(json["merge_count"], 1);
  EXPECT_EQ(json["main_map_poses"], 3);
  EXPECT_EQ(json["other_map_poses"], 1);
  EXPECT_EQ(json["maps_at_end"], nlohmann::json({0, 2}));

  // One map: nothing to say in the summary.
  atlas.maps.erase(1);
  atlas.maps.erase(2);
  std::ostringstream quiet;
  print_atlas(atlas, quiet);
  EXPECT_EQ(quiet.str(), "");
}

}  // namespace
}  // namespace pspslam
