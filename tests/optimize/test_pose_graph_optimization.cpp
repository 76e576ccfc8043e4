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

double max_position_error(const std::vector<Pose>& truth, const PoseGraph& graph) {
  double worst = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    worst = std::max(
        worst, translation_error(graph.nodes[i].T_camera_world.inverse(), truth[i].inverse()));
  }
  return worst;
}

// Root mean square camera-centre error (the first pose is fixed at the truth: no alignment).
double rms_position_error(const std::vector<Pose>& truth, const PoseGraph& graph) {
  double sum = 0.0;
  for (size_t i = 0; i < truth.size(); ++i) {
    const double e = translation_error(graph.nodes[i].T_camera_world.inverse(), truth[i].inverse());
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
    graph.nodes.push_back({static_cast<std::uint64_t>(i), drifted[i], i == 0});
  for (int i = 0; i + 1 < kPoses; ++i)
    graph.edges.push_back({static_cast<size_t>(i), static_cast<size_t>(i + 1), steps[i]});
  graph.edges.push_back({kPoses - 1, 0, truth[kPoses - 1] * truth[0].inverse()});

  const double before = rms_position_error(truth, graph);
  const double end_before = translation_error(drifted.back().inverse(), truth.back().inverse());
  const PoseGraphResult result = optimize_pose_graph(graph);
  const double after = rms_position_error(truth, graph);
  const double end_after =
      translation_error(graph.nodes.back().T_camera_world.inverse(), truth.back().inverse());

  ASSERT_TRUE(result.usable);
  EXPECT_LT(result.final_cost, 0.01 * result.initial_cost);
  EXPECT_GT(before, 0.1) << "the drift should be large before optimisation";
  // Biased odometry cannot be undone by one loop edge everywhere (the middle of the loop keeps
  // part of the bent shape): the loop error is spread, the RMS error about halves (measured
  // 0.203 -> 0.106 m) and the loop end, measured exactly by the loop edge, lands on the start.
  EXPECT_LT(after, 0.6 * before) << "before " << before << " m, after " << after << " m";
  EXPECT_GT(end_before, 0.1);
  EXPECT_LT(end_after, 0.02) << "the loop edge is exact: the end must land on the start";
  EXPECT_NEAR(graph.nodes[0].T_camera_world.translation().x(), truth[0].translation().x(), 1e-12)
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
    graph.nodes.push_back({static_cast<std::uint64_t>(i), drifted[i], false});
  for (int i = 0; i + 1 < kPoses; ++i) {
    graph.edges.push_back(
        {static_cast<size_t>(i), static_cast<size_t>(i + 1), truth[i] * truth[i + 1].inverse()});
  }
  graph.edges.push_back({kPoses - 1, 0, truth[kPoses - 1] * truth[0].inverse()});
  // No fixed node: the first one becomes the gauge, and it starts at the truth.
  const PoseGraphResult result = optimize_pose_graph(graph);
  ASSERT_TRUE(result.usable);
  EXPECT_LT(max_position_error(truth, graph), 1e-4);
  for (int i = 0; i < kPoses; ++i) {
    EXPECT_LT(rotation_error_deg(graph.nodes[i].T_camera_world, truth[i]), 0.01) << "pose " << i;
  }
}

TEST(PoseGraphOptimization, RejectsBadEdges) {
  PoseGraph graph;
  graph.nodes.push_back({0, Pose::Identity(), true});
  graph.nodes.push_back({1, Pose::Identity(), false});
  graph.edges.push_back({0, 2, Pose::Identity()});
  EXPECT_THROW(optimize_pose_graph(graph), Error);
  graph.edges = {{1, 1, Pose::Identity()}};
  EXPECT_THROW(optimize_pose_graph(graph), Error);
}

}  // namespace
}  // namespace pspslam
