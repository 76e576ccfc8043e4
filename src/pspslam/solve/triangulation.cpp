#include "pspslam/solve/triangulation.h"

#include <Eigen/SVD>

namespace pspslam {

Eigen::Vector3d triangulate_dlt(const Eigen::Vector2d& x1, const Eigen::Matrix<double, 3, 4>& P1,
                                const Eigen::Vector2d& x2, const Eigen::Matrix<double, 3, 4>& P2) {
  Eigen::Matrix4d A;
  A.row(0) = x1.x() * P1.row(2) - P1.row(0);
  A.row(1) = x1.y() * P1.row(2) - P1.row(1);
  A.row(2) = x2.x() * P2.row(2) - P2.row(0);
  A.row(3) = x2.y() * P2.row(2) - P2.row(1);
  const Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  return h.head<3>() / h(3);
}

}  // namespace pspslam
