#include "pspslam/optimize/rolling_shutter_pose.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "pspslam/optimize/reprojection_error.h"

namespace pspslam {
namespace {

using Matrix9 = Eigen::Matrix<double, 9, 9>;
using Vector9 = Eigen::Matrix<double, 9, 1>;

// Adds observation i's whitened residual to the normal equations (and its squared norm to
// `cost`); false when the point is at or behind the camera.
template <int kResiduals>
bool accumulate(const StereoProjection& model, const PoseObservation& observation, double dt,
                const Pose& pose, const Eigen::Vector3d& rho, Matrix9& H, Vector9& g,
                double& cost) {
  const Eigen::Vector3d p = pose * observation.point_world;
  // To first order in rho dt (a few milliradians): Exp(-dt [rho]x) ~ I - dt [rho]x.
  const Eigen::Matrix3d turn = Eigen::Matrix3d::Identity() - dt * skew_symmetric(rho);
  const Eigen::Vector3d seen = turn * p;
  Measurement<kResiduals> measured;
  measured.template head<2>() = observation.pixel;
  if constexpr (kResiduals == 3) measured(2) = observation.right_u;
  Eigen::Matrix<double, kResiduals, 1> r;
  Eigen::Matrix<double, kResiduals, 3> dr_dseen;
  if (!whitened_residual<kResiduals>(model, measured, std::sqrt(observation.information), seen, r,
                                     &dr_dseen)) {
    return false;
  }
  Eigen::Matrix<double, kResiduals, 9> J;
  // Left pose update p -> Exp(w) p + v: dp/dw = -[p]x, dp/dv = I; d(seen)/d(rho) = dt [p]x.
  const Eigen::Matrix3d p_cross = skew_symmetric(p);
  J.template leftCols<3>() = dr_dseen * turn * (-p_cross);
  J.template middleCols<3>(3) = dr_dseen * turn;
  J.template rightCols<3>() = dr_dseen * (dt * p_cross);
  H.noalias() += J.transpose() * J;
  g.noalias() += J.transpose() * r;
  cost += r.squaredNorm();
  return true;
}

// The pose block of H with the rate eliminated: H_pp − H_pr H_rr⁻¹ H_rp (H_rr holds the prior,
// so it is invertible).
PoseInformation marginal_pose_information(const Matrix9& H) {
  const Eigen::Matrix3d rate_block = H.bottomRightCorner<3, 3>();
  const Eigen::Matrix<double, 6, 3> coupling = H.topRightCorner<6, 3>();
  return H.topLeftCorner<6, 6>() - coupling * rate_block.ldlt().solve(coupling.transpose());
}

}  // namespace

RollingShutterPose refine_pose_and_rotation_rate(const PinholeCamera& camera, double bf,
                                                 const DepthNoiseModel& depth_noise,
                                                 const Pose& initial_T_camera_world,
                                                 const std::vector<PoseObservation>& observations,
                                                 const std::vector<double>& row_times,
                                                 double sigma_rate, int iterations) {
  RollingShutterPose result{initial_T_camera_world, Eigen::Vector3d::Zero()};
  if (observations.size() != row_times.size() || observations.empty() || !(sigma_rate > 0.0)) {
    return result;
  }
  const StereoProjection model = StereoProjection::from(camera, bf, depth_noise);
  const double prior_weight = 1.0 / (sigma_rate * sigma_rate);
  Pose pose = initial_T_camera_world;
  Eigen::Vector3d rho = Eigen::Vector3d::Zero();
  Matrix9 H = Matrix9::Zero();  // kept after the loop: the last iteration's normal equations
  for (int iteration = 0; iteration < iterations; ++iteration) {
    H.setZero();
    Vector9 g = Vector9::Zero();
    double cost = 0.0;
    for (size_t i = 0; i < observations.size(); ++i) {
      const PoseObservation& observation = observations[i];
      const bool ok = std::isnan(observation.right_u)
                          ? accumulate<2>(model, observation, row_times[i], pose, rho, H, g, cost)
                          : accumulate<3>(model, observation, row_times[i], pose, rho, H, g, cost);
      if (!ok) return {initial_T_camera_world, Eigen::Vector3d::Zero()};
    }
    // The prior's residual rho / sigma.
    H.bottomRightCorner<3, 3>().diagonal().array() += prior_weight;
    g.tail<3>() += prior_weight * rho;
    const Eigen::LDLT<Matrix9> solver(H);
    if (solver.info() != Eigen::Success) return {initial_T_camera_world, Eigen::Vector3d::Zero()};
    // r = sqrt(info) (measured - projection): the Gauss-Newton step solves H delta = -J^T r.
    const Vector9 delta = solver.solve(-g);
    if (!delta.allFinite()) return {initial_T_camera_world, Eigen::Vector3d::Zero()};
    const Eigen::Vector3d w = delta.head<3>();
    Pose update = Pose::Identity();
    if (w.norm() > 0.0) update.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).matrix();
    update.translation() = delta.segment<3>(3);
    pose = update * pose;
    rho += delta.tail<3>();
    if (delta.norm() < 1e-10) break;
  }
  return {pose, rho, iterations > 0 ? marginal_pose_information(H) : PoseInformation::Zero()};
}

}  // namespace pspslam
