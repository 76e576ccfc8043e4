#pragma once

// Reprojection residuals shared by the pose-only optimiser and bundle adjustment. Internal to
// pspslam_optimize (it pulls in Ceres, which the public headers keep out of their users' way).

#include <ceres/sized_cost_function.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/optimize/depth_noise_model.h"

namespace pspslam {

// Pinhole intrinsics plus bf = fx · baseline, the ORB-SLAM2 RGB-D "virtual stereo" model: a depth
// z turns into a right-image coordinate u_r = u − bf / z, so depth error is weighed in pixels.
struct StereoProjection {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0, bf = 0.0;
  DepthNoiseModel depth_noise;

  static StereoProjection from(const PinholeCamera& camera, double bf,
                               const DepthNoiseModel& depth_noise) {
    return {camera.fx, camera.fy, camera.cx, camera.cy, bf, depth_noise};
  }
};

// kResiduals = 2: (u, v) only; kResiduals = 3: (u, v, u_r) for a keypoint with valid depth (the
// third row of the residual is u_r, or the disparity u − u_r with depth_noise.enabled).
template <int kResiduals>
using Measurement = Eigen::Matrix<double, kResiduals, 1>;

// Whitened residual r = √information · (measurement − projection(p_c)) and, when requested,
// ∂r/∂p_c. Returns false for points at or behind the camera, where the projection is undefined.
template <int kResiduals>
inline bool whitened_residual(const StereoProjection& model,
                              const Measurement<kResiduals>& measured, double sqrt_information,
                              const Eigen::Vector3d& point_camera,
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
  double sqrt_information_depth = sqrt_information;
  if constexpr (kResiduals == 3) {
    if (model.depth_noise.enabled) {
      // Row 3 = measured − predicted disparity, whitened by the sensor's σ_d (see DepthNoiseModel).
      const double disparity = std::max(measured(0) - measured(2), 1e-9);
      sqrt_information_depth = model.depth_noise.sqrt_information(model.bf, disparity);
      residual(2) = disparity - model.bf * inv_z;
    } else {
      residual(2) = measured(2) - (u - model.bf * inv_z);
    }
  }
  residual.template head<2>() *= sqrt_information;
  if constexpr (kResiduals == 3) residual(2) *= sqrt_information_depth;

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
      if (model.depth_noise.enabled) {
        jacobian(2, 0) = 0.0;
        jacobian(2, 1) = 0.0;
        jacobian(2, 2) = model.bf * inv_z * inv_z;
      } else {
        jacobian(2, 0) = -model.fx * inv_z;
        jacobian(2, 1) = 0.0;
        jacobian(2, 2) = model.fx * x_over_z * inv_z - model.bf * inv_z * inv_z;
      }
    }
    jacobian.template topRows<2>() *= sqrt_information;
    if constexpr (kResiduals == 3) jacobian.row(2) *= sqrt_information_depth;
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

// The outlier classification after a solve (ORB-SLAM2's χ² test): observation i is an inlier
// when chi2_of(i) is at most chi2_stereo for an observation with a right coordinate (right_u not
// NaN: 3 residuals), chi2_mono otherwise (2). Every observation is classified, earlier outliers
// too. Returns the number of inliers.
template <typename Observation, typename Chi2Of>
inline int classify_by_chi2(const std::vector<Observation>& observations, double chi2_mono,
                            double chi2_stereo, const Chi2Of& chi2_of,
                            std::vector<std::uint8_t>& inlier) {
  int inliers = 0;
  for (size_t i = 0; i < observations.size(); ++i) {
    const double threshold = std::isnan(observations[i].right_u) ? chi2_mono : chi2_stereo;
    inlier[i] = chi2_of(i) <= threshold;
    inliers += inlier[i];
  }
  return inliers;
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

// Huber kernel applied inside a residual, g2o style, for costs that cannot use a Ceres loss
// function on the whole block: the residual is scaled so its squared norm is ρ(s) (the cost is the
// robust cost) and the Jacobian by √ρ'(s) (iteratively reweighted least squares).
// ρ(s) = s for s ≤ δ², 2δ√s − δ² beyond; delta <= 0 disables the kernel.
struct RobustScaling {
  double residual = 1.0;
  double jacobian = 1.0;
};

inline RobustScaling huber_scaling(double squared_norm, double delta) {
  if (delta <= 0.0 || squared_norm <= delta * delta) return {};
  const double norm = std::sqrt(squared_norm);
  return {std::sqrt((2.0 * delta * norm - delta * delta) / squared_norm), std::sqrt(delta / norm)};
}

// Which rows of an observation one bundle-adjustment residual block carries. Every block has two
// rows so that Ceres' Schur eliminator runs its compiled <2, 3, 6> specialisation: with mixed 2-
// and 3-row blocks it falls back to the generic dynamic-size code, several times slower. An RGB-D
// observation (u, v, u_r) is therefore two blocks, (u, v) and (u_r, 0); the padding row is zero in
// value and Jacobian and so changes nothing.
enum class ObservationRows { kPixel, kRightPadded };

// Residual of a point (parameter block 2, world coordinates) seen by a keyframe (block 1, pose).
// kDof = 2: (u, v) only; kDof = 3: with depth, the robust kernel sees all three rows' χ².
template <int kDof, ObservationRows kRows>
class BundleReprojectionCost final : public ceres::SizedCostFunction<2, 7, 3> {
  static_assert(kDof == 3 || kRows == ObservationRows::kPixel);

 public:
  BundleReprojectionCost(const StereoProjection& model, const Measurement<kDof>& measured,
                         double sqrt_information, double huber_delta)
      : model_(model),
        measured_(measured),
        sqrt_information_(sqrt_information),
        huber_delta_(huber_delta) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> point_world(parameters[1]);
    const Eigen::Vector3d point_camera = transform_point(parameters[0], point_world);
    const bool want_jacobian =
        jacobians != nullptr && (jacobians[0] != nullptr || jacobians[1] != nullptr);
    Eigen::Matrix<double, kDof, 1> residual;
    Eigen::Matrix<double, kDof, 3> d_residual_d_point;
    if (!whitened_residual<kDof>(model_, measured_, sqrt_information_, point_camera, residual,
                                 want_jacobian ? &d_residual_d_point : nullptr)) {
      return false;
    }
    const RobustScaling scaling = huber_scaling(residual.squaredNorm(), huber_delta_);
    Eigen::Vector2d rows;
    Eigen::Matrix<double, 2, 3> d_rows_d_point;
    if constexpr (kRows == ObservationRows::kPixel) {
      rows = residual.template head<2>();
      if (want_jacobian) d_rows_d_point = d_residual_d_point.template topRows<2>();
    } else {
      rows << residual(2), 0.0;
      if (want_jacobian) d_rows_d_point << d_residual_d_point.row(2), Eigen::RowVector3d::Zero();
    }
    Eigen::Map<Eigen::Vector2d> output(residuals);
    output = scaling.residual * rows;
    if (!want_jacobian) return true;
    d_rows_d_point *= scaling.jacobian;
    if (jacobians[0] != nullptr) {
      write_pose_jacobian<2>(d_rows_d_point, point_camera, jacobians[0]);
    }
    if (jacobians[1] != nullptr) {
      // ∂p_c/∂p_w = R.
      const Eigen::Map<const Eigen::Quaterniond> rotation(parameters[0]);
      Eigen::Map<Eigen::Matrix<double, 2, 3, Eigen::RowMajor>> point_jacobian(jacobians[1]);
      point_jacobian = d_rows_d_point * rotation.toRotationMatrix();
    }
    return true;
  }

 private:
  StereoProjection model_;
  Measurement<kDof> measured_;
  double sqrt_information_;
  double huber_delta_;
};

}  // namespace pspslam
