#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

#include "pspslam/eval/ate.h"

namespace pspslam {

// A 2-D line chart, drawn identically to PNG (OpenCV) and SVG (hand-written text).
struct PlotSeries {
  std::string label;
  std::vector<Eigen::Vector2d> points;
  unsigned char red = 0, green = 0, blue = 0;
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
  // One metre is as long on both axes (trajectory views); otherwise each axis fills the frame.
  bool equal_aspect = false;
  int width = 900;
  int height = 700;
};

// Errors: "<file>: cannot write plot".
void write_plot_png(const LinePlot& plot, const std::filesystem::path& file);
void write_plot_svg(const LinePlot& plot, const std::filesystem::path& file);
std::string plot_to_svg(const LinePlot& plot);

struct AtePlotFiles {
  std::filesystem::path trajectory_png, trajectory_svg;
  std::filesystem::path error_png, error_svg;
};

// The two ground-truth axes of largest extent, in axis order (0 = x, 1 = y, 2 = z). Ground truth
// from a hand-held or mobile camera mostly moves in a plane; plotting that plane is the honest
// top view whatever the mocap's up axis is.
std::pair<int, int> plane_of_largest_extent(const std::vector<Eigen::Vector3d>& points);

// Writes into `dir` (created): trajectory_top_view.{png,svg} (aligned estimate vs ground truth
// in the plane of largest extent, labelled e.g. "x [m]" / "z [m]") and ate_over_time.{png,svg}
// (each associated pair's error against time since the first evaluated pose).
AtePlotFiles write_ate_plots(const AteResult& ate, const std::filesystem::path& dir,
                             const std::string& alignment_name = "SE(3)");

}  // namespace pspslam
