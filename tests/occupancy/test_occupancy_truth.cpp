#include <gtest/gtest.h>

#include "pspslam/occupancy/occupancy_map.h"
#include "pspslam/occupancy/occupancy_score.h"
#include "pspslam/synth/occupancy_truth.h"
#include "pspslam/synth/scene.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

SynthOptions short_scene() {
  SynthOptions options;
  options.frames = 12;
  options.bodies = 2;
  options.threads = 2;
  options.depth_noise = false;
  return options;
}

TEST(OccupancyTruth, StaticSeenAndSweptCellsOfASyntheticRoom) {
  const SyntheticScene scene(short_scene());
  OccupancyTruthOptions options;
  options.resolution = 0.1;
  options.frame_step = 3;
  options.threads = 2;
  const OccupancyTruth truth = compute_occupancy_truth(scene, options);
  EXPECT_GT(truth.static_cells.size(), 10000u);
  EXPECT_GT(truth.seen_cells.size(), 200u);
  EXPECT_GT(truth.swept_cells.size(), 50u);
  for (const VoxelIndex& cell : truth.seen_cells) EXPECT_TRUE(truth.static_cells.contains(cell));
  // The middle of the room at head height is free; the floor is static.
  EXPECT_FALSE(truth.static_cells.contains(truth.cell_of({3.5, 3.0, 1.5})));
  EXPECT_TRUE(truth.static_cells.contains(truth.cell_of({3.5, 3.0, 0.01})));

  const auto dir = testing::make_temp_dir("occupancy_truth");
  write_occupancy_truth(truth, dir);
  const OccupancyTruth read = read_occupancy_truth(dir);
  EXPECT_EQ(read.resolution, truth.resolution);
  EXPECT_EQ(read.static_cells, truth.static_cells);
  EXPECT_EQ(read.seen_cells, truth.seen_cells);
  EXPECT_EQ(read.swept_cells, truth.swept_cells);
  EXPECT_EQ(read.camera_poses.size(), scene.frame_count());
}

// The exact depth of every frame, inserted at the exact poses, scores as the truth defines it:
// the map is precise, recalls what was seen and keeps no ghost where the people were masked.
TEST(OccupancyTruth, ExactDepthAtExactPosesScoresWell) {
  const SyntheticScene scene(short_scene());
  OccupancyTruthOptions truth_options;
  truth_options.resolution = 0.1;
  truth_options.frame_step = 1;
  truth_options.threads = 2;
  const OccupancyTruth truth = compute_occupancy_truth(scene, truth_options);
  OccupancyOptions options;
  options.resolution_m = 0.1;
  OccupancyMap map(options);
  Trajectory keyframes;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    SynthFrame frame;
    scene.render(i, frame, 2);
    cv::Mat mask = frame.labels != kSynthLabelStatic;
    map.insert(make_keyframe_scan(i, scene.camera(), frame.depth, mask, options),
               frame.T_world_camera);
    keyframes.push_back({frame.timestamp, frame.T_world_camera});
  }
  const OccupancyScore score = score_occupancy(map, nullptr, GridOptions{}, keyframes, truth);
  EXPECT_LT(score.alignment_rmse_m, 1e-6);
  EXPECT_GT(score.precision, 0.97);
  EXPECT_GT(score.recall, 0.9);
  EXPECT_EQ(score.ghosts, 0u);
}

}  // namespace
}  // namespace pspslam
