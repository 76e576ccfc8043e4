#pragma once

#include <Eigen/Core>

namespace pspslam {

// Linear (DLT) triangulation (Hartley & Zisserman 12.2) of one point from its image in two
// views: `x1`, `x2` in the coordinates the 3x4 projections `P1`, `P2` map to (pixels with
// K [R|t], normalised coordinates with [R|t]). Returns the inhomogeneous point; no check of
// depth or parallax (the callers do theirs).
Eigen::Vector3d triangulate_dlt(const Eigen::Vector2d& x1, const Eigen::Matrix<double, 3, 4>& P1,
                                const Eigen::Vector2d& x2, const Eigen::Matrix<double, 3, 4>& P2);

}  // namespace pspslam
