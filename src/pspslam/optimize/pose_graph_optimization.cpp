#include "pspslam/optimize/pose_graph_optimization.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/product_manifold.h>
#include <ceres/solver.h>

#include <Eigen/Geometry>
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
  RelativePoseError(const Pose& T_first_second, double weight, double rotation_weight)
      : measured_rotation_inverse_(Eigen::Quaterniond(T_first_second.linear()).conjugate()),
        measured_translation_(T_first_second.translation()),
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

}  // namespace

PoseGraphResult optimize_pose_graph(PoseGraph& graph, const PoseGraphOptions& options) {
  PoseGraphResult result;
  for (size_t e = 0; e < graph.edges.size(); ++e) {
    const PoseGraphEdge& edge = graph.edges[e];
    if (edge.first >= graph.nodes.size() || edge.second >= graph.nodes.size() ||
        edge.first == edge.second) {
      throw Error("optimize_pose_graph: edge " + std::to_string(e) + " joins nodes " +
                  std::to_string(edge.first) + " and " + std::to_string(edge.second) + " of " +
                  std::to_string(graph.nodes.size()));
    }
  }
  if (graph.nodes.empty() || graph.edges.empty()) return result;

  std::vector<PoseParameters> parameters;
  parameters.reserve(graph.nodes.size());
  for (const PoseGraphNode& node : graph.nodes) {
    parameters.push_back(PoseParameters::from_pose(node.T_camera_world));
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::ProductManifold<ceres::EigenQuaternionManifold, ceres::EuclideanManifold<3>> manifold{
      ceres::EigenQuaternionManifold(), ceres::EuclideanManifold<3>()};
  for (const PoseGraphEdge& edge : graph.edges) {
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 7, 7>(
        new RelativePoseError(edge.T_first_second, edge.weight, options.rotation_weight));
    problem.AddResidualBlock(cost, nullptr, parameters[edge.first].data(),
                             parameters[edge.second].data());
  }
  bool any_fixed = false;
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    double* block = parameters[k].data();
    if (!problem.HasParameterBlock(block)) continue;  // a node without edges stays as it is
    problem.SetManifold(block, &manifold);
    if (graph.nodes[k].fixed) {
      problem.SetParameterBlockConstant(block);
      any_fixed = true;
    }
  }
  if (!any_fixed) {
    for (size_t k = 0; k < graph.nodes.size(); ++k) {
      if (!problem.HasParameterBlock(parameters[k].data())) continue;
      problem.SetParameterBlockConstant(parameters[k].data());
      break;
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.max_solver_time_in_seconds = options.max_seconds;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = static_cast<int>(summary.iterations.size());
  result.usable = summary.IsSolutionUsable();
  if (!result.usable) return result;
  for (size_t k = 0; k < graph.nodes.size(); ++k) {
    if (!graph.nodes[k].fixed) graph.nodes[k].T_camera_world = parameters[k].to_pose();
  }
  return result;
}

}  // namespace pspslam
