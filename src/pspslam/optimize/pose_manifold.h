#pragma once

#include <ceres/manifold.h>

#include <array>

#include "pspslam/core/types.h"

namespace pspslam {

// A pose stored the way Ceres optimises it: quaternion (x y z w, Eigen's coefficient order)
// followed by the translation, i.e. 7 contiguous doubles for one parameter block.
struct PoseParameters {
  static constexpr int kAmbientSize = 7;
  static constexpr int kTangentSize = 6;

  std::array<double, kAmbientSize> values{};

  static PoseParameters from_pose(const Pose& pose);
  Pose to_pose() const;
  double* data() { return values.data(); }
  const double* data() const { return values.data(); }
};

// Left-multiplicative update of a pose stored as PoseParameters:
//   T ⊞ [ω; v] = (Exp(ω), v) · T,   i.e. R' = Exp(ω) R,  t' = Exp(ω) t + v.
// For a camera point p_c = R p_w + t this gives ∂p_c/∂[ω; v] = [-[p_c]×, I] at δ = 0, which is
// what the analytic residual Jacobians below rely on.
//
// The residuals hand Ceres their Jacobians already in this 6-dof tangent space, written into the
// first 6 of the 7 ambient columns (the 7th is zero). PlusJacobian is therefore [I₆; 0], so the
// product Ceres forms (ambient Jacobian × PlusJacobian) is exactly the tangent Jacobian, without
// differentiating through the quaternion. Consequence: the ambient Jacobians are not the true
// derivatives w.r.t. the quaternion, so ceres::GradientChecker must not be used on these costs.
class PoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return PoseParameters::kAmbientSize; }
  int TangentSize() const override { return PoseParameters::kTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace pspslam
