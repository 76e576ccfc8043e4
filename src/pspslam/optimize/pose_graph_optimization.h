#pragma once

// Essential-graph pose optimisation for loop closing (ORB-SLAM2 OptimizeEssentialGraph with the
// scale fixed: RGB-D). Plain structs, no map/ types: the loop closer copies the graph in, solves,
// and writes the poses back.
//
//   PoseGraph graph;
//   graph.nodes.push_back({id, T_camera_world, fixed});          // every keyframe
//   graph.edges.push_back({i, j, T_i_j});  // spanning tree, loop and strong covisibility edges
//   optimize_pose_graph(graph);            // graph.nodes[k].T_camera_world updated in place

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam {

struct PoseGraphNode {
  std::uint64_t id = 0;
  Pose T_camera_world = Pose::Identity();
  bool fixed = false;
};

// Relative pose constraint between nodes `first` and `second` (indices into PoseGraph::nodes):
// measured T_first_second = T_first_world · T_world_second.
struct PoseGraphEdge {
  std::size_t first = 0;
  std::size_t second = 0;
  Pose T_first_second = Pose::Identity();
  double weight = 1.0;  // scales the whole 6-vector residual (information = weight² I)
};

struct PoseGraph {
  std::vector<PoseGraphNode> nodes;
  std::vector<PoseGraphEdge> edges;
};

struct PoseGraphOptions {
  int max_iterations = 20;  // ORB-SLAM2 runs 20 Levenberg-Marquardt iterations
  // The residual is [rotation error (rad); translation error (m)]; identity information as in
  // ORB-SLAM2, so 1 rad weighs like 1 m. Indoor loops drift by centimetres and fractions of a
  // degree: both terms matter.
  double rotation_weight = 1.0;
  double max_seconds = 10.0;
  int num_threads = 1;
};

struct PoseGraphResult {
  double initial_cost = 0.0;  // ½ Σ |r|²
  double final_cost = 0.0;
  int iterations = 0;
  bool usable = false;  // the solver returned a usable solution
};

// Optimises the non-fixed nodes in place. When no node is fixed, the first one is held fixed
// (the graph has a 6-dof gauge freedom). Throws pspslam::Error for an edge indexing outside the
// node vector or joining a node to itself.
PoseGraphResult optimize_pose_graph(PoseGraph& graph, const PoseGraphOptions& options = {});

}  // namespace pspslam
