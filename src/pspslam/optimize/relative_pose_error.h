#pragma once

// The relative-pose factor bundle adjustment takes from tracking: keyframe b was tracked at
// Z = T_b · T_a⁻¹ from keyframe a, with the information of its pose-only optimisation. Internal
// to pspslam_optimize (Ceres).

#include <ceres/sized_cost_function.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>

#include "pspslam/core/types.h"
#include "pspslam/optimize/pose_manifold.h"
#include "pspslam/optimize/pose_optimizer.h"

namespace pspslam {

// Inverse of the left Jacobian of SO(3): Exp(φ + J_l⁻¹(φ) δ) ≈ Exp(δ) Exp(φ).
inline Eigen::Matrix3d so3_inverse_left_jacobian(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d skew = skew_symmetric(phi);
  if (angle < 1e-6) return Eigen::Matrix3d::Identity() - 0.5 * skew;
  const double coefficient =
      1.0 / (angle * angle) - (1.0 + std::cos(angle)) / (2.0 * angle * std::sin(angle));
  return Eigen::Matrix3d::Identity() - 0.5 * skew + coefficient * skew * skew;
}

// Residual r = L (Log R_E; t_E) of the error E = T_b T_a⁻¹ Z⁻¹, a pose in camera b's frame, with
// L Lᵀ = Λ: E = (Exp δ_ω, δ_v) is tracking's own left update of T_b, so Λ is the information
// tracking had for T_b with a held still (it was part of the map tracking saw).
// Parameters: pose a, pose b (PoseParameters). Jacobians in PoseManifold's convention: the
// 6-dof tangent in the first 6 of 7 columns.
class RelativePoseCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const Pose& T_b_a, const PoseInformation& information)
      : T_a_b_measured_(T_b_a.inverse()) {
    // Λ = U Uᵀ with U upper-triangular: r = Uᵀ e gives rᵀ r = eᵀ Λ e.
    sqrt_information_ = information.llt().matrixU();
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Pose T_a = pose_of(parameters[0]);
    const Pose T_b = pose_of(parameters[1]);
    const Pose relative = T_b * T_a.inverse();  // M
    const Pose error = relative * T_a_b_measured_;
    const Eigen::AngleAxisd angle_axis(error.rotation());
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = angle_axis.angle() * angle_axis.axis();
    e.tail<3>() = error.translation();
    Eigen::Map<Eigen::Matrix<double, 6, 1>> r(residuals);
    r = sqrt_information_ * e;
    if (jacobians == nullptr) return true;

    // Left update of b: E ← (Exp ω, v) E. Left update of a: E ← (Exp ω', v') E with
    // ω' = −R_M ω, v' = −R_M v − [t_M]× R_M ω (the update moved through M).
    const Eigen::Matrix3d inverse_left = so3_inverse_left_jacobian(e.head<3>());
    const Eigen::Matrix3d minus_t_error = -skew_symmetric(error.translation());
    Eigen::Matrix<double, 6, 6> d_e_d_b;
    d_e_d_b << inverse_left, Eigen::Matrix3d::Zero(), minus_t_error, Eigen::Matrix3d::Identity();
    const Eigen::Matrix3d R_M = relative.rotation();
    Eigen::Matrix<double, 6, 6> d_update_d_a;
    d_update_d_a << -R_M, Eigen::Matrix3d::Zero(), -skew_symmetric(relative.translation()) * R_M,
        -R_M;
    write_jacobian(sqrt_information_ * d_e_d_b * d_update_d_a, jacobians[0]);
    write_jacobian(sqrt_information_ * d_e_d_b, jacobians[1]);
    return true;
  }

 private:
  static Pose pose_of(const double* parameters) {
    PoseParameters pose;
    std::copy(parameters, parameters + PoseParameters::kAmbientSize, pose.values.begin());
    return pose.to_pose();
  }

  static void write_jacobian(const Eigen::Matrix<double, 6, 6>& tangent, double* out) {
    if (out == nullptr) return;
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> jacobian(out);
    jacobian.leftCols<6>() = tangent;
    jacobian.col(6).setZero();
  }

  Pose T_a_b_measured_;  // Z⁻¹
  Eigen::Matrix<double, 6, 6> sqrt_information_;
};

}  // namespace pspslam
