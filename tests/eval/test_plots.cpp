#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "pspslam/eval/plots.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

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

// A circle in the x-z plane; the estimate covers only its middle (times 12..17 of 10..19.9).
struct PartialRun {
  Trajectory gt, estimate;
  AteResult ate;
  RpeResult rpe;
  PartialRun() {
    for (int i = 0; i < 100; ++i) {
      const double angle = i * 0.0628;
      StampedPose p;
      p.timestamp = 10.0 + 0.1 * i;
      p.T_world_camera.translation() =
          Eigen::Vector3d(std::cos(angle), 0.01 * std::sin(5 * angle), std::sin(angle));
      p.T_world_camera.linear() = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).matrix();
      gt.push_back(p);
      if (i < 20 || i > 70) continue;
      // Error grows along the run: 1 mm per pose, in x.
      p.T_world_camera.translation() += Eigen::Vector3d(0.001 * (i - 20), 0.0, 0.0);
      estimate.push_back(p);
    }
    ate = compute_ate(gt, estimate);
    rpe = compute_rpe(gt, estimate);
  }
};

TEST(Plots, ErrorColourScaleEnds) {
  using Rgb = std::array<unsigned char, 3>;
  EXPECT_EQ(error_colour(2.0, 2.0, 10.0), (Rgb{68, 1, 84}));      // min: dark violet
  EXPECT_EQ(error_colour(10.0, 2.0, 10.0), (Rgb{253, 231, 37}));  // max: yellow
  EXPECT_EQ(error_colour(6.0, 2.0, 10.0), (Rgb{33, 145, 140}));   // middle anchor: teal
  EXPECT_EQ(error_colour(-5.0, 2.0, 10.0), (Rgb{68, 1, 84}));     // clamped below
  EXPECT_EQ(error_colour(50.0, 2.0, 10.0), (Rgb{253, 231, 37}));  // clamped above
  // Between anchors 0 and 1/4: halfway is the mean of (68,1,84) and (59,82,139).
  EXPECT_EQ(error_colour(3.0, 2.0, 10.0), (Rgb{64, 42, 112}));
  EXPECT_EQ(error_colour(5.0, 5.0, 5.0), (Rgb{68, 1, 84}));  // degenerate range: low end
  // Brightness rises monotonically with the error (readable in grey print too).
  double previous = -1.0;
  for (double v = 0.0; v <= 1.0; v += 0.05) {
    const Rgb c = error_colour(v, 0.0, 1.0);
    const double luma = 0.299 * c[0] + 0.587 * c[1] + 0.114 * c[2];
    EXPECT_GT(luma, previous) << v;
    previous = luma;
  }
}

TEST(Plots, GroundTruthSpanIsTheEvaluatedTimeRange) {
  const PartialRun run;
  const std::vector<size_t> span = evaluated_ground_truth_span(run.gt, run.ate);
  ASSERT_EQ(span.size(), 51u);  // ground-truth poses 20..70 of 0..99
  EXPECT_EQ(span.front(), 20u);
  EXPECT_EQ(span.back(), 70u);
  const LinePlot top = trajectory_top_view_plot(run.gt, run.ate, {"seq_a, mode geometry"});
  ASSERT_EQ(top.series.size(), 2u);
  const PlotSeries& gt = top.series[0];
  ASSERT_EQ(gt.points.size(), 51u);
  // x-z plane: the first and last points are the ground truth at times 12.0 and 17.0.
  EXPECT_NEAR(gt.points.front().x(), std::cos(20 * 0.0628), 1e-12);
  EXPECT_NEAR(gt.points.front().y(), std::sin(20 * 0.0628), 1e-12);
  EXPECT_NEAR(gt.points.back().x(), std::cos(70 * 0.0628), 1e-12);
  // Start / end markers sit on the span's ends.
  ASSERT_EQ(top.markers.size(), 2u);
  EXPECT_EQ(top.markers[0].label, "start");
  EXPECT_EQ(top.markers[0].point, gt.points.front());
  EXPECT_EQ(top.markers[1].label, "end");
  EXPECT_EQ(top.markers[1].point, gt.points.back());
  // The estimate carries its ATE in mm, and the colour bar spans exactly those values.
  const PlotSeries& est = top.series[1];
  ASSERT_EQ(est.values.size(), 51u);
  ASSERT_TRUE(top.colour_bar.has_value());
  EXPECT_EQ(top.colour_bar->label, "ATE [mm]");
  const auto [low, high] = std::minmax_element(est.values.begin(), est.values.end());
  EXPECT_DOUBLE_EQ(top.colour_bar->low, *low);
  EXPECT_DOUBLE_EQ(top.colour_bar->high, *high);
  EXPECT_NEAR(*high, 1000.0 * run.ate.error.max, 1e-9);
  EXPECT_GT(*high, 10.0);  // a 50 mm drift, less what the alignment absorbs
  // In the SVG, the ground-truth polyline has exactly the span's 51 points.
  const std::string svg = plot_to_svg(top);
  const size_t polyline = svg.find("<polyline");
  ASSERT_NE(polyline, std::string::npos);
  const std::string points = svg.substr(
      svg.find("points=\"", polyline) + 8,
      svg.find('"', svg.find("points=\"", polyline) + 8) - svg.find("points=\"", polyline) - 8);
  EXPECT_EQ(std::count(points.begin(), points.end(), ','), 51);
  EXPECT_EQ(svg.find("<polyline", polyline + 1), std::string::npos);  // the estimate is segments
  EXPECT_EQ(std::count(svg.begin(), svg.end(), '\n') > 50, true);
}

TEST(Plots, RollPitchYaw) {
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                .matrix();
  const Eigen::Vector3d rpy = roll_pitch_yaw_deg(R);
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  EXPECT_NEAR(rpy[0], 0.1 * kDeg, 1e-9);
  EXPECT_NEAR(rpy[1], -0.2 * kDeg, 1e-9);
  EXPECT_NEAR(rpy[2], 0.3 * kDeg, 1e-9);
}

TEST(Plots, WritesEveryFigureAsPngAndSvgWithTitlesAndLabels) {
  const auto dir = testing::make_temp_dir("plots");
  const PartialRun run;
  EvalPlotOptions options;
  options.run_name = "seq_a, mode geometry";
  const EvalPlotFiles files =
      write_eval_plots(run.gt, run.estimate, run.ate, run.rpe, dir / "plots", options);
  std::vector<std::string> names;
  for (const auto& f : files.files) names.push_back(f.filename().string());
  EXPECT_EQ(names, (std::vector<std::string>{
                       "trajectory_top_view.png", "trajectory_top_view.svg", "ate_over_time.png",
                       "ate_over_time.svg", "position_over_time.png", "position_over_time.svg",
                       "orientation_over_time.png", "orientation_over_time.svg",
                       "rpe_over_time.png", "rpe_over_time.svg"}));
  const cv::Mat trajectory = cv::imread((dir / "plots" / "trajectory_top_view.png").string());
  ASSERT_FALSE(trajectory.empty());
  EXPECT_EQ(trajectory.cols, 900);
  EXPECT_EQ(trajectory.rows, 700);
  // The colour bar's two ends are drawn (BGR of the scale's ends).
  cv::Mat violet, yellow;
  cv::inRange(trajectory, cv::Scalar(80, 0, 64), cv::Scalar(88, 5, 72), violet);
  cv::inRange(trajectory, cv::Scalar(30, 225, 245), cv::Scalar(45, 237, 255), yellow);
  EXPECT_GT(cv::countNonZero(violet), 50);
  EXPECT_GT(cv::countNonZero(yellow), 50);
  // Stacked panels: three of 300 px.
  const cv::Mat position = cv::imread((dir / "plots" / "position_over_time.png").string());
  EXPECT_EQ(position.rows, 900);
  EXPECT_EQ(cv::imread((dir / "plots" / "orientation_over_time.png").string()).rows, 900);
  EXPECT_EQ(cv::imread((dir / "plots" / "rpe_over_time.png").string()).rows, 500);
  EXPECT_EQ(cv::imread((dir / "plots" / "ate_over_time.png").string()).rows, 500);

  const std::string svg = read_all(dir / "plots" / "trajectory_top_view.svg");
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_NE(svg.find(">seq_a, mode geometry: top view (x-z plane), estimate after SE(3) "
                     "alignment, coloured by ATE</text>"),
            std::string::npos);
  EXPECT_NE(svg.find(">x [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">z [m]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">ATE [mm]</text>"), std::string::npos);
  EXPECT_NE(svg.find(">ground truth (evaluated span)</text>"), std::string::npos);
  EXPECT_NE(svg.find(">start</text>"), std::string::npos);
  EXPECT_NE(svg.find(">end</text>"), std::string::npos);
  const std::string position_svg = read_all(dir / "plots" / "position_over_time.svg");
  EXPECT_EQ(std::count(position_svg.begin(), position_svg.end(), '<') > 100, true);
  EXPECT_NE(position_svg.find("height=\"900\""), std::string::npos);
  for (const char* label : {">x [m]</text>", ">y [m]</text>", ">z [m]</text>",
                            ">seq_a, mode geometry: position x over time, estimate after SE(3) "
                            "alignment</text>",
                            ">time since first evaluated pose [s]</text>"}) {
    EXPECT_NE(position_svg.find(label), std::string::npos) << label;
  }
  const std::string orientation_svg = read_all(dir / "plots" / "orientation_over_time.svg");
  for (const char* label : {">roll [deg]</text>", ">pitch [deg]</text>", ">yaw [deg]</text>",
                            ">seq_a, mode geometry: yaw over time</text>"}) {
    EXPECT_NE(orientation_svg.find(label), std::string::npos) << label;
  }
  const std::string rpe_svg = read_all(dir / "plots" / "rpe_over_time.svg");
  EXPECT_NE(rpe_svg.find(">seq_a, mode geometry: translational RPE over 1 s: RMSE "),
            std::string::npos);
  EXPECT_NE(rpe_svg.find(">translation error [m]</text>"), std::string::npos);
  const std::string error_svg = read_all(dir / "plots" / "ate_over_time.svg");
  EXPECT_NE(error_svg.find(">position error [m]</text>"), std::string::npos);
  EXPECT_NE(error_svg.find("seq_a, mode geometry: ATE over time (SE(3) alignment): RMSE"),
            std::string::npos);
}

TEST(Plots, OrientationSeriesFollowTheRotations) {
  const PartialRun run;
  const auto panels = orientation_over_time_plots(run.gt, run.estimate, run.ate, run.rpe, {});
  ASSERT_EQ(panels.size(), 3u);
  // The camera turns about z by 0.0628 rad per pose: yaw rises 3.6 deg per pose, from 72 deg
  // to 252 deg without the wrap at 180 deg (unwrapped); roll and pitch stay 0. The estimate has
  // the same rotations turned by the alignment (which absorbs part of the drift: < 1.5 deg).
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  const PlotSeries& yaw_gt = panels[2].series[0];
  const PlotSeries& yaw_est = panels[2].series[1];
  ASSERT_EQ(yaw_gt.points.size(), 51u);
  EXPECT_NEAR(yaw_gt.points.front().y(), 20 * 0.0628 * kDeg, 1e-6);
  EXPECT_NEAR(yaw_gt.points.back().y(), 70 * 0.0628 * kDeg, 1e-6);
  EXPECT_NEAR(yaw_gt.points.front().x(), 0.0, 1e-12);
  EXPECT_NEAR(yaw_gt.points.back().x(), 5.0, 1e-9);
  for (size_t i = 0; i < yaw_gt.points.size(); ++i) {
    EXPECT_NEAR(yaw_est.points[i].y(), yaw_gt.points[i].y(), 1.5) << i;
    EXPECT_NEAR(panels[0].series[0].points[i].y(), 0.0, 1e-6) << i;
    EXPECT_NEAR(panels[1].series[1].points[i].y(), 0.0, 1.5) << i;
  }
  const Eigen::Vector3d first_est = roll_pitch_yaw_deg(
      run.ate.alignment.rotation * run.estimate.front().T_world_camera.rotation());
  EXPECT_NEAR(panels[1].series[1].points[0].y(), first_est[1], 1e-9);
  EXPECT_NEAR(yaw_est.points[0].y(), first_est[2], 1e-9);
  EXPECT_EQ(panels[0].title, "roll over time");  // no run name, no prefix
}

}  // namespace
}  // namespace pspslam
