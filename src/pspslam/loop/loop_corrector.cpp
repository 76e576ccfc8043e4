#include "pspslam/loop/loop_corrector.h"

#include <Eigen/Geometry>
#include <chrono>
#include <mutex>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "pspslam/loop/loop_detector.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"
#include "pspslam/mapping/keyframe_matching.h"

namespace pspslam {

LoopCorrectionReport correct_loop(Map& map, const DetectedLoop& loop, LoopEdges& loop_edges,
                                  const LoopCorrectionOptions& options,
                                  const std::function<void()>& on_corrected) {
  const auto start = std::chrono::steady_clock::now();
  LoopCorrectionReport report;
  const auto& current = loop.current;
  std::lock_guard lock(map.update_mutex());

  // 1. The current keyframe's neighbourhood moves with it: S_i_world' = T_i_current ·
  // S_current_world' (ORB-SLAM2 CorrectLoop). On a monocular map the similarity also rescales the
  // neighbourhood to the loop side's units; its keyframes take the rescaled poses and its points
  // p' = S_i_world'⁻¹ · T_i_world · p, which keeps every projection as it was.
  current->update_connections();
  std::vector<std::shared_ptr<KeyFrame>> connected = current->covisibles();
  connected.push_back(current);
  std::unordered_set<std::uint64_t> connected_ids;
  for (const auto& keyframe : connected) connected_ids.insert(keyframe->id());
  std::unordered_map<std::uint64_t, Pose> uncorrected;  // T_camera_world before the loop
  std::unordered_map<std::uint64_t, Sim3> corrected;    // S_camera_world after it
  const Pose T_world_current = current->T_world_camera();
  for (const auto& keyframe : connected) {
    const Pose T_camera_world = keyframe->T_camera_world();
    uncorrected[keyframe->id()] = T_camera_world;
    corrected[keyframe->id()] = Sim3(T_camera_world * T_world_current) * loop.S_current_world;
  }
  {
    const Pose corrected_current = loop.S_current_world.rescaled_pose();
    const Pose change = corrected_current * T_world_current;
    report.correction_m =
        (corrected_current.inverse().translation() - T_world_current.translation()).norm();
    report.correction_deg = Eigen::AngleAxisd(change.linear()).angle() * 180.0 / M_PI;
    report.correction_scale = 1.0 / loop.S_current_world.scale;
  }
  // Each point moves with the first neighbourhood keyframe that sees it; remembered so that the
  // final point correction uses the same keyframe.
  std::unordered_map<std::uint64_t, std::uint64_t> corrected_by;
  for (const auto& keyframe : connected) {
    const Pose& before = uncorrected.at(keyframe->id());
    const Sim3 after_inverse = corrected.at(keyframe->id()).inverse();
    for (const auto& point : keyframe->map_points()) {
      if (!point || point->is_bad() || corrected_by.contains(point->id())) continue;
      corrected_by[point->id()] = keyframe->id();
      point->set_position(after_inverse * (before * point->position()));
    }
  }
  for (const auto& keyframe : connected) {
    keyframe->set_pose(corrected.at(keyframe->id()).rescaled_pose());
  }
  for (const auto& keyframe : connected) {
    for (const auto& point : keyframe->map_points()) {
      if (point) point->update_normal_and_depth(keyframe->pyramid());
    }
  }
  report.propagated_keyframes = connected.size();

  // 2. The loop matches: the loop point takes the place of the current keyframe's duplicate.
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
  // 3. Fuse the loop side's points into the whole corrected neighbourhood.
  for (const auto& keyframe : connected) {
    report.fused_points += static_cast<std::size_t>(fuse_into_keyframe(
        map, keyframe, loop.loop_points, options.fuse_radius, options.fuse_max_distance));
  }

  // 4. New covisibility links the fusion created across the loop.
  std::unordered_map<std::uint64_t, std::set<std::uint64_t>> loop_connections;
  for (const auto& keyframe : connected) {
    std::set<std::uint64_t> before;
    for (const auto& neighbour : keyframe->covisibles()) before.insert(neighbour->id());
    keyframe->update_connections();
    for (const auto& neighbour : keyframe->covisibles()) {
      if (!before.contains(neighbour->id()) && !connected_ids.contains(neighbour->id())) {
        loop_connections[keyframe->id()].insert(neighbour->id());
      }
    }
  }

  // 5. Essential graph: spanning tree, previous loop edges, strong covisibility, new loop links.
  PoseGraph graph;
  std::unordered_map<std::uint64_t, std::size_t> node_of;
  std::vector<std::shared_ptr<KeyFrame>> keyframes;
  for (const auto& keyframe : map.keyframes()) {
    if (keyframe->is_bad()) continue;
    node_of[keyframe->id()] = graph.nodes.size();
    keyframes.push_back(keyframe);
    // The loop keyframe is held fixed (gauge), as in ORB-SLAM2.
    const auto moved = corrected.find(keyframe->id());
    graph.nodes.push_back(
        {keyframe->id(),
         moved != corrected.end() ? moved->second : Sim3(keyframe->T_camera_world()),
         keyframe->id() == loop.matched->id()});
  }
  // Relative measurements use the poses before the correction where the neighbourhood moved:
  // odometry inside the neighbourhood is unchanged, only the loop links carry the correction.
  const auto measured_pose = [&](std::uint64_t id, std::size_t node) {
    const auto it = uncorrected.find(id);
    return it != uncorrected.end() ? Sim3(it->second) : graph.nodes[node].S_camera_world;
  };
  std::set<std::pair<std::size_t, std::size_t>> inserted;
  const auto add_edge = [&](std::size_t a, std::size_t b, bool use_corrected) {
    if (a == b) return;
    const auto key = std::minmax(a, b);
    if (!inserted.insert(key).second) return;
    const Sim3 S_a =
        use_corrected ? graph.nodes[a].S_camera_world : measured_pose(graph.nodes[a].id, a);
    const Sim3 S_b =
        use_corrected ? graph.nodes[b].S_camera_world : measured_pose(graph.nodes[b].id, b);
    graph.edges.push_back({a, b, S_a * S_b.inverse()});
  };
  for (const auto& [id, others] : loop_connections) {
    const auto a = node_of.find(id);
    if (a == node_of.end()) continue;
    const auto keyframe = keyframes[a->second];
    for (const std::uint64_t other : others) {
      const auto b = node_of.find(other);
      if (b == node_of.end()) continue;
      const bool the_loop = id == current->id() && other == loop.matched->id();
      if (!the_loop && keyframe->weight(other) < options.strong_covisibility) continue;
      add_edge(a->second, b->second, /*use_corrected=*/true);
    }
  }
  // The loop itself, even if the fusion left its covisibility weight low.
  add_edge(node_of.at(current->id()), node_of.at(loop.matched->id()), true);
  for (std::size_t n = 0; n < keyframes.size(); ++n) {
    const auto& keyframe = keyframes[n];
    if (const auto parent = keyframe->parent()) {
      if (const auto p = node_of.find(parent->id()); p != node_of.end())
        add_edge(n, p->second, false);
    }
    for (const auto& neighbour :
         keyframe->covisibles_with_min_weight(options.strong_covisibility)) {
      if (neighbour->id() >= keyframe->id()) continue;
      if (const auto b = node_of.find(neighbour->id()); b != node_of.end())
        add_edge(n, b->second, false);
    }
  }
  for (const auto& [a_id, b_id] : loop_edges) {
    const auto a = node_of.find(a_id);
    const auto b = node_of.find(b_id);
    if (a != node_of.end() && b != node_of.end()) add_edge(a->second, b->second, false);
  }
  const std::vector<PoseGraphNode> before_optimisation = graph.nodes;
  report.graph = optimize_pose_graph(graph, options.pose_graph);
  report.graph_keyframes = graph.nodes.size();
  report.graph_edges = graph.edges.size();

  // 6. Keyframes take the optimised poses; points move with the keyframe they were corrected by
  // (or their reference keyframe), keeping their place in that camera: p' = S_after⁻¹ S_before p.
  if (report.graph.usable) {
    for (std::size_t n = 0; n < keyframes.size(); ++n) {
      keyframes[n]->set_pose(graph.nodes[n].S_camera_world.rescaled_pose());
    }
    for (const auto& point : map.map_points()) {
      if (point->is_bad()) continue;
      std::uint64_t anchor_id;
      if (const auto it = corrected_by.find(point->id()); it != corrected_by.end()) {
        anchor_id = it->second;
      } else if (const auto reference = point->reference_keyframe()) {
        anchor_id = reference->id();
      } else {
        continue;
      }
      const auto node = node_of.find(anchor_id);
      if (node == node_of.end()) continue;
      const Sim3& before = before_optimisation[node->second].S_camera_world;
      const Sim3& after = graph.nodes[node->second].S_camera_world;
      point->set_position(after.inverse() * (before * point->position()));
      if (const auto reference = point->reference_keyframe()) {
        point->update_normal_and_depth(reference->pyramid());
      }
    }
  }
  loop_edges.emplace_back(current->id(), loop.matched->id());
  if (on_corrected) on_corrected();
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace pspslam
