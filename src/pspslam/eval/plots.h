#pragma once

#include <Eigen/Core>
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "pspslam/eval/ate.h"
#include "pspslam/eval/rpe.h"

namespace pspslam {

// RGB colour of `value` on the error colour scale (a perceptually ordered ramp from dark violet
// through teal to yellow, as viridis): `low` and below -> (68, 1, 84), `high` and above ->
// (253, 231, 37), linear between five anchors. A degenerate range (high <= low) gives the low end.
std::array<unsigned char, 3> error_colour(double value, double low, double high);

// A 2-D line chart, drawn identically to PNG (OpenCV) and SVG (hand-written text).
struct PlotSeries {
  std::string label;
  std::vector<Eigen::Vector2d> points;
  unsigned char red = 0, green = 0, blue = 0;  // line colour (legend colour when `values` is set)
  // When set (one per point), each segment is drawn in error_colour(mean of its two values) on
  // the plot's colour bar scale instead of the line colour.
  std::vector<double> values;
};

// A labelled marker (start / end of a trajectory), in the legend too.
struct PlotMarker {
  std::string label;
  Eigen::Vector2d point = Eigen::Vector2d::Zero();
  unsigned char red = 0, green = 0, blue = 0;
  bool square = false;  // square, else disc
};

// Vertical colour bar right of the frame: the error_colour scale from `low` to `high`, ticked and
// headed by `label` (e.g. "ATE [mm]").
struct ColourBar {
  std::string label;
  double low = 0.0;
  double high = 1.0;
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<PlotSeries> series;
  std::vector<PlotMarker> markers;
  std::optional<ColourBar> colour_bar;
  // One metre is as long on both axes (trajectory views); otherwise each axis fills the frame.
  bool equal_aspect = false;
  int width = 900;
  int height = 700;
};

// Errors: "<file>: cannot write plot".
void write_plot_png(const LinePlot& plot, const std::filesystem::path& file);
void write_plot_svg(const LinePlot& plot, const std::filesystem::path& file);
std::string plot_to_svg(const LinePlot& plot);
// Several plots stacked top to bottom in one picture (panels of one figure, e.g. x, y, z).
void write_stacked_plots_png(const std::vector<LinePlot>& panels,
                             const std::filesystem::path& file);
void write_stacked_plots_svg(const std::vector<LinePlot>& panels,
                             const std::filesystem::path& file);
std::string stacked_plots_to_svg(const std::vector<LinePlot>& panels);

// The two ground-truth axes of largest extent, in axis order (0 = x, 1 = y, 2 = z). Ground truth
// from a hand-held or mobile camera mostly moves in a plane; plotting that plane is the honest
// top view whatever the mocap's up axis is.
std::pair<int, int> plane_of_largest_extent(const std::vector<Eigen::Vector3d>& points);

// Indices (time order) of the ground-truth poses from the first to the last ground-truth pose
// that `ate` associated with an estimate: the stretch the evaluation covers. An estimate of a
// part of a sequence is compared with that part only, so the plots show only that part.
std::vector<size_t> evaluated_ground_truth_span(const Trajectory& ground_truth,
                                                const AteResult& ate);

// Roll, pitch, yaw in degrees (Z-Y-X convention: R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Vector3d roll_pitch_yaw_deg(const Eigen::Matrix3d& rotation);

struct EvalPlotOptions {
  // Leads every title, e.g. "bonn_crowd_dev, mode geometry" (empty: no prefix).
  std::string run_name;
  std::string alignment_name = "SE(3)";
  std::string rpe_delta = "1 s";  // shown in the RPE title
};

struct EvalPlotFiles {
  std::vector<std::filesystem::path> files;  // every file written, PNG then SVG per figure
};

// The plot panels, built without drawing (tests inspect the series):
//   top view of the evaluated ground-truth span and the aligned estimate coloured by its ATE
//   (colour bar in mm), start / end markers; the ATE over time.
LinePlot trajectory_top_view_plot(const Trajectory& ground_truth, const AteResult& ate,
                                  const EvalPlotOptions& options);
LinePlot ate_over_time_plot(const AteResult& ate, const EvalPlotOptions& options);
// x, y, z (m) and roll, pitch, yaw (deg) of the ground truth and the aligned estimate at the
// associated pairs, against time since the first evaluated pose.
std::vector<LinePlot> position_over_time_plots(const AteResult& ate,
                                               const EvalPlotOptions& options);
std::vector<LinePlot> orientation_over_time_plots(const Trajectory& ground_truth,
                                                  const Trajectory& estimate, const AteResult& ate,
                                                  const RpeResult& rpe,
                                                  const EvalPlotOptions& options);
// Translational RPE of each pair against the time of its first pose.
LinePlot rpe_over_time_plot(const AteResult& ate, const RpeResult& rpe,
                            const EvalPlotOptions& options);

// Writes into `dir` (created), each as .png and .svg: trajectory_top_view, ate_over_time,
// position_over_time, orientation_over_time, rpe_over_time.
EvalPlotFiles write_eval_plots(const Trajectory& ground_truth, const Trajectory& estimate,
                               const AteResult& ate, const RpeResult& rpe,
                               const std::filesystem::path& dir,
                               const EvalPlotOptions& options = {});

}  // namespace pspslam
