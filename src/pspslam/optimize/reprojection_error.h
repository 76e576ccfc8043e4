#pragma once

// Reprojection residuals shared by the pose-only optimiser and bundle adjustment. Internal to
// pspslam_optimize (it pulls in Ceres, which the public headers keep out of their users' way).

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "pspslam/camera/pinhole_camera.h"

namespace pspslam {

// Pinhole intrinsics plus bf = fx · baseline, the ORB-SLAM2 RGB-D "virtual stereo" model: a depth
// z turns into a right-image coordinate u_r = u − bf / z, so depth error is weighed in pixels.
struct StereoProjection {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0, bf = 0.0;

  static StereoProjection from(const PinholeCamera& camera, double bf) {
    return {camera.fx, camera.fy, camera.cx, camera.cy, bf};
  }
};

// kResiduals = 2: (u, v) only; kResiduals = 3: (u, v, u_r) for a keypoint with valid depth.
template <int kResiduals>
using Measurement = Eigen::Matrix<double, kResiduals, 1>;

// Whitened residual r = √information · (measurement − projection(p_c)) and, when requested,
// ∂r/∂p_c. Returns false for points at or behind the camera, where the projection is undefined.
template <int kResiduals>
inline bool whitened_residual(const StereoProjection& model, const Measurement<kResiduals>& measured,
                              double sqrt_information, const Eigen::Vector3d& point_camera,
                              Eigen::Matrix<double, kResiduals, 1>& residual,
                              Eigen::Matrix<double, kResiduals, 3>* d_residual_d_point) {
  static_assert(kResiduals == 2 || kResiduals == 3);
  constexpr double kMinDepth = 1e-6;
  const double z = point_camera.z();
  if (z < kMinDepth) return false;
  const double inv_z = 1.0 / z;
  const double x_over_z = point_camera.x() * inv_z;
  const double y_over_z = point_camera.y() * inv_z;
  const double u = model.fx * x_over_z + model.cx;
  residual(0) = measured(0) - u;
  residual(1) = measured(1) - (model.fy * y_over_z + model.cy);
  if constexpr (kResiduals == 3) residual(2) = measured(2) - (u - model.bf * inv_z);
  residual *= sqrt_information;

  if (d_residual_d_point != nullptr) {
    auto& jacobian = *d_residual_d_point;
    // ∂(measured − projection)/∂p_c = −∂projection/∂p_c.
    jacobian(0, 0) = -model.fx * inv_z;
    jacobian(0, 1) = 0.0;
    jacobian(0, 2) = model.fx * x_over_z * inv_z;
    jacobian(1, 0) = 0.0;
    jacobian(1, 1) = -model.fy * inv_z;
    jacobian(1, 2) = model.fy * y_over_z * inv_z;
    if constexpr (kResiduals == 3) {
      jacobian(2, 0) = jacobian(0, 0);
      jacobian(2, 1) = 0.0;
      jacobian(2, 2) = jacobian(0, 2) - model.bf * inv_z * inv_z;
    }
    jacobian *= sqrt_information;
  }
  return true;
}

// χ² of one observation (squared whitened residual); +∞ behind the camera so it is an outlier.
template <int kResiduals>
inline double chi_squared(const StereoProjection& model, const Measurement<kResiduals>& measured,
                          double sqrt_information, const Eigen::Vector3d& point_camera) {
  Eigen::Matrix<double, kResiduals, 1> residual;
  if (!whitened_residual<kResiduals>(model, measured, sqrt_information, point_camera, residual,
                                     nullptr)) {
    return std::numeric_limits<double>::infinity();
  }
  return residual.squaredNorm();
}

// Writes ∂r/∂δ = ∂r/∂p_c · [−[p_c]×, I] (the PoseManifold tangent) into the first six columns of a
// row-major kResiduals × 7 block; the seventh column is zero (see PoseManifold).
template <int kResiduals>
inline void write_pose_jacobian(const Eigen::Matrix<double, kResiduals, 3>& d_residual_d_point,
                                const Eigen::Vector3d& point_camera, double* jacobian) {
  Eigen::Map<Eigen::Matrix<double, kResiduals, 7, Eigen::RowMajor>> pose_jacobian(jacobian);
  Eigen::Matrix3d minus_skew;
  minus_skew << 0.0, point_camera.z(), -point_camera.y(),  //
      -point_camera.z(), 0.0, point_camera.x(),            //
      point_camera.y(), -point_camera.x(), 0.0;
  pose_jacobian.template leftCols<3>() = d_residual_d_point * minus_skew;
  pose_jacobian.template middleCols<3>(3) = d_residual_d_point;
  pose_jacobian.col(6).setZero();
}

inline Eigen::Vector3d transform_point(const double* pose_parameters,
                                       const Eigen::Vector3d& point_world) {
  const Eigen::Map<const Eigen::Quaterniond> rotation(pose_parameters);
  const Eigen::Map<const Eigen::Vector3d> translation(pose_parameters + 4);
  return rotation * point_world + translation;
}

// Residual of a point (parameter block 2, world coordinates) seen by a keyframe (block 1, pose).
template <int kResiduals>
class BundleReprojectionCost final : public ceres::SizedCostFunction<kResiduals, 7, 3> {
 public:
  BundleReprojectionCost(const StereoProjection& model, const Measurement<kResiduals>& measured,
                         double sqrt_information)
      : model_(model), measured_(measured), sqrt_information_(sqrt_information) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> point_world(parameters[1]);
    const Eigen::Vector3d point_camera = transform_point(parameters[0], point_world);
    Eigen::Map<Eigen::Matrix<double, kResiduals, 1>> residual(residuals);
    Eigen::Matrix<double, kResiduals, 1> value;
    const bool want_jacobian =
        jacobians != nullptr && (jacobians[0] != nullptr || jacobians[1] != nullptr);
    Eigen::Matrix<double, kResiduals, 3> d_residual_d_point;
    if (!whitened_residual<kResiduals>(model_, measured_, sqrt_information_, point_camera, value,
                                       want_jacobian ? &d_residual_d_point : nullptr)) {
      return false;
    }
    residual = value;
    if (!want_jacobian) return true;
    if (jacobians[0] != nullptr) {
      write_pose_jacobian<kResiduals>(d_residual_d_point, point_camera, jacobians[0]);
    }
    if (jacobians[1] != nullptr) {
      // ∂p_c/∂p_w = R.
      const Eigen::Map<const Eigen::Quaterniond> rotation(parameters[0]);
      Eigen::Map<Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor>> point_jacobian(
          jacobians[1]);
      point_jacobian = d_residual_d_point * rotation.toRotationMatrix();
    }
    return true;
  }

 private:
  StereoProjection model_;
  Measurement<kResiduals> measured_;
  double sqrt_information_;
};

}  // namespace pspslam
