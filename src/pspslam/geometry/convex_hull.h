#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

namespace pspslam {

// Convex hull (Andrew's monotone chain) of `points`, written counter-clockwise into `hull`
// without repeating the first vertex. Duplicates and collinear points are dropped, so a single
// point gives one vertex and collinear points give the two extremes. `scratch` is reused storage.
void convex_hull(std::span<const Eigen::Vector2f> points, std::vector<Eigen::Vector2f>& scratch,
                 std::vector<Eigen::Vector2f>& hull);

// Distance from `p` to the convex polygon `hull` (counter-clockwise, as convex_hull() writes it);
// 0 inside. Works for degenerate hulls (one vertex = point distance, two = segment distance).
float distance_to_convex_hull(std::span<const Eigen::Vector2f> hull, const Eigen::Vector2f& p);

}  // namespace pspslam
