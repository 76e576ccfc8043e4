#include "pspslam/geometry/convex_hull.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pspslam {
namespace {

float cross(const Eigen::Vector2f& o, const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

float distance_to_segment(const Eigen::Vector2f& a, const Eigen::Vector2f& b,
                          const Eigen::Vector2f& p) {
  const Eigen::Vector2f ab = b - a;
  const float length2 = ab.squaredNorm();
  const float t = length2 > 0.0f ? std::clamp((p - a).dot(ab) / length2, 0.0f, 1.0f) : 0.0f;
  return (a + t * ab - p).norm();
}

}  // namespace

void convex_hull(std::span<const Eigen::Vector2f> points, std::vector<Eigen::Vector2f>& scratch,
                 std::vector<Eigen::Vector2f>& hull) {
  scratch.assign(points.begin(), points.end());
  std::sort(scratch.begin(), scratch.end(), [](const Eigen::Vector2f& a, const Eigen::Vector2f& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  scratch.erase(std::unique(scratch.begin(), scratch.end()), scratch.end());
  hull.clear();
  if (scratch.size() <= 2) {
    hull.assign(scratch.begin(), scratch.end());
    return;
  }
  hull.resize(2 * scratch.size());
  size_t k = 0;
  for (const Eigen::Vector2f& p : scratch) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], p) <= 0.0f) --k;
    hull[k++] = p;
  }
  const size_t lower_size = k + 1;
  for (auto it = scratch.rbegin() + 1; it != scratch.rend(); ++it) {  // upper chain
    while (k >= lower_size && cross(hull[k - 2], hull[k - 1], *it) <= 0.0f) --k;
    hull[k++] = *it;
  }
  hull.resize(k - 1);  // the last point repeats the first
}

float distance_to_convex_hull(std::span<const Eigen::Vector2f> hull, const Eigen::Vector2f& p) {
  if (hull.empty()) return std::numeric_limits<float>::infinity();
  if (hull.size() == 1) return (hull[0] - p).norm();
  if (hull.size() == 2) return distance_to_segment(hull[0], hull[1], p);
  bool inside = true;
  float best = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < hull.size(); ++i) {
    const Eigen::Vector2f& a = hull[i];
    const Eigen::Vector2f& b = hull[(i + 1) % hull.size()];
    if (cross(a, b, p) < 0.0f) inside = false;
    best = std::min(best, distance_to_segment(a, b, p));
  }
  return inside ? 0.0f : best;
}

}  // namespace pspslam
