#include "pspslam/optimize/pose_manifold.h"

#include <Eigen/Core>

namespace pspslam {

namespace {

using ConstQuaternionMap = Eigen::Map<const Eigen::Quaterniond>;
using ConstVector3Map = Eigen::Map<const Eigen::Vector3d>;

// Exp of so(3): rotation by |ω| about ω/|ω|; the first-order form near zero avoids 0/0.
Eigen::Quaterniond so3_exp(const Eigen::Vector3d& omega) {
  const double angle = omega.norm();
  if (angle < 1e-12) {
    return Eigen::Quaterniond(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z()).normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(angle, omega / angle));
}

Eigen::Vector3d so3_log(const Eigen::Quaterniond& rotation) {
  const Eigen::AngleAxisd angle_axis(rotation);
  return angle_axis.angle() * angle_axis.axis();
}

}  // namespace

PoseParameters PoseParameters::from_pose(const Pose& pose) {
  PoseParameters parameters;
  const Eigen::Quaterniond rotation(pose.linear());
  Eigen::Map<Eigen::Quaterniond> stored_rotation(parameters.values.data());
  Eigen::Map<Eigen::Vector3d> stored_translation(parameters.values.data() + 4);
  stored_rotation = rotation.normalized();
  stored_translation = pose.translation();
  return parameters;
}

Pose PoseParameters::to_pose() const {
  Pose pose = Pose::Identity();
  pose.linear() = ConstQuaternionMap(values.data()).normalized().toRotationMatrix();
  pose.translation() = ConstVector3Map(values.data() + 4);
  return pose;
}

bool PoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const ConstQuaternionMap rotation(x);
  const ConstVector3Map translation(x + 4);
  const Eigen::Quaterniond delta_rotation = so3_exp(ConstVector3Map(delta));
  Eigen::Map<Eigen::Quaterniond> new_rotation(x_plus_delta);
  Eigen::Map<Eigen::Vector3d> new_translation(x_plus_delta + 4);
  new_rotation = (delta_rotation * rotation).normalized();
  new_translation = delta_rotation * translation + ConstVector3Map(delta + 3);
  return true;
}

bool PoseManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> plus_jacobian(jacobian);
  plus_jacobian.setZero();
  plus_jacobian.topRows<6>().setIdentity();
  return true;
}

bool PoseManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                               const double* ambient_matrix,
                                               double* tangent_matrix) const {
  // Multiplying by [I₆; 0] keeps the first 6 columns.
  for (int row = 0; row < num_rows; ++row) {
    for (int col = 0; col < 6; ++col) tangent_matrix[row * 6 + col] = ambient_matrix[row * 7 + col];
  }
  return true;
}

bool PoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  // Inverse of Plus: D = T_y · T_x⁻¹ = (Exp(ω), v).
  const ConstQuaternionMap rotation_x(x);
  const ConstQuaternionMap rotation_y(y);
  const Eigen::Quaterniond delta_rotation = rotation_y * rotation_x.conjugate();
  Eigen::Map<Eigen::Vector3d> omega(y_minus_x);
  Eigen::Map<Eigen::Vector3d> v(y_minus_x + 3);
  omega = so3_log(delta_rotation);
  v = ConstVector3Map(y + 4) - delta_rotation * ConstVector3Map(x + 4);
  return true;
}

bool PoseManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> minus_jacobian(jacobian);
  minus_jacobian.setZero();
  minus_jacobian.leftCols<6>().setIdentity();
  return true;
}

}  // namespace pspslam
