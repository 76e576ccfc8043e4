#include "pspslam/optimize/pose_graph_optimization.h"

#include <gtest/gtest.h>

#include <random>

#include "optimize/synthetic_views.h"
#include "pspslam/core/error.h"

namespace pspslam {
namespace {

using testing::make_pose;
using testing::radians;
using testing::rotation_error_deg;
using testing::translation_error;

// A loop of `n` cameras on a circle of radius 2 m, looking outwards (as the synthetic loop
// sequence does), returned as T_camera_world.
std::vector<Pose> circle_poses(int n) {
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    const double angle = 2.0 * std::numbers::pi * i / n;
    Pose T_world_camera = make_pose(
        Eigen::Vector3d(0.0, 0.0, angle),
        Eigen::Vector3d(2.0 * std::cos(angle), 2.0 * std::sin(angle), 0.1 * std::sin(3.0 * angle)));
    poses.push_back(T_world_camera.inverse());
  }
  return poses;
}

// Odometry that drifts: each step's relative pose carries the same small bias (0.25° yaw,
// 0.3° roll, 8 mm) plus noise, as visual odometry does. Returns the dead-reckoned poses.
std::vector<Pose> dead_reckoning(const std::vector<Pose>& truth, std::vector<Pose>& steps,
                                 std::mt19937& rng, double noise) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const Pose bias = make_pose(Eigen::Vector3d(radians(0.3), 0.0, radians(0.25)),
                              Eigen::Vector3d(0.008, -0.004, 0.002));
  std::vector<Pose> estimate{truth[0]};
  steps.clear();
  for (size_t i = 0; i + 1 < truth.size(); ++i) {
    const Pose true_step = truth[i] * truth[i + 1].inverse();  // T_i_(i+1)
    const Pose jitter =
        make_pose(radians(0.05) * noise * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
                  0.002 * noise * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    const Pose step = true_step * bias * jitter;
    steps.push_back(step);
    estimate.push_back(step.inverse() * estimate.back());  // T_(i+1)_w = T_(i+1)_i · T_i_w
  }
  return estimate;
}

PoseGraphNode node(std::uint64_t id, const Pose& T_camera_world, bool fixed) {
  return {id, Sim3(T_camera_world), fixed};
}

// The camera pose a node stands for (its similarity rescaled to the world's units).
Pose pose_of(const PoseGraphNode& node) { return node.S_camera_world.rescaled_pose(); }

double max_position_error(const std::vector<Pose>& truth, const PoseGraph& graph) {
  double worst = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    worst =
        std::max(worst, translation_error(pose_of(graph.nodes[i]).inverse(), truth[i].inverse()));
  }
  return worst;
}

// Root mean square camera-centre error (the first pose is fixed at the truth: no alignment).
double rms_position_error(const std::vector<Pose>& truth, const PoseGraph& graph) {
  double sum = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double e = translation_error(pose_of(graph.nodes[i]).inverse(), truth[i].inverse());
    sum += e * e;
  }
  return std::sqrt(sum / static_cast<double>(truth.size()));
}

// The essential-graph situation of loop closing: odometry edges carry the drift, one loop edge
// (last -> first) is measured exactly. Optimisation must spread the loop error over the loop.
TEST(PoseGraphOptimization, DriftCorruptedLoopIsClosed) {
  constexpr int kPoses = 60;
  const std::vector<Pose> truth = circle_poses(kPoses);
  std::mt19937 rng(7);
  std::vector<Pose> steps;
  const std::vector<Pose> drifted = dead_reckoning(truth, steps, rng, 1.0);

  PoseGraph graph;
  for (int i = 0; i < kPoses; ++i)
    graph.nodes.push_back(node(static_cast<std::uint64_t>(i), drifted[i], i == 0));
  for (int i = 0; i + 1 < kPoses; ++i)
    graph.edges.push_back({static_cast<size_t>(i), static_cast<size_t>(i + 1), Sim3(steps[i])});
  graph.edges.push_back({kPoses - 1, 0, Sim3(truth[kPoses - 1] * truth[0].inverse())});

  const double before = rms_position_error(truth, graph);
  const double end_before = translation_error(drifted.back().inverse(), truth.back().inverse());
  const PoseGraphResult result = optimize_pose_graph(graph);
  const double after = rms_position_error(truth, graph);
  const double end_after =
      translation_error(pose_of(graph.nodes.back()).inverse(), truth.back().inverse());

  ASSERT_TRUE(result.usable);
  EXPECT_LT(result.final_cost, 0.01 * result.initial_cost);
  EXPECT_GT(before, 0.1) << "the drift should be large before optimisation";
  // Biased odometry cannot be undone by one loop edge everywhere (the middle of the loop keeps
  // part of the bent shape): the loop error is spread, the RMS error about halves and the loop
  // end, measured exactly by the loop edge, lands on the start.
  EXPECT_LT(after, 0.6 * before) << "before " << before << " m, after " << after << " m";
  EXPECT_GT(end_before, 0.1);
  EXPECT_LT(end_after, 0.02) << "the loop edge is exact: the end must land on the start";
  EXPECT_NEAR(pose_of(graph.nodes[0]).translation().x(), truth[0].translation().x(), 1e-12)
      << "the fixed node must not move";
}

// With exact odometry and exact loop edge, the optimum is the ground truth, whatever the start.
TEST(PoseGraphOptimization, ExactEdgesRecoverGroundTruth) {
  constexpr int kPoses = 30;
  const std::vector<Pose> truth = circle_poses(kPoses);
  std::mt19937 rng(3);
  std::vector<Pose> steps;
  const std::vector<Pose> drifted = dead_reckoning(truth, steps, rng, 1.0);
  PoseGraph graph;
  for (int i = 0; i < kPoses; ++i)
    graph.nodes.push_back(node(static_cast<std::uint64_t>(i), drifted[i], false));
  for (int i = 0; i + 1 < kPoses; ++i) {
    graph.edges.push_back({static_cast<size_t>(i), static_cast<size_t>(i + 1),
                           Sim3(truth[i] * truth[i + 1].inverse())});
  }
  graph.edges.push_back({kPoses - 1, 0, Sim3(truth[kPoses - 1] * truth[0].inverse())});
  // No fixed node: the first one becomes the gauge, and it starts at the truth.
  const PoseGraphResult result = optimize_pose_graph(graph);
  ASSERT_TRUE(result.usable);
  EXPECT_LT(max_position_error(truth, graph), 1e-4);
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_LT(rotation_error_deg(pose_of(graph.nodes[i]), truth[i]), 0.01) << "pose " << i;
  }
}

// Monocular odometry drifts in scale: every step's measured similarity shrinks the map by 1 %
// (and carries the usual noise), so by the end of the loop the map is 25 % smaller and the last
// camera is far from the first. The loop edge says how the last keyframe truly sits relative to
// the first, scale included. With Sim(3) nodes the optimiser spreads the scale error over the
// loop; SE(3) nodes cannot absorb it and leave most of the error in place.
TEST(PoseGraphOptimization, ScaleDriftIsSpreadOverTheLoopBySimilarityNodes) {
  constexpr int kPoses = 30;
  const std::vector<Pose> truth = circle_poses(kPoses);
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  constexpr double kShrinkPerStep = 0.99;
  std::vector<Sim3> estimate{Sim3(truth[0])};
  std::vector<Sim3> steps;
  for (int i = 0; i + 1 < kPoses; ++i) {
    const Pose jitter =
        make_pose(radians(0.05) * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)),
                  0.002 * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)));
    // S_i_(i+1): the true relative pose, its translation seen at the map's current scale.
    Sim3 step(truth[i] * truth[i + 1].inverse() * jitter);
    step.scale = kShrinkPerStep;
    steps.push_back(step);
    estimate.push_back(step.inverse() * estimate.back());
  }
  const auto graph_with = [&](const std::vector<Sim3>& nodes) {
    PoseGraph graph;
    for (int i = 0; i < kPoses; ++i)
      graph.nodes.push_back({static_cast<std::uint64_t>(i), nodes[i], i == 0});
    for (int i = 0; i + 1 < kPoses; ++i)
      graph.edges.push_back({static_cast<size_t>(i), static_cast<size_t>(i + 1), steps[i]});
    graph.edges.push_back({kPoses - 1, 0, Sim3(truth[kPoses - 1] * truth[0].inverse())});
    return graph;
  };
  PoseGraph similarity = graph_with(estimate);
  const double before = rms_position_error(truth, similarity);
  PoseGraphOptions options;
  options.optimize_scale = true;
  ASSERT_TRUE(optimize_pose_graph(similarity, options).usable);
  const double after = rms_position_error(truth, similarity);
  PoseGraph rigid = graph_with(estimate);
  ASSERT_TRUE(optimize_pose_graph(rigid).usable);
  const double after_rigid = rms_position_error(truth, rigid);
  RecordProperty("rms_before_mm", static_cast<int>(1000 * before));
  RecordProperty("rms_sim3_mm", static_cast<int>(1000 * after));
  RecordProperty("rms_se3_mm", static_cast<int>(1000 * after_rigid));
  EXPECT_GT(before, 0.2) << "the synthetic scale drift should be large";
  EXPECT_LT(after, 0.1 * before) << "Sim(3): " << before << " -> " << after << " m RMS";
  EXPECT_LT(after, 0.5 * after_rigid) << "SE(3) nodes reach " << after_rigid << " m RMS";
  // The loop's last keyframe is back at its true scale (the loop edge measured scale 1).
  EXPECT_NEAR(similarity.nodes[kPoses - 1].S_camera_world.scale, 1.0, 0.02);
  EXPECT_EQ(similarity.nodes[0].S_camera_world.scale, 1.0) << "the fixed node keeps its scale";
}

TEST(PoseGraphOptimization, RejectsBadEdges) {
  PoseGraph graph;
  graph.nodes.push_back(node(0, Pose::Identity(), true));
  graph.nodes.push_back(node(1, Pose::Identity(), false));
  graph.edges.push_back({0, 2, Sim3()});
  EXPECT_THROW(optimize_pose_graph(graph), Error);
  graph.edges = {{1, 1, Sim3()}};
  EXPECT_THROW(optimize_pose_graph(graph), Error);
}

}  // namespace
}  // namespace pspslam
