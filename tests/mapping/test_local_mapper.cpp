#include "pspslam/mapping/local_mapper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "mapping/synthetic_world.h"
#include "pspslam/mapping/local_bundle_adjuster.h"

namespace pspslam {
namespace {

using testing::SyntheticWorld;

// Every live map point is where its observing keyframes say it is, and vice versa.
void expect_consistent(const Map& map) {
  std::set<std::uint64_t> live_points;
  for (const auto& point : map.map_points()) {
    EXPECT_FALSE(point->is_bad()) << "bad point " << point->id() << " left in the map";
    live_points.insert(point->id());
    for (const auto& [keyframe_id, observation] : point->observations()) {
      const auto keyframe = observation.keyframe.lock();
      ASSERT_TRUE(keyframe);
      EXPECT_EQ(keyframe->map_point(observation.keypoint_index), point)
          << "point " << point->id() << " in keyframe " << keyframe_id;
    }
  }
  for (const auto& keyframe : map.keyframes()) {
    const auto points = keyframe->map_points();
    for (int i = 0; i < static_cast<int>(points.size()); ++i) {
      if (!points[i]) continue;
      EXPECT_TRUE(live_points.contains(points[i]->id())) << "dangling " << points[i]->id();
      EXPECT_EQ(points[i]->keypoint_index_in(keyframe->id()), i)
          << "keyframe " << keyframe->id() << " keypoint " << i << " unknown to its point";
    }
  }
}

struct PathRun {
  std::shared_ptr<Map> map = std::make_shared<Map>();
  std::vector<Pose> truth;
  std::vector<Pose> initial;
  std::vector<int> transient_points;  // world indices of features seen once
  LocalMappingStats stats;
};

// Eight keyframes along a path; poses after the first perturbed by 0.5° / 3 cm as a drifting
// tracker would give them; 30 transient close features in each keyframe.
PathRun run_path(SyntheticWorld& world, int num_keyframes) {
  PathRun run;
  LocalMappingOptions options;
  LocalMapper mapper(run.map, options);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> pixel_x(40.0, 600.0), pixel_y(40.0, 440.0);
  for (int k = 0; k < num_keyframes; ++k) {
    run.truth.push_back(testing::path_pose(k));
    run.initial.push_back(k == 0 ? run.truth[k]
                                 : testing::perturbed(run.truth[k], 0.0087, 0.03, rng));
    for (int t = 0; t < 30; ++t) {
      const Eigen::Vector3d in_camera =
          world.camera()->pinhole.unproject({pixel_x(rng), pixel_y(rng)}, 2.0);
      run.transient_points.push_back(
          world.add_transient_point(run.truth[k].inverse() * in_camera, k));
    }
    const auto keyframe = world.make_keyframe(k, run.truth[k], run.initial[k], *run.map);
    mapper.process(keyframe);
  }
  run.stats = mapper.stats();
  return run;
}

TEST(LocalMapper, BuildsCullsAndOptimisesASyntheticMap) {
  SyntheticWorld world(900, 0.35, 21);
  const int num_keyframes = 8;
  PathRun run = run_path(world, num_keyframes);

  EXPECT_EQ(run.stats.keyframes_processed, static_cast<std::uint64_t>(num_keyframes));
  EXPECT_GT(run.stats.points_from_depth, 300u);
  EXPECT_GT(run.stats.points_triangulated, 50u);
  EXPECT_GE(run.stats.bundle_adjustments, static_cast<std::uint64_t>(num_keyframes - 2));
  EXPECT_GT(run.stats.points_culled, 0u);
  expect_consistent(*run.map);

  // Transient features older than the culling span are gone from the map.
  std::set<int> mapped_world_points;
  for (const auto& point : run.map->map_points()) {
    mapped_world_points.insert(world.world_index(*point));
  }
  int stale_transients = 0;
  for (int k = 0; k + 2 < num_keyframes; ++k) {
    for (int t = 0; t < 30; ++t)
      stale_transients += mapped_world_points.contains(run.transient_points[k * 30 + t]);
  }
  EXPECT_EQ(stale_transients, 0);

  // Triangulated points (world points without depth) sit where the world has them.
  std::vector<double> errors;
  for (const auto& point : run.map->map_points()) {
    const int w = world.world_index(*point);
    if (w < 0 || world.points()[w].has_depth) continue;
    errors.push_back((point->position() - world.points()[w].position).norm());
  }
  ASSERT_GT(errors.size(), 50u);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.05);

  // Local BA pulled the drifted keyframes back towards the truth.
  double error_before = 0.0, error_after = 0.0;
  int compared = 0;
  for (const auto& keyframe : run.map->keyframes()) {
    const auto k = keyframe->id();
    if (k == 0) continue;
    error_before += testing::center_error(run.initial[k], run.truth[k]);
    error_after += testing::center_error(keyframe->T_camera_world(), run.truth[k]);
    ++compared;
  }
  ASSERT_GT(compared, 0);
  EXPECT_LT(error_after, 0.3 * error_before)
      << "mean centre error " << error_before / compared << " -> " << error_after / compared;
  EXPECT_LT(error_after / compared, 0.01);
}

// The local BA window: the new keyframe and its best covisible keyframes, all of them by default
// (ORB-SLAM2) or the best N; the other keyframes that see the window's points are held fixed.
TEST(LocalMapper, LocalBundleAdjustmentWindowKeepsTheBestCovisibles) {
  SyntheticWorld world(900, 0.35, 21);
  PathRun run = run_path(world, 8);
  const auto newest = run.map->keyframe(run.map->max_keyframe_id());
  ASSERT_TRUE(newest);
  // Keyframe 0 anchors the map: it is held fixed even inside the window.
  const auto free_count = [](const std::vector<std::shared_ptr<KeyFrame>>& keyframes) {
    return 1 + static_cast<int>(std::count_if(keyframes.begin(), keyframes.end(),
                                              [](const auto& kf) { return kf->id() != 0; }));
  };
  const auto covisibles = newest->covisibles();
  ASSERT_GE(covisibles.size(), 5u);

  const LocalBundleAdjustmentReport all = run_local_bundle_adjustment(*run.map, newest, {});
  EXPECT_EQ(all.local_keyframes, free_count(covisibles));

  const LocalBundleAdjustmentReport capped =
      run_local_bundle_adjustment(*run.map, newest, {}, {.max_covisibles = 3});
  EXPECT_EQ(capped.local_keyframes, free_count(newest->best_covisibles(3)));
  // The covisible keyframes left out still constrain the window's points, fixed.
  EXPECT_GE(capped.fixed_keyframes, static_cast<int>(covisibles.size()) - 3);
  EXPECT_LT(capped.points, all.points);
  expect_consistent(*run.map);
}

// A capped border: of the keyframes held fixed around a window of 2, only the 2 that see the most
// of its points remain, with their observations; the window's own keyframes are unchanged.
TEST(LocalMapper, LocalBundleAdjustmentBorderKeepsTheKeyframesSeeingMostOfTheWindow) {
  SyntheticWorld world(900, 0.35, 21);
  PathRun run = run_path(world, 8);
  const auto newest = run.map->keyframe(run.map->max_keyframe_id());
  ASSERT_TRUE(newest);
  const LocalBundleAdjustmentReport border_all =
      run_local_bundle_adjustment(*run.map, newest, {}, {.max_covisibles = 2});
  ASSERT_GT(border_all.fixed_keyframes, 2);
  const LocalBundleAdjustmentReport border_two = run_local_bundle_adjustment(
      *run.map, newest, {}, {.max_covisibles = 2, .max_fixed_keyframes = 2});
  EXPECT_EQ(border_two.local_keyframes, border_all.local_keyframes);
  EXPECT_EQ(border_two.fixed_keyframes, 2);
  EXPECT_EQ(border_two.points, border_all.points);
  EXPECT_LT(border_two.observations, border_all.observations);
  expect_consistent(*run.map);
}

TEST(LocalMapper, CullsRedundantKeyframes) {
  SyntheticWorld world(600, 0.0, 22);
  auto map = std::make_shared<Map>();
  LocalMapper mapper(map, LocalMappingOptions{});
  const int num_keyframes = 7;
  for (int k = 0; k < num_keyframes; ++k) {
    // Nearly the same view each time: every keyframe's points are seen by all the others.
    const Pose pose = testing::path_pose(k, 0.01, 0.001);
    mapper.process(world.make_keyframe(k, pose, pose, *map));
  }
  EXPECT_GT(mapper.stats().keyframes_culled, 0u);
  EXPECT_EQ(map->num_keyframes() + mapper.stats().keyframes_culled,
            static_cast<size_t>(num_keyframes));
  EXPECT_TRUE(map->keyframe(0)) << "the anchor keyframe is never culled";
  expect_consistent(*map);
}

TEST(LocalMapper, FirstKeyframeCreatesPointsFromDepthOnly) {
  SyntheticWorld world(400, 0.5, 23);
  auto map = std::make_shared<Map>();
  LocalMapper mapper(map, LocalMappingOptions{});
  const Pose pose = testing::path_pose(0);
  const auto keyframe = world.make_keyframe(0, pose, pose, *map);
  mapper.process(keyframe);
  EXPECT_EQ(map->num_keyframes(), 1u);
  EXPECT_EQ(mapper.stats().points_triangulated, 0u);
  EXPECT_EQ(mapper.stats().bundle_adjustments, 0u);
  EXPECT_EQ(map->num_map_points(), mapper.stats().points_from_depth);
  // Every close reading becomes a point, and at least 100 readings in total (far ones too).
  size_t close = 0, with_depth = 0;
  for (int i = 0; i < keyframe->size(); ++i) {
    with_depth += keyframe->depth(i) > 0.0f;
    close += keyframe->depth(i) > 0.0f && keyframe->depth(i) <= 4.0f;
  }
  ASSERT_GT(close, 20u);
  ASSERT_GT(with_depth, close);
  EXPECT_EQ(map->num_map_points(), std::max<size_t>(close, std::min<size_t>(100, with_depth)));
  for (const auto& point : map->map_points()) {
    const int w = world.world_index(*point);
    ASSERT_GE(w, 0);
    EXPECT_TRUE(world.points()[w].has_depth);
    EXPECT_LT((point->position() - world.points()[w].position).norm(), 0.01);
  }
}

// Associations of `keyframe` whose map point stands for another world point than the keypoint.
int count_wrong_associations(const SyntheticWorld& world, const KeyFrame& keyframe) {
  int wrong = 0;
  const auto points = keyframe.map_points();
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (points[i]) wrong += world.world_index(keyframe.id(), i) != world.world_index(*points[i]);
  }
  return wrong;
}

TEST(LocalMapper, BundleAdjustmentRemovesWrongAssociations) {
  SyntheticWorld world(700, 0.2, 24);
  auto map = std::make_shared<Map>();
  LocalMapper mapper(map, LocalMappingOptions{});
  const int num_keyframes = 5;
  int injected = 0;
  for (int k = 0; k < num_keyframes; ++k) {
    const Pose pose = testing::path_pose(k);
    // From the third keyframe on, 5% of tracking's matches point at the wrong map point.
    const auto keyframe = world.make_keyframe(k, pose, pose, *map, k >= 2 ? 0.05 : 0.0);
    injected += count_wrong_associations(world, *keyframe);
    mapper.process(keyframe);
  }
  ASSERT_GT(injected, 30);
  EXPECT_GT(mapper.stats().ba_outliers_removed, static_cast<std::uint64_t>(injected / 2));
  expect_consistent(*map);
  // Nearly all wrong matches are gone. A few cannot be told apart: a point seen once without
  // depth plus one wrong match is triangulated to where both agree.
  int remaining = 0;
  for (const auto& keyframe : map->keyframes()) {
    remaining += count_wrong_associations(world, *keyframe);
  }
  EXPECT_LT(remaining, injected / 4) << remaining << " of " << injected << " wrong matches left";
}

}  // namespace
}  // namespace pspslam
