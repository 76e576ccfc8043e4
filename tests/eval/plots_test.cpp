#include <gtest/gtest.h>

#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "pspslam/eval/plots.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

AteResult circle_result() {
  Trajectory gt, estimate;
  for (int i = 0; i < 100; ++i) {
    const double angle = i * 0.0628;
    StampedPose p;
    p.timestamp = 10.0 + 0.1 * i;
    // A circle in the x-z plane with small y wobble: the top view must pick x-z.
    p.T_world_camera.translation() =
        Eigen::Vector3d(std::cos(angle), 0.01 * std::sin(5 * angle), std::sin(angle));
    gt.push_back(p);
    p.T_world_camera.translation() += Eigen::Vector3d(0.02 * std::sin(i), 0.0, 0.0);
    estimate.push_back(p);
  }
  return compute_ate(gt, estimate);
}

std::string read_all(const std::filesystem::path& file) {
  std::ifstream stream(file);
  std::stringstream text;
  text << stream.rdbuf();
  return text.str();
}

TEST(Plots, PlaneOfLargestExtent) {
  const std::vector<Eigen::Vector3d> xz = {{0, 0, 0}, {2, 0.1, 1}};
  EXPECT_EQ(plane_of_largest_extent(xz), std::make_pair(0, 2));
  const std::vector<Eigen::Vector3d> yz = {{0, 0, 0}, {0.1, 2, 1}};
  EXPECT_EQ(plane_of_largest_extent(yz), std::make_pair(1, 2));
  const std::vector<Eigen::Vector3d> xy = {{0, 0, 0}, {1, 2, 0.1}};
  EXPECT_EQ(plane_of_largest_extent(xy), std::make_pair(0, 1));
}

TEST(Plots, WritesPngAndSvgWithLabelsAndLegend) {
  const auto dir = testing::make_temp_dir("plots");
  const AtePlotFiles files = write_ate_plots(circle_result(), dir / "plots");
  const cv::Mat trajectory = cv::imread(files.trajectory_png.string());
  ASSERT_FALSE(trajectory.empty());
  EXPECT_EQ(trajectory.cols, 900);
  EXPECT_EQ(trajectory.rows, 700);
  // Something other than white background was drawn in the estimate's colour (BGR 230,114,0).
  cv::Mat estimate_pixels;
  cv::inRange(trajectory, cv::Scalar(220, 100, 0), cv::Scalar(240, 130, 20), estimate_pixels);
  EXPECT_GT(cv::countNonZero(estimate_pixels), 500);
  const cv::Mat errors = cv::imread(files.error_png.string());
  ASSERT_FALSE(errors.empty());
  EXPECT_EQ(errors.rows, 500);

  const std::string svg = read_all(files.trajectory_svg);
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find(">x [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">z [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find("Top view (x-z plane, largest extent)"), std::string::npos);
  EXPECT_NE(svg.find(">ground truth</text>"), std::string::npos);
  EXPECT_NE(svg.find(">estimate (aligned)</text>"), std::string::npos);
  EXPECT_EQ(std::count(svg.begin(), svg.end(), '\n') > 20, true);
  const std::string error_svg = read_all(files.error_svg);
  EXPECT_NE(error_svg.find(">position error [m]</text>"), std::string::npos);
  EXPECT_NE(error_svg.find("ATE over time (SE(3) alignment): RMSE"), std::string::npos);
}

}  // namespace
}  // namespace pspslam
