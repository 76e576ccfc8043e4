#include "pspslam/semantic/overlay.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <utility>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kFontScale = 0.5;
constexpr int kRowHeight = 20;
constexpr int kSwatch = 14;
constexpr int kPadding = 6;

bool is_dynamic(int id, const std::vector<int>& dynamic_ids) {
  return std::find(dynamic_ids.begin(), dynamic_ids.end(), id) != dynamic_ids.end();
}

std::string class_name(int id, const std::vector<std::string>& class_names) {
  if (id >= 0 && static_cast<size_t>(id) < class_names.size()) return class_names[id];
  return "class " + std::to_string(id);
}

}  // namespace

cv::Rect draw_legend(cv::Mat& image, const std::vector<LegendEntry>& entries, cv::Point corner) {
  if (image.type() != CV_8UC3) throw Error("draw_legend: expected a CV_8UC3 image");
  if (entries.empty()) return {};
  int text_width = 0;
  for (const LegendEntry& entry : entries) {
    int baseline = 0;
    text_width =
        std::max(text_width, cv::getTextSize(entry.label, kFont, kFontScale, 1, &baseline).width);
  }
  const cv::Rect wanted(corner.x, corner.y, kPadding + kSwatch + kPadding + text_width + kPadding,
                        kPadding + kRowHeight * static_cast<int>(entries.size()) + kPadding / 2);
  const cv::Rect box = wanted & cv::Rect(0, 0, image.cols, image.rows);
  if (box.empty()) return {};
  // Semi-opaque so the picture under the legend is still guessable, dark enough for white text.
  cv::Mat region = image(box);
  region.convertTo(region, -1, 0.35, 0.0);
  int y = corner.y + kPadding;
  for (const LegendEntry& entry : entries) {
    const cv::Rect swatch(corner.x + kPadding, y + (kRowHeight - kSwatch) / 2, kSwatch, kSwatch);
    const cv::Scalar colour(entry.colour[0], entry.colour[1], entry.colour[2]);
    cv::rectangle(image, swatch, colour, cv::FILLED);
    cv::rectangle(image, swatch, cv::Scalar(255, 255, 255), 1);
    cv::putText(image, entry.label, {swatch.x + kSwatch + kPadding, y + kRowHeight - 6}, kFont,
                kFontScale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    y += kRowHeight;
  }
  return box;
}

cv::Vec3b overlay_class_colour(int id, const std::vector<int>& dynamic_ids,
                               const std::vector<std::string>& class_names,
                               const OverlayStyle& style) {
  if (is_dynamic(id, dynamic_ids)) {
    if (class_name(id, class_names) == "person") return {0, 0, 255};
    // Vivid BGR colours far from each other and from red (reserved for people).
    static constexpr std::array<std::array<unsigned char, 3>, 7> kVivid = {{{0, 140, 255},
                                                                            {0, 230, 255},
                                                                            {255, 0, 255},
                                                                            {255, 255, 0},
                                                                            {0, 255, 0},
                                                                            {255, 90, 0},
                                                                            {255, 0, 140}}};
    size_t rank = 0;
    for (const int other : dynamic_ids) {
      if (other < id && class_name(other, class_names) != "person") ++rank;
    }
    const auto& c = kVivid[rank % kVivid.size()];
    return {c[0], c[1], c[2]};
  }
  const cv::Vec3b voc = label_color(id);
  const double grey = (voc[0] + voc[1] + voc[2]) / 3.0;
  cv::Vec3b muted;
  for (int k = 0; k < 3; ++k) {
    muted[k] = cv::saturate_cast<uchar>(grey + style.static_saturation * (voc[k] - grey));
  }
  return muted;
}

std::vector<LegendEntry> overlay_legend_entries(const LabelMap& labels,
                                                const std::vector<int>& dynamic_ids,
                                                const std::vector<std::string>& class_names,
                                                const OverlayStyle& style) {
  if (labels.type() != CV_8UC1) throw Error("overlay_legend_entries: expected a CV_8UC1 label map");
  std::array<size_t, 256> counts{};
  for (int y = 0; y < labels.rows; ++y) {
    const uchar* row = labels.ptr<uchar>(y);
    for (int x = 0; x < labels.cols; ++x) ++counts[row[x]];
  }
  std::vector<std::pair<int, size_t>> present;  // (id, pixels)
  for (int id = 1; id < 256; ++id) {
    if (counts[id] > 0) present.emplace_back(id, counts[id]);
  }
  std::stable_sort(present.begin(), present.end(), [&](const auto& a, const auto& b) {
    const bool da = is_dynamic(a.first, dynamic_ids), db = is_dynamic(b.first, dynamic_ids);
    if (da != db) return da;
    return a.second > b.second;
  });
  std::vector<LegendEntry> entries;
  for (const auto& [id, pixels] : present) {
    const bool dynamic = is_dynamic(id, dynamic_ids);
    entries.push_back({class_name(id, class_names) + (dynamic ? " (dynamic)" : ""),
                       overlay_class_colour(id, dynamic_ids, class_names, style)});
  }
  return entries;
}

cv::Mat overlay_segmentation(const cv::Mat& bgr, const LabelMap& labels,
                             const std::vector<int>& dynamic_ids,
                             const std::vector<std::string>& class_names,
                             const OverlayStyle& style) {
  if (bgr.type() != CV_8UC3 || labels.type() != CV_8UC1 || bgr.size() != labels.size()) {
    throw Error(
        "overlay_segmentation: expected a CV_8UC3 image and a CV_8UC1 label map of its size");
  }
  std::array<cv::Vec3b, 256> colours;
  std::array<double, 256> alphas;
  std::array<bool, 256> dynamic{};
  for (int id = 0; id < 256; ++id) {
    dynamic[id] = is_dynamic(id, dynamic_ids);
    colours[id] = overlay_class_colour(id, dynamic_ids, class_names, style);
    alphas[id] = id == 0 ? 0.0 : (dynamic[id] ? style.dynamic_alpha : style.static_alpha);
  }
  cv::Mat out = bgr.clone();
  for (int y = 0; y < out.rows; ++y) {
    const uchar* l = labels.ptr<uchar>(y);
    cv::Vec3b* p = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.cols; ++x) {
      const double alpha = alphas[l[x]];
      if (alpha <= 0.0) continue;
      const cv::Vec3b c = colours[l[x]];
      for (int k = 0; k < 3; ++k) {
        p[x][k] = cv::saturate_cast<uchar>((1.0 - alpha) * p[x][k] + alpha * c[k]);
      }
    }
  }
  if (style.outline_px > 0) {
    // Outlines per dynamic class present, holes included (RETR_LIST): a person seen through a gap
    // still shows where the masked region ends.
    for (const int id : dynamic_ids) {
      if (id < 0 || id > 255) continue;
      const cv::Mat region = labels == id;
      if (cv::countNonZero(region) == 0) continue;
      std::vector<std::vector<cv::Point>> contours;
      cv::findContours(region, contours, cv::RETR_LIST, cv::CHAIN_APPROX_NONE);
      const cv::Vec3b c = colours[id];
      cv::drawContours(out, contours, -1, cv::Scalar(c[0], c[1], c[2]), style.outline_px,
                       cv::LINE_8);
    }
  }
  if (style.legend) {
    draw_legend(out, overlay_legend_entries(labels, dynamic_ids, class_names, style));
  }
  return out;
}

}  // namespace pspslam
