#include "pspslam/eval/plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <utility>

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
  // Room for the colour bar and its tick labels right of the frame.
  if (plot.colour_bar) layout.right = 130;
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = -x_min;
  const auto extend = [&](const Eigen::Vector2d& p) {
    x_min = std::min(x_min, p.x());
    x_max = std::max(x_max, p.x());
    y_min = std::min(y_min, p.y());
    y_max = std::max(y_max, p.y());
  };
  for (const PlotSeries& s : plot.series) {
    for (const Eigen::Vector2d& p : s.points) extend(p);
  }
  for (const PlotMarker& m : plot.markers) extend(m.point);
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

std::string svg_colour(unsigned char red, unsigned char green, unsigned char blue) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "#%02x%02x%02x", red, green, blue);
  return buffer;
}

std::string svg_colour(const std::array<unsigned char, 3>& rgb) {
  return svg_colour(rgb[0], rgb[1], rgb[2]);
}

std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.2f", value);
  return buffer;
}

// Colour bar ticks: the scale's range widened when degenerate, so a constant error still shows.
std::pair<double, double> colour_bar_range(const ColourBar& bar) {
  return {bar.low, bar.high > bar.low ? bar.high : bar.low + 1.0};
}

std::string svg_grid(const Layout& L) {
  std::string svg;
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
  return svg;
}

std::string svg_series(const Layout& L, const PlotSeries& s, double scale_low, double scale_high) {
  if (s.points.empty()) return {};
  std::string svg;
  if (s.values.size() == s.points.size()) {
    // One segment per pair of points, each in the colour of its mean value.
    for (size_t i = 1; i < s.points.size(); ++i) {
      const double value = 0.5 * (s.values[i - 1] + s.values[i]);
      svg += "<line x1=\"" + number(L.px(s.points[i - 1].x())) + "\" y1=\"" +
             number(L.py(s.points[i - 1].y())) + "\" x2=\"" + number(L.px(s.points[i].x())) +
             "\" y2=\"" + number(L.py(s.points[i].y())) + "\" stroke=\"" +
             svg_colour(error_colour(value, scale_low, scale_high)) +
             "\" stroke-width=\"2.5\" stroke-linecap=\"round\"/>\n";
    }
    return svg;
  }
  svg += "<polyline fill=\"none\" stroke=\"" + svg_colour(s.red, s.green, s.blue) +
         "\" stroke-width=\"1.5\" points=\"";
  for (const Eigen::Vector2d& p : s.points)
    svg += number(L.px(p.x())) + "," + number(L.py(p.y())) + " ";
  svg += "\"/>\n";
  return svg;
}

std::string svg_marker(const PlotMarker& m, double x, double y) {
  const std::string colour = svg_colour(m.red, m.green, m.blue);
  if (m.square) {
    return "<rect x=\"" + number(x - 6) + "\" y=\"" + number(y - 6) +
           "\" width=\"12\" height=\"12\" fill=\"" + colour + "\" stroke=\"black\"/>\n";
  }
  return "<circle cx=\"" + number(x) + "\" cy=\"" + number(y) + "\" r=\"6\" fill=\"" + colour +
         "\" stroke=\"black\"/>\n";
}

std::string svg_colour_bar(const Layout& L, const ColourBar& bar) {
  const auto [scale_low, scale_high] = colour_bar_range(bar);
  const double bar_x = L.left + L.frame_width() + 24, bar_top = L.top + 24;
  const double bar_bottom = L.top + L.frame_height(), bar_height = bar_bottom - bar_top;
  constexpr int kSteps = 64;
  std::string svg;
  for (int i = 0; i < kSteps; ++i) {
    const double value = scale_low + (scale_high - scale_low) * (i + 0.5) / kSteps;
    svg += "<rect x=\"" + number(bar_x) + "\" y=\"" +
           number(bar_bottom - bar_height * (i + 1) / kSteps) + "\" width=\"18\" height=\"" +
           number(bar_height / kSteps + 0.5) + "\" fill=\"" +
           svg_colour(error_colour(value, scale_low, scale_high)) + "\"/>\n";
  }
  svg += "<rect x=\"" + number(bar_x) + "\" y=\"" + number(bar_top) + "\" width=\"18\" height=\"" +
         number(bar_height) + "\" fill=\"none\" stroke=\"black\"/>\n";
  const double step = nice_step(scale_high - scale_low, 5);
  for (const double v : ticks(scale_low, scale_high, step)) {
    const double y = bar_bottom - (v - scale_low) / (scale_high - scale_low) * bar_height;
    svg += "<text x=\"" + number(bar_x + 24) + "\" y=\"" + number(y + 4) + "\">" +
           format_tick(v, step) + "</text>\n";
  }
  svg += "<text x=\"" + number(bar_x + 9) + "\" y=\"" + number(bar_top - 8) +
         "\" text-anchor=\"middle\">" + escape_xml(bar.label) + "</text>\n";
  return svg;
}

// Title and axis labels.
std::string svg_labels(const Layout& L, const LinePlot& plot) {
  std::string svg;
  svg += "<text x=\"" + number(plot.width / 2.0) + "\" y=\"28\" text-anchor=\"middle\" " +
         "font-size=\"16\">" + escape_xml(plot.title) + "</text>\n";
  svg += "<text x=\"" + number(L.left + L.frame_width() / 2) + "\" y=\"" +
         number(plot.height - 20.0) + "\" text-anchor=\"middle\">" + escape_xml(plot.x_label) +
         "</text>\n";
  svg += "<text transform=\"translate(24," + number(L.top + L.frame_height() / 2) +
         ") rotate(-90)\" text-anchor=\"middle\">" + escape_xml(plot.y_label) + "</text>\n";
  return svg;
}

// Legend box in the top-right corner; text width estimated at 7.5 px per character (13 px font).
std::string svg_legend(const Layout& L, const LinePlot& plot) {
  size_t longest = 0;
  for (const PlotSeries& s : plot.series) longest = std::max(longest, s.label.size());
  for (const PlotMarker& m : plot.markers) longest = std::max(longest, m.label.size());
  const size_t rows = plot.series.size() + plot.markers.size();
  const double box_width = 7.5 * static_cast<double>(longest) + 56;
  const double box_height = 20.0 * static_cast<double>(rows) + 8;
  const double box_x = L.left + L.frame_width() - box_width - 8, box_y = L.top + 8;
  std::string svg;
  svg += "<rect x=\"" + number(box_x) + "\" y=\"" + number(box_y) + "\" width=\"" +
         number(box_width) + "\" height=\"" + number(box_height) +
         "\" fill=\"white\" stroke=\"#969696\"/>\n";
  double legend_y = box_y + 20;
  for (const PlotSeries& s : plot.series) {
    const double x = box_x + 8;
    svg += "<line x1=\"" + number(x) + "\" y1=\"" + number(legend_y - 4) + "\" x2=\"" +
           number(x + 30) + "\" y2=\"" + number(legend_y - 4) + "\" stroke=\"" +
           svg_colour(s.red, s.green, s.blue) + "\" stroke-width=\"3\"/>\n";
    svg += "<text x=\"" + number(x + 38) + "\" y=\"" + number(legend_y) + "\">" +
           escape_xml(s.label) + "</text>\n";
    legend_y += 20;
  }
  for (const PlotMarker& m : plot.markers) {
    const double x = box_x + 8;
    svg += svg_marker(m, x + 15, legend_y - 4);
    svg += "<text x=\"" + number(x + 38) + "\" y=\"" + number(legend_y) + "\">" +
           escape_xml(m.label) + "</text>\n";
    legend_y += 20;
  }
  return svg;
}

// Draws the whole plot as SVG elements in plot coordinates (no document header).
std::string svg_body(const LinePlot& plot) {
  const Layout L = make_layout(plot);
  std::string svg;
  svg += "<rect width=\"" + std::to_string(plot.width) + "\" height=\"" +
         std::to_string(plot.height) + "\" fill=\"white\"/>\n";
  // Grid and tick labels.
  svg += svg_grid(L);
  const auto [scale_low, scale_high] =
      plot.colour_bar ? colour_bar_range(*plot.colour_bar) : std::make_pair(0.0, 1.0);
  for (const PlotSeries& s : plot.series) svg += svg_series(L, s, scale_low, scale_high);
  for (const PlotMarker& m : plot.markers)
    svg += svg_marker(m, L.px(m.point.x()), L.py(m.point.y()));
  if (plot.colour_bar) svg += svg_colour_bar(L, *plot.colour_bar);
  // Title, axis labels, legend.
  svg += svg_labels(L, plot);
  svg += svg_legend(L, plot);
  return svg;
}

std::string svg_document(int width, int height, const std::string& body) {
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
         std::to_string(width) + "\" height=\"" + std::to_string(height) + "\" viewBox=\"0 0 " +
         std::to_string(width) + " " + std::to_string(height) +
         "\" font-family=\"sans-serif\" font-size=\"13\">\n" + body + "</svg>\n";
}

void write_text(const std::string& text, const std::filesystem::path& file) {
  std::ofstream stream(file);
  if (!stream) throw Error(file.string() + ": cannot write plot");
  stream << text;
  if (!stream) throw Error(file.string() + ": cannot write plot");
}

void write_image(const cv::Mat& image, const std::filesystem::path& file) {
  bool written = false;
  try {
    written = cv::imwrite(file.string(), image);
  } catch (const cv::Exception&) {
  }
  if (!written) throw Error(file.string() + ": cannot write plot");
}

cv::Scalar bgr(unsigned char red, unsigned char green, unsigned char blue) {
  return cv::Scalar(blue, green, red);
}

cv::Scalar bgr(const std::array<unsigned char, 3>& rgb) { return bgr(rgb[0], rgb[1], rgb[2]); }

// A LinePlot drawn into a picture, step by step.
class PngPlot {
 public:
  explicit PngPlot(const LinePlot& plot)
      : plot_(plot),
        L_(make_layout(plot)),
        image_(plot.height, plot.width, CV_8UC3, cv::Scalar(255, 255, 255)),
        frame_left_(static_cast<int>(L_.left)),
        frame_top_(static_cast<int>(L_.top)),
        frame_right_(static_cast<int>(L_.left + L_.frame_width())),
        frame_bottom_(static_cast<int>(L_.top + L_.frame_height())) {}

  cv::Mat draw() {
    draw_grid();
    const auto [scale_low, scale_high] =
        plot_.colour_bar ? colour_bar_range(*plot_.colour_bar) : std::make_pair(0.0, 1.0);
    for (const PlotSeries& s : plot_.series) draw_series(s, scale_low, scale_high);
    for (const PlotMarker& m : plot_.markers) draw_marker(m, at(m.point.x(), m.point.y()));
    if (plot_.colour_bar) draw_colour_bar(*plot_.colour_bar);
    draw_title();
    put_text(plot_.x_label, {(frame_left_ + frame_right_) / 2, plot_.height - 18}, 0.5, 0);
    draw_y_label();
    draw_legend();
    return image_;
  }

 private:
  static constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

  cv::Point at(double x, double y) const {
    return cv::Point(static_cast<int>(std::lround(L_.px(x))),
                     static_cast<int>(std::lround(L_.py(y))));
  }

  // align: -1 left, 0 centred, 1 right of the anchor.
  void put_text(const std::string& text, cv::Point anchor, double size, int align) {
    int baseline = 0;
    const cv::Size extent = cv::getTextSize(text, kFont, size, 1, &baseline);
    anchor.x -= align == 0 ? extent.width / 2 : (align > 0 ? extent.width : 0);
    cv::putText(image_, text, anchor, kFont, size, kBlack, 1, cv::LINE_AA);
  }

  void draw_grid() {
    const cv::Scalar grid(221, 221, 221);
    for (const double x : ticks(L_.x_min, L_.x_max, L_.x_step)) {
      const int px = at(x, 0).x;
      cv::line(image_, {px, frame_top_}, {px, frame_bottom_}, grid, 1);
      put_text(format_tick(x, L_.x_step), {px, frame_bottom_ + 20}, 0.45, 0);
    }
    for (const double y : ticks(L_.y_min, L_.y_max, L_.y_step)) {
      const int py = at(0, y).y;
      cv::line(image_, {frame_left_, py}, {frame_right_, py}, grid, 1);
      put_text(format_tick(y, L_.y_step), {frame_left_ - 6, py + 5}, 0.45, 1);
    }
    cv::rectangle(image_, {frame_left_, frame_top_}, {frame_right_, frame_bottom_}, kBlack, 1);
  }

  void draw_series(const PlotSeries& s, double scale_low, double scale_high) {
    std::vector<cv::Point> polyline;
    polyline.reserve(s.points.size());
    for (const Eigen::Vector2d& p : s.points) polyline.push_back(at(p.x(), p.y()));
    const cv::Scalar colour = bgr(s.red, s.green, s.blue);
    if (s.values.size() == s.points.size()) {
      for (size_t i = 1; i < polyline.size(); ++i) {
        const double value = 0.5 * (s.values[i - 1] + s.values[i]);
        cv::line(image_, polyline[i - 1], polyline[i],
                 bgr(error_colour(value, scale_low, scale_high)), 3, cv::LINE_AA);
      }
      return;
    }
    if (polyline.size() == 1) cv::circle(image_, polyline[0], 2, colour, cv::FILLED, cv::LINE_AA);
    cv::polylines(image_, polyline, false, colour, 2, cv::LINE_AA);
  }

  void draw_marker(const PlotMarker& m, cv::Point p) {
    if (m.square) {
      cv::rectangle(image_, {p.x - 6, p.y - 6}, {p.x + 6, p.y + 6}, bgr(m.red, m.green, m.blue),
                    cv::FILLED);
      cv::rectangle(image_, {p.x - 6, p.y - 6}, {p.x + 6, p.y + 6}, kBlack, 1);
    } else {
      cv::circle(image_, p, 6, bgr(m.red, m.green, m.blue), cv::FILLED, cv::LINE_AA);
      cv::circle(image_, p, 6, kBlack, 1, cv::LINE_AA);
    }
  }

  void draw_colour_bar(const ColourBar& bar) {
    const auto [scale_low, scale_high] = colour_bar_range(bar);
    const int bar_x = frame_right_ + 24, bar_top = frame_top_ + 24;
    const int bar_height = frame_bottom_ - bar_top;
    for (int row = 0; row < bar_height; ++row) {
      const double value = scale_low + (scale_high - scale_low) * (row + 0.5) / bar_height;
      cv::line(image_, {bar_x, frame_bottom_ - 1 - row}, {bar_x + 17, frame_bottom_ - 1 - row},
               bgr(error_colour(value, scale_low, scale_high)), 1);
    }
    cv::rectangle(image_, {bar_x, bar_top}, {bar_x + 18, frame_bottom_}, kBlack, 1);
    const double step = nice_step(scale_high - scale_low, 5);
    for (const double v : ticks(scale_low, scale_high, step)) {
      const int y =
          frame_bottom_ -
          static_cast<int>(std::lround((v - scale_low) / (scale_high - scale_low) * bar_height));
      cv::line(image_, {bar_x + 18, y}, {bar_x + 22, y}, kBlack, 1);
      put_text(format_tick(v, step), {bar_x + 25, y + 5}, 0.45, -1);
    }
    put_text(bar.label, {bar_x + 9, bar_top - 8}, 0.45, 0);
  }

  // The title shrinks to fit the picture's width (long sequence names).
  void draw_title() {
    double size = 0.6;
    int baseline = 0;
    while (size > 0.35 &&
           cv::getTextSize(plot_.title, kFont, size, 1, &baseline).width > plot_.width - 20) {
      size -= 0.05;
    }
    put_text(plot_.title, {plot_.width / 2, 30}, size, 0);
  }

  // OpenCV has no rotated text: draw the y label horizontally, then rotate that strip.
  void draw_y_label() {
    int baseline = 0;
    const cv::Size extent = cv::getTextSize(plot_.y_label, kFont, 0.5, 1, &baseline);
    cv::Mat strip(extent.height + baseline + 6, extent.width + 6, CV_8UC3,
                  cv::Scalar(255, 255, 255));
    cv::putText(strip, plot_.y_label, {3, extent.height + 3}, kFont, 0.5, kBlack, 1, cv::LINE_AA);
    cv::Mat rotated;
    cv::rotate(strip, rotated, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int x0 = 8;
    const int y0 = std::max(0, (frame_top_ + frame_bottom_) / 2 - rotated.rows / 2);
    if (x0 + rotated.cols <= image_.cols && y0 + rotated.rows <= image_.rows) {
      rotated.copyTo(image_(cv::Rect(x0, y0, rotated.cols, rotated.rows)));
    }
  }

  // Legend: a white box in the top-right corner, sized to its longest label, drawn over the data.
  void draw_legend() {
    int label_width = 0;
    const auto widen = [&](const std::string& label) {
      int baseline = 0;
      label_width = std::max(label_width, cv::getTextSize(label, kFont, 0.45, 1, &baseline).width);
    };
    for (const PlotSeries& s : plot_.series) widen(s.label);
    for (const PlotMarker& m : plot_.markers) widen(m.label);
    const int rows = static_cast<int>(plot_.series.size() + plot_.markers.size());
    const int box_width = label_width + 56;
    const int box_height = 20 * rows + 8;
    const cv::Rect box(frame_right_ - box_width - 8, frame_top_ + 8, box_width, box_height);
    cv::rectangle(image_, box, cv::Scalar(255, 255, 255), cv::FILLED);
    cv::rectangle(image_, box, cv::Scalar(150, 150, 150), 1);
    int legend_y = box.y + 20;
    for (const PlotSeries& s : plot_.series) {
      const int x = box.x + 8;
      cv::line(image_, {x, legend_y - 4}, {x + 30, legend_y - 4}, bgr(s.red, s.green, s.blue), 3,
               cv::LINE_AA);
      put_text(s.label, {x + 38, legend_y}, 0.45, -1);
      legend_y += 20;
    }
    for (const PlotMarker& m : plot_.markers) {
      const int x = box.x + 8;
      draw_marker(m, {x + 15, legend_y - 4});
      put_text(m.label, {x + 38, legend_y}, 0.45, -1);
      legend_y += 20;
    }
  }

  inline static const cv::Scalar kBlack{0, 0, 0};
  const LinePlot& plot_;
  const Layout L_;
  cv::Mat image_;
  const int frame_left_, frame_top_, frame_right_, frame_bottom_;
};

cv::Mat render_png(const LinePlot& plot) { return PngPlot(plot).draw(); }

// Degrees made continuous: a jump of more than 180 between neighbours is a wrap, not a turn.
std::vector<double> unwrap_degrees(std::vector<double> values) {
  for (size_t i = 1; i < values.size(); ++i) {
    while (values[i] - values[i - 1] > 180.0) values[i] -= 360.0;
    while (values[i] - values[i - 1] < -180.0) values[i] += 360.0;
  }
  return values;
}

std::string titled(const EvalPlotOptions& options, const std::string& what) {
  return options.run_name.empty() ? what : options.run_name + ": " + what;
}

double first_time(const AteResult& ate) {
  return ate.pairs.empty() ? 0.0 : ate.pairs.front().gt_timestamp;
}

constexpr const char* kTimeLabel = "time since first evaluated pose [s]";

}  // namespace

std::array<unsigned char, 3> error_colour(double value, double low, double high) {
  // Anchors of viridis at 0, 1/4, 1/2, 3/4, 1 (RGB).
  static constexpr double kAnchors[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  double t = high > low ? (value - low) / (high - low) : 0.0;
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double position = t * 4.0;
  const int k = std::min(3, static_cast<int>(position));
  const double f = position - k;
  std::array<unsigned char, 3> rgb{};
  for (int c = 0; c < 3; ++c) {
    rgb[c] = static_cast<unsigned char>(
        std::lround((1.0 - f) * kAnchors[k][c] + f * kAnchors[k + 1][c]));
  }
  return rgb;
}

std::string plot_to_svg(const LinePlot& plot) {
  return svg_document(plot.width, plot.height, svg_body(plot));
}

std::string stacked_plots_to_svg(const std::vector<LinePlot>& panels) {
  int width = 0, height = 0;
  std::string body;
  for (const LinePlot& panel : panels) {
    body += "<g transform=\"translate(0," + std::to_string(height) + ")\">\n" + svg_body(panel) +
            "</g>\n";
    width = std::max(width, panel.width);
    height += panel.height;
  }
  return svg_document(width, height, body);
}

void write_plot_svg(const LinePlot& plot, const std::filesystem::path& file) {
  write_text(plot_to_svg(plot), file);
}

void write_plot_png(const LinePlot& plot, const std::filesystem::path& file) {
  write_image(render_png(plot), file);
}

void write_stacked_plots_svg(const std::vector<LinePlot>& panels,
                             const std::filesystem::path& file) {
  write_text(stacked_plots_to_svg(panels), file);
}

void write_stacked_plots_png(const std::vector<LinePlot>& panels,
                             const std::filesystem::path& file) {
  int width = 0;
  for (const LinePlot& panel : panels) width = std::max(width, panel.width);
  std::vector<cv::Mat> images;
  for (const LinePlot& panel : panels) {
    cv::Mat image = render_png(panel);
    if (image.cols < width) {
      cv::copyMakeBorder(image, image, 0, 0, 0, width - image.cols, cv::BORDER_CONSTANT,
                         cv::Scalar(255, 255, 255));
    }
    images.push_back(image);
  }
  cv::Mat stacked;
  if (!images.empty()) cv::vconcat(images, stacked);
  write_image(stacked, file);
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

std::vector<size_t> evaluated_ground_truth_span(const Trajectory& ground_truth,
                                                const AteResult& ate) {
  std::vector<size_t> order(ground_truth.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return ground_truth[a].timestamp < ground_truth[b].timestamp;
  });
  if (ate.pairs.empty()) return {};
  Timestamp first = ate.pairs.front().gt_timestamp, last = first;
  for (const AtePair& pair : ate.pairs) {
    first = std::min(first, pair.gt_timestamp);
    last = std::max(last, pair.gt_timestamp);
  }
  std::vector<size_t> span;
  for (const size_t i : order) {
    if (ground_truth[i].timestamp >= first && ground_truth[i].timestamp <= last) span.push_back(i);
  }
  return span;
}

Eigen::Vector3d roll_pitch_yaw_deg(const Eigen::Matrix3d& R) {
  constexpr double kDeg = 180.0 / 3.14159265358979323846;
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  const double roll = std::atan2(R(2, 1), R(2, 2));
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  return Eigen::Vector3d(roll, pitch, yaw) * kDeg;
}

LinePlot trajectory_top_view_plot(const Trajectory& ground_truth, const AteResult& ate,
                                  const EvalPlotOptions& options) {
  constexpr const char* kAxisNames[3] = {"x", "y", "z"};
  const std::vector<size_t> span = evaluated_ground_truth_span(ground_truth, ate);
  std::vector<Eigen::Vector3d> gt_positions;
  gt_positions.reserve(span.size());
  for (const size_t i : span) gt_positions.push_back(ground_truth[i].T_world_camera.translation());
  const auto [a, b] = plane_of_largest_extent(gt_positions);

  LinePlot plot;
  plot.title = titled(options, std::string("top view (") + kAxisNames[a] + "-" + kAxisNames[b] +
                                   " plane), estimate after " + options.alignment_name +
                                   " alignment, coloured by ATE");
  plot.x_label = std::string(kAxisNames[a]) + " [m]";
  plot.y_label = std::string(kAxisNames[b]) + " [m]";
  plot.equal_aspect = true;
  PlotSeries gt{"ground truth (evaluated span)", {}, 40, 40, 40, {}};
  for (const Eigen::Vector3d& p : gt_positions) gt.points.emplace_back(p[a], p[b]);
  // Errors in millimetres: an RGB-D ATE is a few centimetres, so mm gives readable ticks.
  double low = std::numeric_limits<double>::infinity(), high = 0.0;
  for (const AtePair& pair : ate.pairs) {
    low = std::min(low, 1000.0 * pair.error);
    high = std::max(high, 1000.0 * pair.error);
  }
  if (ate.pairs.empty()) low = 0.0;
  const auto middle = error_colour(0.5, 0.0, 1.0);
  PlotSeries est{"estimate (aligned), colour = ATE", {}, middle[0], middle[1], middle[2], {}};
  for (const AtePair& pair : ate.pairs) {
    est.points.emplace_back(pair.est_aligned[a], pair.est_aligned[b]);
    est.values.push_back(1000.0 * pair.error);
  }
  plot.series = {gt, est};
  if (!gt.points.empty()) {
    plot.markers.push_back({"start", gt.points.front(), 44, 160, 44, false});
    plot.markers.push_back({"end", gt.points.back(), 214, 39, 40, true});
  }
  plot.colour_bar = ColourBar{"ATE [mm]", low, high};
  return plot;
}

LinePlot ate_over_time_plot(const AteResult& ate, const EvalPlotOptions& options) {
  LinePlot plot;
  char what[160];
  std::snprintf(what, sizeof(what), "ATE over time (%s alignment): RMSE %.4f m, %zu poses",
                options.alignment_name.c_str(), ate.error.rmse, ate.error.count);
  plot.title = titled(options, what);
  plot.x_label = kTimeLabel;
  plot.y_label = "position error [m]";
  plot.height = 500;
  PlotSeries errors{"|estimate - ground truth|", {}, 214, 39, 40, {}};
  const double t0 = first_time(ate);
  for (const AtePair& p : ate.pairs) errors.points.emplace_back(p.gt_timestamp - t0, p.error);
  plot.series = {errors};
  return plot;
}

std::vector<LinePlot> position_over_time_plots(const AteResult& ate,
                                               const EvalPlotOptions& options) {
  constexpr const char* kAxisNames[3] = {"x", "y", "z"};
  const double t0 = first_time(ate);
  std::vector<LinePlot> panels;
  for (int axis = 0; axis < 3; ++axis) {
    LinePlot plot;
    plot.title =
        titled(options, std::string("position ") + kAxisNames[axis] +
                            " over time, estimate after " + options.alignment_name + " alignment");
    plot.x_label = kTimeLabel;
    plot.y_label = std::string(kAxisNames[axis]) + " [m]";
    plot.height = 300;
    PlotSeries gt{"ground truth", {}, 40, 40, 40, {}};
    PlotSeries est{"estimate (aligned)", {}, 0, 114, 230, {}};
    for (const AtePair& p : ate.pairs) {
      gt.points.emplace_back(p.gt_timestamp - t0, p.gt_position[axis]);
      est.points.emplace_back(p.gt_timestamp - t0, p.est_aligned[axis]);
    }
    plot.series = {gt, est};
    panels.push_back(std::move(plot));
  }
  return panels;
}

std::vector<LinePlot> orientation_over_time_plots(const Trajectory& ground_truth,
                                                  const Trajectory& estimate, const AteResult& ate,
                                                  const RpeResult& rpe,
                                                  const EvalPlotOptions& options) {
  constexpr const char* kAngleNames[3] = {"roll", "pitch", "yaw"};
  const double t0 = first_time(ate);
  std::vector<double> times, angles[2][3];  // [gt / estimate][roll / pitch / yaw]
  for (const AtePair& p : ate.pairs) {
    if (p.gt_index >= ground_truth.size() || p.est_index >= estimate.size()) continue;
    times.push_back(p.gt_timestamp - t0);
    // The estimate's orientation in the ground truth's frame: the alignment turns it too.
    const Eigen::Matrix3d gt_rotation = ground_truth[p.gt_index].T_world_camera.rotation();
    const Eigen::Matrix3d est_rotation =
        ate.alignment.rotation * estimate[p.est_index].T_world_camera.rotation();
    const Eigen::Vector3d gt_rpy = roll_pitch_yaw_deg(gt_rotation);
    const Eigen::Vector3d est_rpy = roll_pitch_yaw_deg(est_rotation);
    for (int k = 0; k < 3; ++k) {
      angles[0][k].push_back(gt_rpy[k]);
      angles[1][k].push_back(est_rpy[k]);
    }
  }
  std::string note;
  if (rpe.body_frames_differ()) {
    char buffer[128];
    std::snprintf(buffer, sizeof(buffer),
                  " (ground truth body frame %.0f deg from the camera's: offsets expected)",
                  rpe.body_frame_rotation_deg);
    note = buffer;
  }
  std::vector<LinePlot> panels;
  for (int k = 0; k < 3; ++k) {
    LinePlot plot;
    plot.title = titled(options, std::string(kAngleNames[k]) + " over time" + note);
    plot.x_label = kTimeLabel;
    plot.y_label = std::string(kAngleNames[k]) + " [deg]";
    plot.height = 300;
    PlotSeries gt{"ground truth", {}, 40, 40, 40, {}};
    PlotSeries est{"estimate (aligned)", {}, 0, 114, 230, {}};
    const std::vector<double> gt_values = unwrap_degrees(angles[0][k]);
    const std::vector<double> est_values = unwrap_degrees(angles[1][k]);
    for (size_t i = 0; i < times.size(); ++i) {
      gt.points.emplace_back(times[i], gt_values[i]);
      est.points.emplace_back(times[i], est_values[i]);
    }
    plot.series = {gt, est};
    panels.push_back(std::move(plot));
  }
  return panels;
}

LinePlot rpe_over_time_plot(const AteResult& ate, const RpeResult& rpe,
                            const EvalPlotOptions& options) {
  LinePlot plot;
  char what[200];
  std::snprintf(
      what, sizeof(what), "translational RPE over %s: RMSE %.4f m, %zu pairs%s",
      options.rpe_delta.c_str(), rpe.translation.rmse, rpe.translation.count,
      rpe.body_frames_differ() ? " (ground truth tracks another body: not meaningful)" : "");
  plot.title = titled(options, what);
  plot.x_label = kTimeLabel;
  plot.y_label = "translation error [m]";
  plot.height = 500;
  PlotSeries errors{"RPE translation", {}, 148, 103, 189, {}};
  const double t0 = first_time(ate);
  for (const RpePair& p : rpe.pairs) {
    errors.points.emplace_back(p.gt_from - t0, p.translation_error);
  }
  plot.series = {errors};
  return plot;
}

EvalPlotFiles write_eval_plots(const Trajectory& ground_truth, const Trajectory& estimate,
                               const AteResult& ate, const RpeResult& rpe,
                               const std::filesystem::path& dir, const EvalPlotOptions& options) {
  std::error_code failure;
  std::filesystem::create_directories(dir, failure);
  if (failure) throw Error(dir.string() + ": cannot create plot directory: " + failure.message());
  EvalPlotFiles files;
  const auto single = [&](const LinePlot& plot, const std::string& name) {
    files.files.push_back(dir / (name + ".png"));
    write_plot_png(plot, files.files.back());
    files.files.push_back(dir / (name + ".svg"));
    write_plot_svg(plot, files.files.back());
  };
  const auto stacked = [&](const std::vector<LinePlot>& panels, const std::string& name) {
    files.files.push_back(dir / (name + ".png"));
    write_stacked_plots_png(panels, files.files.back());
    files.files.push_back(dir / (name + ".svg"));
    write_stacked_plots_svg(panels, files.files.back());
  };
  single(trajectory_top_view_plot(ground_truth, ate, options), "trajectory_top_view");
  single(ate_over_time_plot(ate, options), "ate_over_time");
  stacked(position_over_time_plots(ate, options), "position_over_time");
  stacked(orientation_over_time_plots(ground_truth, estimate, ate, rpe, options),
          "orientation_over_time");
  single(rpe_over_time_plot(ate, rpe, options), "rpe_over_time");
  return files;
}

}  // namespace pspslam
