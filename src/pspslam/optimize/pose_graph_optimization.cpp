#include "pspslam/optimize/pose_graph_optimization.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/solver.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/optimize/pose_manifold.h"

namespace pspslam {
namespace {

// r = [w_R · Log(R_err); t_err] with T_err = T_measured⁻¹ · T_first_world · T_second_world⁻¹.
// Log is taken as 2·vec(q) (sign fixed to w >= 0): exact to O(θ³), and the loop errors this graph
// spreads are a few degrees at most. Automatic differentiation through the quaternion, with
// Ceres' quaternion manifold (the analytic PoseManifold expects tangent-space Jacobians, which
// autodiff does not produce).
class RelativePoseError {
 public:
  RelativePoseError(const Sim3& S_first_second, double weight, double rotation_weight)
      : measured_rotation_inverse_(Eigen::Quaterniond(S_first_second.rotation).conjugate()),
        measured_translation_(S_first_second.translation),
        weight_(weight),
        rotation_weight_(rotation_weight) {}

  template <typename T>
  bool operator()(const T* first, const T* second, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_first(first);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_first(first + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_second(second);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_second(second + 4);
    // Predicted T_first_second = T_first_world · T_second_world⁻¹.
    const Eigen::Quaternion<T> q_predicted = q_first * q_second.conjugate();
    const Eigen::Matrix<T, 3, 1> t_predicted = t_first - q_predicted * t_second;
    const Eigen::Quaternion<T> q_measured_inverse = measured_rotation_inverse_.cast<T>();
    Eigen::Quaternion<T> q_error = q_measured_inverse * q_predicted;
    if (q_error.w() < T(0)) q_error.coeffs() = -q_error.coeffs();
    const Eigen::Matrix<T, 3, 1> t_error =
        q_measured_inverse * (t_predicted - measured_translation_.cast<T>());
    const T rotation_scale = T(2.0 * weight_ * rotation_weight_);
    for (int k = 0; k < 3; ++k) {
      residual[k] = rotation_scale * q_error.vec()[k];
      residual[3 + k] = T(weight_) * t_error[k];
    }
    return true;
  }

 private:
  Eigen::Quaterniond measured_rotation_inverse_;
  Eigen::Vector3d measured_translation_;
  double weight_;
  double rotation_weight_;
};

// The Sim(3) form, for monocular maps (ORB-SLAM2's EdgeSim3): each node adds a log-scale block.
// With S_i = (s_i, R_i, t_i) the prediction is S_first_second = S_first · S_second⁻¹, i.e.
// (s_p, R_p, t_p) = (s_1 / s_2, R_1 R_2ᵀ, t_1 − s_p R_p t_2), and the error is
// S_measured⁻¹ · S_predicted = (s_p / s_m, R_mᵀ R_p, R_mᵀ (t_p − t_m) / s_m), read as
// r = [w_R · 2 vec(q_err); t_err; log(s_p / s_m)].
class RelativeSimilarityError {
 public:
  RelativeSimilarityError(const Sim3& S_first_second, double weight, double rotation_weight)
      : measured_rotation_inverse_(Eigen::Quaterniond(S_first_second.rotation).conjugate()),
        measured_translation_(S_first_second.translation),
        measured_log_scale_(std::log(S_first_second.scale)),
        weight_(weight),
        rotation_weight_(rotation_weight) {}

  template <typename T>
  bool operator()(const T* first, const T* first_log_scale, const T* second,
                  const T* second_log_scale, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_first(first);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_first(first + 4);
    const Eigen::Map<const Eigen::Quaternion<T>> q_second(second);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> t_second(second + 4);
    const T log_scale_predicted = first_log_scale[0] - second_log_scale[0];
    const Eigen::Quaternion<T> q_predicted = q_first * q_second.conjugate();
    const Eigen::Matrix<T, 3, 1> t_predicted =
        t_first - ceres::exp(log_scale_predicted) * (q_predicted * t_second);
    const Eigen::Quaternion<T> q_measured_inverse = measured_rotation_inverse_.cast<T>();
    Eigen::Quaternion<T> q_error = q_measured_inverse * q_predicted;
    if (q_error.w() < T(0)) q_error.coeffs() = -q_error.coeffs();
    const Eigen::Matrix<T, 3, 1> t_error =
        (q_measured_inverse * (t_predicted - measured_translation_.cast<T>())) *
        T(std::exp(-measured_log_scale_));
    const T rotation_scale = T(2.0 * weight_ * rotation_weight_);
    for (int k = 0; k < 3; ++k) {
      residual[k] = rotation_scale * q_error.vec()[k];
      residual[3 + k] = T(weight_) * t_error[k];
    }
    residual[6] = T(weight_) * (log_scale_predicted - T(measured_log_scale_));
    return true;
  }

 private:
  Eigen::Quaterniond measured_rotation_inverse_;
  Eigen::Vector3d measured_translation_;
  double measured_log_scale_;
  double weight_;
  double rotation_weight_;
};

void check_edges(const PoseGraph& graph) {
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const PoseGraphEdge& edge = graph.edges[e];
    if (edge.first >= graph.nodes.size() || edge.second >= graph.nodes.size() ||
        edge.first == edge.second) {
      throw Error("optimize_pose_graph: edge " + std::to_string(e) + " joins nodes " +
                  std::to_string(edge.first) + " and " + std::to_string(edge.second) + " of " +
                  std::to_string(graph.nodes.size()));
    }
  }
}

// Each node: the rotation and translation of its similarity as a pose block, and (with
// optimize_scale) its log scale as a block of one.
struct NodeBlocks {
  std::vector<PoseParameters> parameters;
  std::vector<double> log_scales;
};

NodeBlocks node_blocks(const PoseGraph& graph) {
  NodeBlocks blocks;
  blocks.parameters.reserve(graph.nodes.size());
  blocks.log_scales.reserve(graph.nodes.size());
  for (const PoseGraphNode& node : graph.nodes) {
    Pose rigid = Pose::Identity();
    rigid.linear() = node.S_camera_world.rotation;
    rigid.translation() = node.S_camera_world.translation;
    blocks.parameters.push_back(PoseParameters::from_pose(rigid));
    blocks.log_scales.push_back(std::log(node.S_camera_world.scale));
  }
  return blocks;
}

void add_edges(const PoseGraph& graph, const PoseGraphOptions& options, NodeBlocks& blocks,
               ceres::Problem& problem) {
  std::vector<PoseParameters>& parameters = blocks.parameters;
  std::vector<double>& log_scales = blocks.log_scales;
  for (const PoseGraphEdge& edge : graph.edges) {
    if (options.optimize_scale) {
      auto* cost = new ceres::AutoDiffCostFunction<RelativeSimilarityError, 7, 7, 1, 7, 1>(
          new RelativeSimilarityError(edge.S_first_second, edge.weight, options.rotation_weight));
      problem.AddResidualBlock(cost, nullptr, parameters[edge.first].data(),
                               &log_scales[edge.first], parameters[edge.second].data(),
                               &log_scales[edge.second]);
    } else {
      auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 7, 7>(
          new RelativePoseError(edge.S_first_second, edge.weight, options.rotation_weight));
      problem.AddResidualBlock(cost, nullptr, parameters[edge.first].data(),
                               parameters[edge.second].data());
    }
  }
}

// Sets the pose manifold on every node with edges and holds the fixed nodes; without a fixed
// node the first node with edges is held (the gauge).
void hold_gauge(const PoseGraph& graph, const PoseGraphOptions& options, NodeBlocks& blocks,
                ceres::Manifold* manifold, ceres::Problem& problem) {
  const auto hold = [&](size_t k) {
    problem.SetParameterBlockConstant(blocks.parameters[k].data());
    if (options.optimize_scale) problem.SetParameterBlockConstant(&blocks.log_scales[k]);
  };
  bool any_fixed = false;
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    double* block = blocks.parameters[k].data();
    if (!problem.HasParameterBlock(block)) continue;  // a node without edges stays as it is
    problem.SetManifold(block, manifold);
    if (graph.nodes[k].fixed) {
      hold(k);
      any_fixed = true;
    }
  }
  if (any_fixed) return;
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    if (!problem.HasParameterBlock(blocks.parameters[k].data())) continue;
    hold(k);
    break;
  }
}

ceres::Solver::Options pose_graph_solver_options(const PoseGraphOptions& options) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.max_solver_time_in_seconds = options.max_seconds;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  return solver_options;
}

}  // namespace

PoseGraphResult optimize_pose_graph(PoseGraph& graph, const PoseGraphOptions& options) {
  PoseGraphResult result;
  check_edges(graph);
  if (graph.nodes.empty() || graph.edges.empty()) return result;
  NodeBlocks blocks = node_blocks(graph);

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>> manifold{
      ceres::EigenQuaternionManifold(), ceres::EuclideanManifold<3>()};
  add_edges(graph, options, blocks, problem);
  hold_gauge(graph, options, blocks, &manifold, problem);

  ceres::Solver::Summary summary;
  ceres::Solve(pose_graph_solver_options(options), &problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.usable = summary.IsSolutionUsable();
  if (!result.usable) return result;
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    if (graph.nodes[k].fixed) continue;
    const Pose rigid = blocks.parameters[k].to_pose();
    graph.nodes[k].S_camera_world =
        Sim3(rigid.linear(), rigid.translation(),
             options.optimize_scale ? std::exp(blocks.log_scales[k])
                                    : graph.nodes[k].S_camera_world.scale);
  }
  return result;
}

}  // namespace pspslam
