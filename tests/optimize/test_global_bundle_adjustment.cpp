#include "pspslam/optimize/global_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "mapping/synthetic_world.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

using testing::center_error;
using testing::path_pose;
using testing::perturbed;
using testing::SyntheticWorld;

// Registers a keyframe as tracking + local mapping would: observations of its associated points,
// new points from its depth for the rest, descriptors/normals, covisibility and spanning tree.
void register_keyframe(Map& map, const std::shared_ptr<KeyFrame>& keyframe) {
  map.add_keyframe(keyframe);
  for (int i = 0; i < keyframe->size(); ++i) {
    auto point = keyframe->map_point(i);
    if (!point) {
      if (!keyframe->has_depth(i)) continue;
      point = std::make_shared<MapPoint>(map.next_map_point_id(), keyframe->unproject_world(i),
                                         keyframe);
      keyframe->add_map_point(i, point);
      map.add_map_point(point);
    }
    point->add_observation(keyframe, i);
  }
  for (const auto& point : keyframe->map_points()) {
    if (!point) continue;
    point->compute_distinctive_descriptor();
    point->update_normal_and_depth(keyframe->pyramid());
  }
  keyframe->update_connections();
}

// Five keyframes whose estimated poses (except the anchor) are off by 0.5° / 2 cm: global BA
// must pull them back to the truth (with 1 px keypoint noise), and a keyframe added while it runs
// (a child of keyframe 4 in the spanning tree) must move along with its parent when the result is
// applied.
TEST(GlobalBundleAdjustment, CorrectsPosesAndPropagatesToNewKeyframes) {
  SyntheticWorld world(1500, 0.0, 21);
  Map map;
  std::mt19937 rng(4);
  std::vector<Pose> truth;
  for (int k = 0; k < 5; ++k) {
    truth.push_back(path_pose(k));
    const Pose estimate = k == 0 ? truth[k] : perturbed(truth[k], 0.5 * M_PI / 180.0, 0.02, rng);
    register_keyframe(map,
                      world.make_keyframe(static_cast<std::uint64_t>(k), truth[k], estimate, map));
  }
  double error_before = 0.0;
  for (int k = 1; k < 5; ++k) {
    error_before =
        std::max(error_before, center_error(map.keyframe(k)->T_camera_world(), truth[k]));
  }

  GlobalBaOptions options;
  options.iterations = 20;
  const GlobalBaResult result = solve_global_bundle_adjustment(map, options);
  ASSERT_TRUE(result.completed);
  EXPECT_EQ(result.keyframes, 5u);
  EXPECT_GT(result.points, 500u);

  // A keyframe created during the solve, at its (drifted) tracked pose relative to keyframe 4.
  const Pose drifted_parent = map.keyframe(4)->T_camera_world();
  const Pose T_new_parent = path_pose(5) * truth[4].inverse();
  auto late = world.make_keyframe(5, path_pose(5), T_new_parent * drifted_parent, map);
  register_keyframe(map, late);
  late->change_parent(map.keyframe(4));

  {
    std::lock_guard lock(map.update_mutex());
    const GlobalBaApplyReport report = apply_global_bundle_adjustment(map, result);
    EXPECT_EQ(report.keyframes_optimised, 5u);
    EXPECT_EQ(report.keyframes_propagated, 1u);
    EXPECT_GT(report.points_propagated, 0u) << "points first seen by the late keyframe";
  }
  double error_after = 0.0;
  for (int k = 1; k < 5; ++k) {
    error_after = std::max(error_after, center_error(map.keyframe(k)->T_camera_world(), truth[k]));
  }
  RecordProperty("error_before_um", static_cast<int>(1e6 * error_before));
  RecordProperty("error_after_um", static_cast<int>(1e6 * error_after));
  RecordProperty("late_error_um",
                 static_cast<int>(1e6 * center_error(late->T_camera_world(), path_pose(5))));
  EXPECT_GT(error_before, 0.015);
  EXPECT_LT(error_after, 0.004) << "before " << error_before << " m";
  // The late keyframe kept its pose relative to its parent, so it is now near its truth too.
  EXPECT_LT(center_error(late->T_camera_world(), path_pose(5)), 0.004);
}

// The global BA must weigh depth with the model it is given (System passes the camera's, the one
// local BA uses). With it ignored, the u_r row (about 15x looser) lets keyframes slide along their
// viewing direction, most of all weakly connected keyframes of a long loop. Here the depth is
// exact and the keypoints carry 1 px noise, so the sensor model must land the keyframes closer to
// the truth than the u_r row (ignoring the option gives equal errors).
TEST(GlobalBundleAdjustment, UsesTheGivenDepthNoiseModel) {
  const auto solve_error = [](const GlobalBaOptions& options) {
    SyntheticWorld world(1500, 0.0, 21);
    Map map;
    std::mt19937 rng(4);
    std::vector<Pose> truth;
    for (int k = 0; k < 5; ++k) {
      truth.push_back(path_pose(k));
      const Pose estimate = k == 0 ? truth[k] : perturbed(truth[k], 0.5 * M_PI / 180.0, 0.02, rng);
      register_keyframe(
          map, world.make_keyframe(static_cast<std::uint64_t>(k), truth[k], estimate, map));
    }
    const GlobalBaResult result = solve_global_bundle_adjustment(map, options);
    EXPECT_TRUE(result.completed);
    double rms = 0.0;
    for (int k = 1; k < 5; ++k) {
      const double e =
          center_error(result.T_camera_world.at(static_cast<std::uint64_t>(k)), truth[k]);
      rms += e * e / 4.0;
    }
    return std::sqrt(rms);
  };
  GlobalBaOptions u_r_row;
  u_r_row.iterations = 20;
  GlobalBaOptions sensor = u_r_row;
  sensor.depth_noise = {.enabled = true, .scale = 2.0};
  const double error_u_r = solve_error(u_r_row);
  const double error_sensor = solve_error(sensor);
  RecordProperty("error_u_r_um", static_cast<int>(1e6 * error_u_r));
  RecordProperty("error_sensor_um", static_cast<int>(1e6 * error_sensor));
  EXPECT_LT(error_sensor, 0.75 * error_u_r) << "u_r row " << error_u_r << " m";
}

TEST(GlobalBundleAdjustment, StopRequestLeavesNothingToApply) {
  SyntheticWorld world(500, 0.0, 3);
  Map map;
  for (int k = 0; k < 3; ++k) {
    register_keyframe(
        map, world.make_keyframe(static_cast<std::uint64_t>(k), path_pose(k), path_pose(k), map));
  }
  GlobalBaOptions options;
  options.should_stop = [] { return true; };
  const GlobalBaResult result = solve_global_bundle_adjustment(map, options);
  EXPECT_FALSE(result.completed);
  std::lock_guard lock(map.update_mutex());
  EXPECT_EQ(apply_global_bundle_adjustment(map, result).keyframes_optimised, 0u);
}

}  // namespace
}  // namespace pspslam
