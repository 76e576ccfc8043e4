#pragma once

// Global bundle adjustment of the whole map (ORB-SLAM2 RunGlobalBundleAdjustment), in two halves
// so that the slow part never blocks tracking:
//   1. solve_global_bundle_adjustment(map, options): snapshots every keyframe and point (each
//      read under its own lock, no map-wide lock) and optimises the copy. Tracking and local
//      mapping go on meanwhile; should_stop aborts (a new loop was found).
//   2. apply_global_bundle_adjustment(map, result): writes the result back. The caller holds
//      Map::update_mutex() and has local mapping stopped. Keyframes and points created during
//      step 1 are not in the result: they are moved with their spanning-tree parent / reference
//      keyframe, by the same rigid correction that parent received.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <unordered_map>

#include "pspslam/core/types.h"
#include "pspslam/optimize/depth_noise_model.h"

namespace pspslam {

class Map;

struct GlobalBaOptions {
  int iterations = 10;  // ORB-SLAM2: 10 Levenberg-Marquardt iterations with the Huber kernel
  double max_seconds = 120.0;
  std::function<bool()> should_stop;
  // How the depth row is weighed: must be the local BA's model (System passes the camera's).
  // With the tracker and local BA on the sensor model but this on ORB-SLAM2's u_r row (much
  // looser), the global BA undoes local BA's depth constraint: weakly connected keyframes (few
  // covisible keyframes, few shared points) slide along their viewing direction, away from the
  // truth (tests/optimize/test_global_bundle_adjustment.cpp). Default as BaOptions: the u_r row.
  DepthNoiseModel depth_noise{.scale = 20.0};
  // Only the keyframes of this map of the atlas (and the points they see); none: every map.
  std::optional<std::uint32_t> map_id;
};

struct GlobalBaResult {
  bool completed = false;  // false: stopped early or nothing to optimise; do not apply
  // Optimised values by id; also the poses every keyframe had when the snapshot was taken,
  // which apply_global_bundle_adjustment needs to move what was not optimised.
  std::unordered_map<std::uint64_t, Pose> T_camera_world;
  std::unordered_map<std::uint64_t, Pose> T_camera_world_before;
  std::unordered_map<std::uint64_t, Eigen::Vector3d> point_position;
  std::size_t keyframes = 0;
  std::size_t points = 0;
  std::size_t observations = 0;
  int iterations = 0;
  double seconds = 0.0;  // wall time of the solve
};

GlobalBaResult solve_global_bundle_adjustment(const Map& map, const GlobalBaOptions& options = {});

struct GlobalBaApplyReport {
  std::size_t keyframes_optimised = 0;
  std::size_t keyframes_propagated = 0;  // created during the solve, moved with their parent
  std::size_t points_optimised = 0;
  std::size_t points_propagated = 0;
};

// Requires map.update_mutex() held by the caller and local mapping stopped (see above).
GlobalBaApplyReport apply_global_bundle_adjustment(Map& map, const GlobalBaResult& result);

}  // namespace pspslam
