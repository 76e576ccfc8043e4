#pragma once

// Loop correction (ORB-SLAM2 LoopClosing::CorrectLoop), which also completes a merge of two maps
// of the atlas (map_merge.h): moves the current keyframe's
// neighbourhood to where the loop's similarity says it is (rescaled too on a monocular map),
// fuses the duplicated map points, adds the loop edges and spreads the loop error over the map
// with an essential-graph optimisation (Sim(3) nodes when pose_graph.optimize_scale).
//
// The caller stops local mapping first (it must not create or cull keyframes meanwhile) and
// releases it afterwards. correct_loop() takes Map::update_mutex() for its whole duration, so
// tracking sees the map either before or after the correction, never half-way; `on_corrected`
// runs while the mutex is still held, so the tracker can re-anchor its last pose before it
// tracks the next frame.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "pspslam/map/map.h"
#include "pspslam/optimize/pose_graph_optimization.h"

namespace pspslam {

struct DetectedLoop;

struct LoopCorrectionOptions {
  double fuse_radius = 4.0;       // pixels at level 0 (SearchAndFuse)
  int fuse_max_distance = 50;     // descriptor distance
  int strong_covisibility = 100;  // essential graph: covisibility edges of at least this weight
  PoseGraphOptions pose_graph;
};

// Loop edges already closed, as keyframe id pairs; kept by the caller across loops (ORB-SLAM2
// stores them in the keyframes), they enter every later essential graph.
using LoopEdges = std::vector<std::pair<std::uint64_t, std::uint64_t>>;

struct LoopCorrectionReport {
  std::size_t propagated_keyframes = 0;  // the current keyframe and its neighbours
  std::size_t replaced_points = 0;       // current keyframe's points replaced by loop points
  std::size_t fused_points = 0;          // loop points fused into the neighbourhood
  std::size_t graph_keyframes = 0;
  std::size_t graph_edges = 0;
  PoseGraphResult graph;
  double correction_m = 0.0;      // how far the current keyframe moved
  double correction_deg = 0.0;    // and turned
  double correction_scale = 1.0;  // and how its neighbourhood was resized (monocular)
  double seconds = 0.0;           // wall time with Map::update_mutex() held
  // Set when the loop joined two maps of the atlas (loop/map_merge.h); the correction figures
  // above are then the merge's transform.
  std::optional<MapMerge> merge;
};

LoopCorrectionReport correct_loop(Map& map, const DetectedLoop& loop, LoopEdges& loop_edges,
                                  const LoopCorrectionOptions& options,
                                  const std::function<void()>& on_corrected);

}  // namespace pspslam
