#include "pspslam/loop/loop_corrector.h"

#include <Eigen/Geometry>
#include <chrono>
#include <mutex>
#include <optional>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "pspslam/loop/loop_detector.h"
#include "pspslam/loop/map_merge.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/mapping/keyframe_matching.h"

namespace pspslam {
namespace {

// The current keyframe and its covisible keyframes, before and after the loop's correction.
struct Neighbourhood {
  std::vector<std::shared_ptr<KeyFrame>> connected;  // the current keyframe last
  std::unordered_set<std::uint64_t> connected_ids;
  std::unordered_map<std::uint64_t, Pose> uncorrected;  // T_camera_world before the loop
  std::unordered_map<std::uint64_t, Sim3> corrected;    // S_camera_world after it
  // Each point moves with the first neighbourhood keyframe that sees it; remembered so that the
  // final point correction uses the same keyframe.
  std::unordered_map<std::uint64_t, std::uint64_t> corrected_by;
};

// S_i_world' = T_i_current · S_current_world' for the current keyframe's neighbourhood.
Neighbourhood corrected_neighbourhood(const DetectedLoop& loop) {
  const auto& current = loop.current;
  Neighbourhood hood;
  current->update_connections();
  hood.connected = current->covisibles();
  hood.connected.push_back(current);
  for (const auto& keyframe : hood.connected) hood.connected_ids.insert(keyframe->id());
  const Pose T_world_current = current->T_world_camera();
  for (const auto& keyframe : hood.connected) {
    const Pose T_camera_world = keyframe->T_camera_world();
    hood.uncorrected[keyframe->id()] = T_camera_world;
    hood.corrected[keyframe->id()] = Sim3(T_camera_world * T_world_current) * loop.S_current_world;
  }
  return hood;
}

// How far the loop moves, turns and resizes the current keyframe.
void measure_correction(const DetectedLoop& loop, LoopCorrectionReport& report) {
  const Pose T_world_current = loop.current->T_world_camera();
  const Pose corrected_current = loop.S_current_world.rescaled_pose();
  const Pose change = corrected_current * T_world_current;
  report.correction_m =
      (corrected_current.inverse().translation() - T_world_current.translation()).norm();
  report.correction_deg = Eigen::AngleAxisd(change.linear()).angle() * 180.0 / M_PI;
  report.correction_scale = 1.0 / loop.S_current_world.scale;
}

// The neighbourhood's keyframes take the corrected poses and its points
// p' = S_i_world'⁻¹ · T_i_world · p.
void move_neighbourhood(Neighbourhood& hood) {
  for (const auto& keyframe : hood.connected) {
    const Pose& before = hood.uncorrected.at(keyframe->id());
    const Sim3 after_inverse = hood.corrected.at(keyframe->id()).inverse();
    for (const auto& point : keyframe->map_points()) {
      if (!point || point->is_bad() || hood.corrected_by.contains(point->id())) continue;
      hood.corrected_by[point->id()] = keyframe->id();
      point->set_position(after_inverse * (before * point->position()));
    }
  }
  for (const auto& keyframe : hood.connected) {
    keyframe->set_pose(hood.corrected.at(keyframe->id()).rescaled_pose());
  }
  for (const auto& keyframe : hood.connected) {
    for (const auto& point : keyframe->map_points()) {
      if (point) point->update_normal_and_depth(keyframe->pyramid());
    }
  }
}

// The loop point takes the place of the current keyframe's duplicate.
void take_loop_matches(Map& map, const DetectedLoop& loop, LoopCorrectionReport& report) {
  const auto& current = loop.current;
  for (int i = 0; i < current->size(); ++i) {
    const auto& loop_point = loop.matched_points[i];
    if (!loop_point || loop_point->is_bad()) continue;
    if (const auto existing = current->map_point(i)) {
      if (existing == loop_point) continue;
      if (existing->replace_with(loop_point)) {
        map.erase_map_point(existing);
        ++report.replaced_points;
      }
    } else if (!loop_point->is_observed_by(current->id())) {
      loop_point->add_observation(current, i);
      current->add_map_point(i, loop_point);
      loop_point->compute_distinctive_descriptor();
    }
  }
}

// Per neighbourhood keyframe, the keyframes outside the neighbourhood it became covisible with.
using LoopConnections = std::unordered_map<std::uint64_t, std::set<std::uint64_t>>;

LoopConnections new_loop_connections(const Neighbourhood& hood) {
  LoopConnections loop_connections;
  for (const auto& keyframe : hood.connected) {
    std::set<std::uint64_t> before;
    for (const auto& neighbour : keyframe->covisibles()) before.insert(neighbour->id());
    keyframe->update_connections();
    for (const auto& neighbour : keyframe->covisibles()) {
      if (!before.contains(neighbour->id()) && !hood.connected_ids.contains(neighbour->id())) {
        loop_connections[keyframe->id()].insert(neighbour->id());
      }
    }
  }
  return loop_connections;
}

// The essential graph under construction: a node per good keyframe, each edge once.
struct EssentialGraph {
  PoseGraph graph;
  std::unordered_map<std::uint64_t, std::size_t> node_of;
  std::vector<std::shared_ptr<KeyFrame>> keyframes;
  std::set<std::pair<std::size_t, std::size_t>> inserted;
};

EssentialGraph essential_graph_nodes(Map& map, const DetectedLoop& loop,
                                     const Neighbourhood& hood) {
  EssentialGraph essential;
  for (const auto& keyframe : map.keyframes()) {
    if (keyframe->is_bad()) continue;
    essential.node_of[keyframe->id()] = essential.graph.nodes.size();
    essential.keyframes.push_back(keyframe);
    // The loop keyframe is held fixed (gauge), as in ORB-SLAM2; so are the other maps of the
    // atlas, which the loop does not touch.
    const auto moved = hood.corrected.find(keyframe->id());
    essential.graph.nodes.push_back(
        {keyframe->id(),
         moved != hood.corrected.end() ? moved->second : Sim3(keyframe->T_camera_world()),
         keyframe->id() == loop.matched->id() || keyframe->map_id() != loop.matched->map_id()});
  }
  return essential;
}

// Relative measurements use the poses before the correction where the neighbourhood moved:
// odometry inside the neighbourhood is unchanged, only the loop links carry the correction.
void add_edge(EssentialGraph& essential, const Neighbourhood& hood, std::size_t a, std::size_t b,
              bool use_corrected) {
  if (a == b) return;
  const auto key = std::minmax(a, b);
  if (!essential.inserted.insert(key).second) return;
  const auto measured_pose = [&](std::size_t node) {
    const auto it = hood.uncorrected.find(essential.graph.nodes[node].id);
    return it != hood.uncorrected.end() ? Sim3(it->second)
                                        : essential.graph.nodes[node].S_camera_world;
  };
  const Sim3 S_a = use_corrected ? essential.graph.nodes[a].S_camera_world : measured_pose(a);
  const Sim3 S_b = use_corrected ? essential.graph.nodes[b].S_camera_world : measured_pose(b);
  essential.graph.edges.push_back({a, b, S_a * S_b.inverse()});
}

// The strong new links across the loop, and the loop itself even if the fusion left its
// covisibility weight low.
void add_loop_links(EssentialGraph& essential, const Neighbourhood& hood, const DetectedLoop& loop,
                    const LoopConnections& loop_connections, int strong_covisibility) {
  const auto& node_of = essential.node_of;
  for (const auto& [id, others] : loop_connections) {
    const auto a = node_of.find(id);
    if (a == node_of.end()) continue;
    const auto keyframe = essential.keyframes[a->second];
    for (const std::uint64_t other : others) {
      const auto b = node_of.find(other);
      if (b == node_of.end()) continue;
      const bool the_loop = id == loop.current->id() && other == loop.matched->id();
      if (!the_loop && keyframe->weight(other) < strong_covisibility) continue;
      add_edge(essential, hood, a->second, b->second, /*use_corrected=*/true);
    }
  }
  add_edge(essential, hood, node_of.at(loop.current->id()), node_of.at(loop.matched->id()), true);
}

// The spanning tree, strong covisibility and the loops closed before.
void add_map_links(EssentialGraph& essential, const Neighbourhood& hood,
                   const LoopEdges& loop_edges, int strong_covisibility) {
  const auto& node_of = essential.node_of;
  for (std::size_t n = 0; n < essential.keyframes.size(); ++n) {
    const auto& keyframe = essential.keyframes[n];
    if (const auto parent = keyframe->parent()) {
      if (const auto p = node_of.find(parent->id()); p != node_of.end())
        add_edge(essential, hood, n, p->second, false);
    }
    for (const auto& neighbour : keyframe->covisibles_with_min_weight(strong_covisibility)) {
      if (neighbour->id() >= keyframe->id()) continue;
      if (const auto b = node_of.find(neighbour->id()); b != node_of.end())
        add_edge(essential, hood, n, b->second, false);
    }
  }
  for (const auto& [a_id, b_id] : loop_edges) {
    const auto a = node_of.find(a_id);
    const auto b = node_of.find(b_id);
    if (a != node_of.end() && b != node_of.end())
      add_edge(essential, hood, a->second, b->second, false);
  }
}

// Keyframes take the optimised poses; points move with the keyframe they were corrected by (or
// their reference keyframe), keeping their place in that camera: p' = S_after⁻¹ S_before p.
void apply_optimised_poses(Map& map, const EssentialGraph& essential,
                           const std::vector<PoseGraphNode>& before_optimisation,
                           const Neighbourhood& hood) {
  for (std::size_t n = 0; n < essential.keyframes.size(); ++n) {
    essential.keyframes[n]->set_pose(essential.graph.nodes[n].S_camera_world.rescaled_pose());
  }
  for (const auto& point : map.map_points()) {
    if (point->is_bad()) continue;
    std::uint64_t anchor_id;
    if (const auto it = hood.corrected_by.find(point->id()); it != hood.corrected_by.end()) {
      anchor_id = it->second;
    } else if (const auto reference = point->reference_keyframe()) {
      anchor_id = reference->id();
    } else {
      continue;
    }
    const auto node = essential.node_of.find(anchor_id);
    if (node == essential.node_of.end()) continue;
    const Sim3& before = before_optimisation[node->second].S_camera_world;
    const Sim3& after = essential.graph.nodes[node->second].S_camera_world;
    point->set_position(after.inverse() * (before * point->position()));
    if (const auto reference = point->reference_keyframe()) {
      point->update_normal_and_depth(reference->pyramid());
    }
  }
}

}  // namespace

LoopCorrectionReport correct_loop(Map& map, const DetectedLoop& detected, LoopEdges& loop_edges,
                                  const LoopCorrectionOptions& options,
                                  const std::function<void()>& on_corrected) {
  const auto start = std::chrono::steady_clock::now();
  LoopCorrectionReport report;
  std::lock_guard lock(map.update_mutex());

  // 0. A place recognised in another map of the atlas: that map takes the current one in first
  // (map_merge.h), and the rest is the loop seen from there.
  std::optional<DetectedLoop> merged;
  if (detected.current->map_id() != detected.matched->map_id()) {
    measure_correction(detected, report);
    report.merge = MapMerge{.from = detected.current->map_id(),
                            .into = detected.matched->map_id(),
                            .current_keyframe = detected.current->id(),
                            .matched_keyframe = detected.matched->id()};
    merged = bring_into_matched_map(map, detected);
  }
  const DetectedLoop& loop = merged ? *merged : detected;

  // 1. The current keyframe's neighbourhood moves with it: S_i_world' = T_i_current ·
  // S_current_world' (ORB-SLAM2 CorrectLoop). On a monocular map the similarity also rescales the
  // neighbourhood to the loop side's units; its keyframes take the rescaled poses and its points
  // p' = S_i_world'⁻¹ · T_i_world · p, which keeps every projection as it was.
  Neighbourhood hood = corrected_neighbourhood(loop);
  if (!merged) measure_correction(loop, report);
  move_neighbourhood(hood);
  report.propagated_keyframes = hood.connected.size();

  // 2. The loop matches: the loop point takes the place of the current keyframe's duplicate.
  take_loop_matches(map, loop, report);
  // 3. Fuse the loop side's points into the whole corrected neighbourhood.
  for (const auto& keyframe : hood.connected) {
    report.fused_points += static_cast<std::size_t>(fuse_into_keyframe(
        map, keyframe, loop.loop_points, options.fuse_radius, options.fuse_max_distance));
  }
  // 4. New covisibility links the fusion created across the loop.
  const LoopConnections loop_connections = new_loop_connections(hood);

  // 5. Essential graph: spanning tree, previous loop edges, strong covisibility, new loop links.
  EssentialGraph essential = essential_graph_nodes(map, loop, hood);
  add_loop_links(essential, hood, loop, loop_connections, options.strong_covisibility);
  add_map_links(essential, hood, loop_edges, options.strong_covisibility);
  const std::vector<PoseGraphNode> before_optimisation = essential.graph.nodes;
  report.graph = optimize_pose_graph(essential.graph, options.pose_graph);
  report.graph_keyframes = essential.graph.nodes.size();
  report.graph_edges = essential.graph.edges.size();

  // 6. Keyframes take the optimised poses and the points follow them.
  if (report.graph.usable) apply_optimised_poses(map, essential, before_optimisation, hood);
  loop_edges.emplace_back(loop.current->id(), loop.matched->id());
  if (on_corrected) on_corrected();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace pspslam
