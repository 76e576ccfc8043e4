#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "pspslam/geometry/reference_selection.h"

namespace pspslam {
namespace {

// A camera at the origin turned about the vertical axis by `yaw_deg`, looking at a wall 3 m away
// (every view's depth image is the constant 3 m: only which pixels project inside matters here).
Pose turned(double yaw_deg) {
  Pose T = Pose::Identity();
  T.linear() =
      Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return T;
}

std::vector<CandidatePoint> grid_candidates(double depth) {
  std::vector<CandidatePoint> points;
  for (int v = 20; v < 480; v += 40)
    for (int u = 10; u < 640; u += 20) points.push_back({Eigen::Vector2d(u, v), depth});
  return points;
}

TEST(ReferenceSelection, CoversTheStripThatTheMostOverlappingViewsAllMiss) {
  const PinholeCamera camera;  // 640x480, fx 525
  const cv::Mat wall(480, 640, CV_32FC1, cv::Scalar(3.0f));
  // Newest first: five views turned 8-12 deg one way (each overlaps the current view most), then
  // an older one turned 10 deg the other way (the only one that sees the opposite image edge).
  std::vector<DepthView> pool;
  for (double yaw : {8.0, 9.0, 10.0, 11.0, 12.0, -10.0}) pool.push_back({turned(yaw), wall});
  const std::vector<CandidatePoint> points = grid_candidates(3.0);
  ReferenceSelector::Params params;
  params.point_stride = 1;
  ReferenceSelector selector(camera, params);
  const std::vector<int>& chosen = selector.select(turned(0.0), points, pool);
  ASSERT_EQ(chosen.size(), 5u);
  EXPECT_EQ(chosen.front(), 0) << "first pick = the most overlapping view (DynaSLAM's rule)";
  EXPECT_NE(std::find(chosen.begin(), chosen.end(), 5), chosen.end())
      << "the view covering the other image edge must be picked";

  // Every candidate is seen by at least one chosen view.
  int unseen = 0;
  for (const CandidatePoint& point : points) {
    bool seen = false;
    for (int v : chosen) {
      const Eigen::Vector3d p =
          pool[v].T_world_camera.inverse() * camera.unproject(point.pixel, 3.0);
      const Eigen::Vector2d pixel = camera.project(p);
      seen = seen ||
             (p.z() > 0 && pixel.x() >= 4 && pixel.y() >= 4 && pixel.x() < 636 && pixel.y() < 476);
    }
    unseen += !seen;
  }
  EXPECT_EQ(unseen, 0);
}

TEST(ReferenceSelection, SmallPoolIsPassedThroughAndOlderViewsWinNearTies) {
  const PinholeCamera camera;
  const cv::Mat wall(480, 640, CV_32FC1, cv::Scalar(3.0f));
  const std::vector<CandidatePoint> points = grid_candidates(3.0);
  std::vector<DepthView> pool = {
      {turned(1.0), wall}, {turned(2.0), wall}, {turned(3.0), cv::Mat()}};
  ReferenceSelector selector(camera, {});
  // Not more views than wanted: all views with a depth image, in pool order.
  EXPECT_EQ(selector.select(turned(0.0), points, pool), (std::vector<int>{0, 1}));

  // Views turned further and further see fewer candidates. With a gain share of 1 the first pick
  // is the most overlapping view; with 0.85 an older view whose gain is within 15 % of it.
  pool.clear();
  for (double yaw : {0.5, 4.0, 8.0, 12.0, 16.0, 20.0, 30.0}) pool.push_back({turned(yaw), wall});
  ReferenceSelector::Params params;
  params.point_stride = 1;
  params.max_views = 1;
  EXPECT_EQ(ReferenceSelector(camera, params).select(turned(0.0), points, pool).front(), 0);
  params.older_view_gain_share = 0.85;
  const int older = ReferenceSelector(camera, params).select(turned(0.0), points, pool).front();
  EXPECT_GT(older, 0);
  EXPECT_LT(older, 4) << "views turned by 12 deg or more see too little to be picked";
}

}  // namespace
}  // namespace pspslam
