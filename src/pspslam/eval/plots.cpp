#include "pspslam/eval/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

std::string format_tick(double value, double step) {
  // Enough decimals to tell neighbouring ticks apart, no more.
  const int decimals = std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, std::abs(value) < 1e-12 ? 0.0 : value);
  return buffer;
}

// 1, 2 or 5 times a power of ten giving about `target` ticks over `span`.
double nice_step(double span, int target) {
  const double raw = span / target;
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double factor : {1.0, 2.0, 5.0}) {
    if (factor * power >= raw) return factor * power;
  }
  return 10.0 * power;
}

// Maps data coordinates into the plot frame of the image (y up in data, down in pixels).
struct Layout {
  double left = 90, right = 30, top = 50, bottom = 70;
  double x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  double x_step = 0.1, y_step = 0.1;
  int width = 0, height = 0;

  double frame_width() const { return width - left - right; }
  double frame_height() const { return height - top - bottom; }
  double px(double x) const { return left + (x - x_min) / (x_max - x_min) * frame_width(); }
  double py(double y) const { return top + (y_max - y) / (y_max - y_min) * frame_height(); }
};

Layout make_layout(const LinePlot& plot) {
  Layout layout;
  layout.width = plot.width;
  layout.height = plot.height;
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = -x_min;
  for (const PlotSeries& s : plot.series) {
    for (const Eigen::Vector2d& p : s.points) {
      x_min = std::min(x_min, p.x());
      x_max = std::max(x_max, p.x());
      y_min = std::min(y_min, p.y());
      y_max = std::max(y_max, p.y());
    }
  }
  if (!std::isfinite(x_min)) x_min = 0, x_max = 1, y_min = 0, y_max = 1;
  // Degenerate (constant) data still gets a visible range; then 5% padding on each side.
  if (x_max - x_min < 1e-9) x_min -= 0.5, x_max += 0.5;
  if (y_max - y_min < 1e-9) y_min -= 0.5, y_max += 0.5;
  const double x_pad = 0.05 * (x_max - x_min), y_pad = 0.05 * (y_max - y_min);
  x_min -= x_pad, x_max += x_pad, y_min -= y_pad, y_max += y_pad;
  if (plot.equal_aspect) {
    // Widen the tighter axis so that one data unit spans the same number of pixels on both.
    const double scale =
        std::min(layout.frame_width() / (x_max - x_min), layout.frame_height() / (y_max - y_min));
    const double x_center = 0.5 * (x_min + x_max), y_center = 0.5 * (y_min + y_max);
    const double x_half = 0.5 * layout.frame_width() / scale;
    const double y_half = 0.5 * layout.frame_height() / scale;
    x_min = x_center - x_half, x_max = x_center + x_half;
    y_min = y_center - y_half, y_max = y_center + y_half;
  }
  layout.x_min = x_min, layout.x_max = x_max, layout.y_min = y_min, layout.y_max = y_max;
  layout.x_step = nice_step(x_max - x_min, 8);
  layout.y_step = nice_step(y_max - y_min, 8);
  return layout;
}

std::vector<double> ticks(double low, double high, double step) {
  std::vector<double> values;
  for (double v = std::ceil(low / step) * step; v <= high + 1e-9 * step; v += step) {
    values.push_back(v);
  }
  return values;
}

std::string escape_xml(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
        break;
    }
  }
  return out;
}

std::string svg_colour(const PlotSeries& s) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "#%02x%02x%02x", s.red, s.green, s.blue);
  return buffer;
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", value);
  return buffer;
}

}  // namespace

std::string plot_to_svg(const LinePlot& plot) {
  const Layout L = make_layout(plot);
  std::string svg;
  svg += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  svg += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(plot.width) +
         "\" height=\"" + std::to_string(plot.height) + "\" viewBox=\"0 0 " +
         std::to_string(plot.width) + " " + std::to_string(plot.height) +
         "\" font-family=\"sans-serif\" font-size=\"13\">\n";
  svg += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  // Grid and tick labels.
  for (const double x : ticks(L.x_min, L.x_max, L.x_step)) {
    svg += "<line x1=\"" + number(L.px(x)) + "\" y1=\"" + number(L.top) + "\" x2=\"" +
           number(L.px(x)) + "\" y2=\"" + number(L.top + L.frame_height()) +
           "\" stroke=\"#dddddd\"/>\n";
    svg += "<text x=\"" + number(L.px(x)) + "\" y=\"" + number(L.top + L.frame_height() + 18) +
           "\" text-anchor=\"middle\">" + format_tick(x, L.x_step) + "</text>\n";
  }
  for (const double y : ticks(L.y_min, L.y_max, L.y_step)) {
    svg += "<line x1=\"" + number(L.left) + "\" y1=\"" + number(L.py(y)) + "\" x2=\"" +
           number(L.left + L.frame_width()) + "\" y2=\"" + number(L.py(y)) +
           "\" stroke=\"#dddddd\"/>\n";
    svg += "<text x=\"" + number(L.left - 6) + "\" y=\"" + number(L.py(y) + 4) +
           "\" text-anchor=\"end\">" + format_tick(y, L.y_step) + "</text>\n";
  }
  svg += "<rect x=\"" + number(L.left) + "\" y=\"" + number(L.top) + "\" width=\"" +
         number(L.frame_width()) + "\" height=\"" + number(L.frame_height()) +
         "\" fill=\"none\" stroke=\"black\"/>\n";
  for (const PlotSeries& s : plot.series) {
    if (s.points.empty()) continue;
    svg +=
        "<polyline fill=\"none\" stroke=\"" + svg_colour(s) + "\" stroke-width=\"1.5\" points=\"";
    for (const Eigen::Vector2d& p : s.points)
      svg += number(L.px(p.x())) + "," + number(L.py(p.y())) + " ";
    svg += "\"/>\n";
  }
  // Title, axis labels, legend.
  svg += "<text x=\"" + number(plot.width / 2.0) + "\" y=\"28\" text-anchor=\"middle\" " +
         "font-size=\"16\">" + escape_xml(plot.title) + "</text>\n";
  svg += "<text x=\"" + number(L.left + L.frame_width() / 2) + "\" y=\"" +
         number(plot.height - 20.0) + "\" text-anchor=\"middle\">" + escape_xml(plot.x_label) +
         "</text>\n";
  svg += "<text transform=\"translate(24," + number(L.top + L.frame_height() / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">" + escape_xml(plot.y_label) + "</text>\n";
  // Legend box in the top-right corner; text width estimated at 7.5 px per character (13 px font).
  size_t longest = 0;
  for (const PlotSeries& s : plot.series) longest = std::max(longest, s.label.size());
  const double box_width = 7.5 * static_cast<double>(longest) + 56;
  const double box_height = 20.0 * static_cast<double>(plot.series.size()) + 8;
  const double box_x = L.left + L.frame_width() - box_width - 8, box_y = L.top + 8;
  svg += "<rect x=\"" + number(box_x) + "\" y=\"" + number(box_y) + "\" width=\"" +
         number(box_width) + "\" height=\"" + number(box_height) +
         "\" fill=\"white\" stroke=\"#969696\"/>\n";
  double legend_y = box_y + 20;
  for (const PlotSeries& s : plot.series) {
    const double x = box_x + 8;
    svg += "<line x1=\"" + number(x) + "\" y1=\"" + number(legend_y - 4) + "\" x2=\"" +
           number(x + 30) + "\" y2=\"" + number(legend_y - 4) + "\" stroke=\"" + svg_colour(s) +
           "\" stroke-width=\"3\"/>\n";
    svg += "<text x=\"" + number(x + 38) + "\" y=\"" + number(legend_y) + "\">" +
           escape_xml(s.label) + "</text>\n";
    legend_y += 20;
  }
  svg += "</svg>\n";
  return svg;
}

void write_plot_svg(const LinePlot& plot, const std::filesystem::path& file) {
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write plot");
  stream << plot_to_svg(plot);
  if (!stream) throw Error(file.string() + ": cannot write plot");
}

void write_plot_png(const LinePlot& plot, const std::filesystem::path& file) {
  const Layout L = make_layout(plot);
  cv::Mat image(plot.height, plot.width, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto at = [&](double x, double y) {
    return cv::Point(static_cast<int>(std::lround(L.px(x))),
                     static_cast<int>(std::lround(L.py(y))));
  };
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const cv::Scalar black(0, 0, 0), grid(221, 221, 221);
  const auto put_text = [&](const std::string& text, cv::Point anchor, double size, int align) {
    // align: -1 left, 0 centred, 1 right of the anchor.
    int baseline = 0;
    const cv::Size extent = cv::getTextSize(text, font, size, 1, &baseline);
    anchor.x -= align == 0 ? extent.width / 2 : (align > 0 ? extent.width : 0);
    cv::putText(image, text, anchor, font, size, black, 1, cv::LINE_AA);
  };
  const int frame_left = static_cast<int>(L.left), frame_top = static_cast<int>(L.top);
  const int frame_right = static_cast<int>(L.left + L.frame_width());
  const int frame_bottom = static_cast<int>(L.top + L.frame_height());
  for (const double x : ticks(L.x_min, L.x_max, L.x_step)) {
    const int px = at(x, 0).x;
    cv::line(image, {px, frame_top}, {px, frame_bottom}, grid, 1);
    put_text(format_tick(x, L.x_step), {px, frame_bottom + 20}, 0.45, 0);
  }
  for (const double y : ticks(L.y_min, L.y_max, L.y_step)) {
    const int py = at(0, y).y;
    cv::line(image, {frame_left, py}, {frame_right, py}, grid, 1);
    put_text(format_tick(y, L.y_step), {frame_left - 6, py + 5}, 0.45, 1);
  }
  cv::rectangle(image, {frame_left, frame_top}, {frame_right, frame_bottom}, black, 1);
  for (const PlotSeries& s : plot.series) {
    std::vector<cv::Point> polyline;
    polyline.reserve(s.points.size());
    for (const Eigen::Vector2d& p : s.points) polyline.push_back(at(p.x(), p.y()));
    const cv::Scalar colour(s.blue, s.green, s.red);
    if (polyline.size() == 1) cv::circle(image, polyline[0], 2, colour, cv::FILLED, cv::LINE_AA);
    cv::polylines(image, polyline, false, colour, 2, cv::LINE_AA);
  }
  put_text(plot.title, {plot.width / 2, 30}, 0.6, 0);
  put_text(plot.x_label, {(frame_left + frame_right) / 2, plot.height - 18}, 0.5, 0);
  // OpenCV has no rotated text: draw the y label horizontally, then rotate that strip.
  {
    int baseline = 0;
    const cv::Size extent = cv::getTextSize(plot.y_label, font, 0.5, 1, &baseline);
    cv::Mat strip(extent.height + baseline + 6, extent.width + 6, CV_8UC3,
                  cv::Scalar(255, 255, 255));
    cv::putText(strip, plot.y_label, {3, extent.height + 3}, font, 0.5, black, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(strip, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x0 = 8;
    const int y0 = std::max(0, (frame_top + frame_bottom) / 2 - rotated.rows / 2);
    if (x0 + rotated.cols <= image.cols && y0 + rotated.rows <= image.rows) {
      rotated.copyTo(image(cv::Rect(x0, y0, rotated.cols, rotated.rows)));
    }
  }
  // Legend: a white box in the top-right corner, sized to its longest label, drawn over the data.
  int label_width = 0;
  for (const PlotSeries& s : plot.series) {
    int baseline = 0;
    label_width = std::max(label_width, cv::getTextSize(s.label, font, 0.45, 1, &baseline).width);
  }
  const int box_width = label_width + 56;
  const int box_height = 20 * static_cast<int>(plot.series.size()) + 8;
  const cv::Rect box(frame_right - box_width - 8, frame_top + 8, box_width, box_height);
  cv::rectangle(image, box, cv::Scalar(255, 255, 255), cv::FILLED);
  cv::rectangle(image, box, cv::Scalar(150, 150, 150), 1);
  int legend_y = box.y + 20;
  for (const PlotSeries& s : plot.series) {
    const int x = box.x + 8;
    cv::line(image, {x, legend_y - 4}, {x + 30, legend_y - 4}, cv::Scalar(s.blue, s.green, s.red),
             3, cv::LINE_AA);
    put_text(s.label, {x + 38, legend_y}, 0.45, -1);
    legend_y += 20;
  }
  bool written = false;
  try {
    written = cv::imwrite(file.string(), image);
  } catch (const cv::Exception&) {
  }
  if (!written) throw Error(file.string() + ": cannot write plot");
}

std::pair<int, int> plane_of_largest_extent(const std::vector<Eigen::Vector3d>& points) {
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  if (!points.empty()) {
    Eigen::Vector3d low = points.front(), high = points.front();
    for (const Eigen::Vector3d& p : points) {
      low = low.cwiseMin(p);
      high = high.cwiseMax(p);
    }
    extent = high - low;
  }
  int smallest = 0;
  for (int axis = 1; axis < 3; ++axis) {
    if (extent[axis] < extent[smallest]) smallest = axis;
  }
  const int first = smallest == 0 ? 1 : 0;
  const int second = smallest == 2 ? 1 : 2;
  return {first, second};
}

AtePlotFiles write_ate_plots(const AteResult& ate, const std::filesystem::path& dir,
                             const std::string& alignment_name) {
  std::error_code failure;
  std::filesystem::create_directories(dir, failure);
  if (failure) throw Error(dir.string() + ": cannot create plot directory: " + failure.message());
  constexpr const char* kAxisNames[3] = {"x", "y", "z"};
  const auto [a, b] = plane_of_largest_extent(ate.gt_all);

  LinePlot trajectory;
  trajectory.title = std::string("Top view (") + kAxisNames[a] + "-" + kAxisNames[b] +
                     " plane, largest extent): estimate after " + alignment_name +
                     " alignment vs ground truth";
  trajectory.x_label = std::string(kAxisNames[a]) + " [m]";
  trajectory.y_label = std::string(kAxisNames[b]) + " [m]";
  trajectory.equal_aspect = true;
  PlotSeries gt{"ground truth", {}, 40, 40, 40};
  for (const Eigen::Vector3d& p : ate.gt_all) gt.points.emplace_back(p[a], p[b]);
  PlotSeries est{"estimate (aligned)", {}, 0, 114, 230};
  for (const Eigen::Vector3d& p : ate.est_aligned_all) est.points.emplace_back(p[a], p[b]);
  trajectory.series = {gt, est};

  LinePlot errors;
  char title[128];
  std::snprintf(title, sizeof(title), "ATE over time (%s alignment): RMSE %.4f m, %zu poses",
                alignment_name.c_str(), ate.error.rmse, ate.error.count);
  errors.title = title;
  errors.x_label = "time since first evaluated pose [s]";
  errors.y_label = "position error [m]";
  errors.height = 500;
  PlotSeries error_series{"|estimate - ground truth|", {}, 214, 39, 40};
  const double t0 = ate.pairs.empty() ? 0.0 : ate.pairs.front().gt_timestamp;
  for (const AtePair& p : ate.pairs) error_series.points.emplace_back(p.gt_timestamp - t0, p.error);
  errors.series = {error_series};

  AtePlotFiles files;
  files.trajectory_png = dir / "trajectory_top_view.png";
  files.trajectory_svg = dir / "trajectory_top_view.svg";
  files.error_png = dir / "ate_over_time.png";
  files.error_svg = dir / "ate_over_time.svg";
  write_plot_png(trajectory, files.trajectory_png);
  write_plot_svg(trajectory, files.trajectory_svg);
  write_plot_png(errors, files.error_png);
  write_plot_svg(errors, files.error_svg);
  return files;
}

}  // namespace pspslam
