#pragma once

// Essential-graph optimisation for loop closing (ORB-SLAM2 OptimizeEssentialGraph): nodes and
// edges are similarities; their scales are optimised for a monocular map (7 dof per keyframe,
// the scale drift spreads over the loop) and stay at 1 otherwise (6 dof, depth fixes the scale).
// Plain structs, no map/ types: the loop closer copies the graph in, solves, and writes back.
//
//   PoseGraph graph;
//   graph.nodes.push_back({id, S_camera_world, fixed});          // every keyframe
//   graph.edges.push_back({i, j, S_i_j});  // spanning tree, loop and strong covisibility edges
//   optimize_pose_graph(graph);            // graph.nodes[k].S_camera_world updated in place

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pspslam/core/similarity.h"

namespace pspslam {

struct PoseGraphNode {
  std::uint64_t id = 0;
  Sim3 S_camera_world;
  bool fixed = false;
};

// Relative constraint between nodes `first` and `second` (indices into PoseGraph::nodes):
// measured S_first_second = S_first_world · S_second_world⁻¹.
struct PoseGraphEdge {
  std::size_t first = 0;
  std::size_t second = 0;
  Sim3 S_first_second;
  double weight = 1.0;  // scales the whole residual (information = weight² I)
};

struct PoseGraph {
  std::vector<PoseGraphNode> nodes;
  std::vector<PoseGraphEdge> edges;
};

struct PoseGraphOptions {
  int max_iterations = 20;  // ORB-SLAM2 runs 20 Levenberg-Marquardt iterations
  // The residual is [rotation error (rad); translation error (m)] (and, with optimize_scale,
  // the log scale error); identity information as in ORB-SLAM2, so 1 rad weighs like 1 m.
  // Indoor loops drift by centimetres and fractions of a degree: both terms matter.
  double rotation_weight = 1.0;
  // Sim(3) nodes (monocular). Without it the scales are taken as 1 and the nodes are SE(3).
  bool optimize_scale = false;
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
// (the graph has a 6-dof, with scale 7-dof, gauge freedom). Throws pspslam::Error for an edge
// indexing outside the node vector or joining a node to itself.
PoseGraphResult optimize_pose_graph(PoseGraph& graph, const PoseGraphOptions& options = {});

}  // namespace pspslam
