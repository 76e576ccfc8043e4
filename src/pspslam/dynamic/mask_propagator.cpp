#include "pspslam/dynamic/mask_propagator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "pspslam/core/median.h"
#include "pspslam/geometry/compensated_homography.h"

namespace pspslam {
namespace {

// Median valid depth (metres) inside `shape` over `box` of `depth`, every other pixel.
double median_depth(const cv::Mat& depth, const cv::Rect& box, const cv::Mat& shape) {
  if (depth.empty() || depth.type() != CV_32FC1) return 0.0;
  std::vector<double> values;
  for (int y = 0; y < box.height; y += 2) {
    const float* row = depth.ptr<float>(box.y + y) + box.x;
    const std::uint8_t* inside = shape.ptr<std::uint8_t>(y);
    for (int x = 0; x < box.width; x += 2) {
      if (inside[x] && row[x] > 0.0f && std::isfinite(row[x])) values.push_back(row[x]);
    }
  }
  return upper_median(values);
}

}  // namespace

MaskPropagator::MaskPropagator(double fx, double frame_period_s, MaskPropagationParams params)
    : fx_(fx), frame_period_s_(frame_period_s), params_(params) {}

void MaskPropagator::add_frame(std::int64_t id, const cv::Mat& gray, const cv::Mat& depth) {
  if (!frames_.empty() && frames_.back().id + 1 != id) frames_.clear();
  frames_.push_back({id, gray, depth});
  while (frames_.size() > std::max<size_t>(2, params_.frames_kept)) frames_.pop_front();
}

const MaskPropagator::Images* MaskPropagator::images(std::int64_t id) const {
  if (frames_.empty() || id < frames_.front().id || id > frames_.back().id) return nullptr;
  return &frames_[static_cast<size_t>(id - frames_.front().id)];
}

PropagatedMask MaskPropagator::propagate(const cv::Mat& mask, std::int64_t mask_id,
                                         std::int64_t current_id, const HomographyChain& chain,
                                         bool with_watch) {
  PropagatedMask out;
  out.age_frames = static_cast<int>(current_id - mask_id);
  if (mask.empty() || mask_id > current_id) return out;
  if (mask_id == current_id) {
    out.mask = mask;
    return out;
  }
  if (mask_id != mask_id_) start(mask, mask_id);
  advance(current_id);
  const std::optional<Eigen::Matrix3d> H = chain.between(mask_id, current_id);
  out.mask = cv::Mat::zeros(mask.size(), CV_8UC1);
  out.moved = cv::Mat::zeros(mask.size(), CV_8UC1);
  if (with_watch) out.watch = cv::Mat::zeros(mask.size(), CV_8UC1);
  out.components = static_cast<int>(components_.size());
  for (const Component& component : components_) {
    bool by_flow = false;
    const cv::Point2d moved = displacement(component, H, by_flow);
    out.moved_by_flow += by_flow ? 1 : 0;
    const cv::Point offset(static_cast<int>(std::lround(moved.x)),
                           static_cast<int>(std::lround(moved.y)));
    // Unmoved (no flow, no homography): it may have gone anywhere a person can walk.
    const int radius =
        (by_flow || H) ? growth_px(component, out.age_frames) : params_.max_growth_px;
    out.growth_px = std::max(out.growth_px, radius);
    paint_grown(component, offset, radius, out.mask);
    paint_grown(component, offset, 0, out.moved);
    if (with_watch) paint_grown(component, offset, radius + params_.watch_band_px, out.watch);
  }
  return out;
}

void MaskPropagator::start(const cv::Mat& mask, std::int64_t mask_id) {
  components_.clear();
  mask_id_ = mask_id;
  tracked_to_ = mask_id;
  const Images* frame = images(mask_id);
  cv::Mat labels;
  cv::Mat stats;
  cv::Mat centroids;
  const int count =
      cv::connectedComponentsWithStats(mask != 0, labels, stats, centroids, 8, CV_32S);
  static const Images kNoImages;
  for (int label = 1; label < count; ++label)
    add_component(labels, stats, centroids, label, frame ? *frame : kNoImages);
}

void MaskPropagator::add_component(const cv::Mat& labels, const cv::Mat& stats,
                                   const cv::Mat& centroids, int label, const Images& frame) {
  Component component;
  component.box = {stats.at<int>(label, cv::CC_STAT_LEFT), stats.at<int>(label, cv::CC_STAT_TOP),
                   stats.at<int>(label, cv::CC_STAT_WIDTH),
                   stats.at<int>(label, cv::CC_STAT_HEIGHT)};
  component.shape = labels(component.box) == label;
  component.centroid = {centroids.at<double>(label, 0), centroids.at<double>(label, 1)};
  component.depth_m = median_depth(frame.depth, component.box, component.shape);
  const int area = stats.at<int>(label, cv::CC_STAT_AREA);
  if (!frame.gray.empty() && area >= params_.min_component_area_px) {
    cv::Mat inside;
    const int inset = params_.corner_inset_px;
    cv::erode(component.shape, inside,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * inset + 1, 2 * inset + 1}));
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(frame.gray(component.box), corners, params_.corners_per_component, 0.01,
                            5.0, inside);
    for (cv::Point2f& corner : corners) corner += cv::Point2f(component.box.tl());
    component.origin = corners;
    component.now = std::move(corners);
    component.alive.assign(component.now.size(), 1);
  }
  components_.push_back(std::move(component));
}

// Follows the corners from the frame they were last seen in to `current_id` in one pyramidal
// Lucas-Kanade call for all components.
void MaskPropagator::advance(std::int64_t current_id) {
  if (tracked_to_ >= current_id) return;
  const Images* previous = images(tracked_to_);
  const Images* current = images(current_id);
  tracked_to_ = current_id;
  from_.clear();
  for (const Component& component : components_) {
    for (size_t i = 0; i < component.now.size(); ++i)
      if (component.alive[i]) from_.push_back(component.now[i]);
  }
  const bool can_track =
      previous && current && !previous->gray.empty() && !current->gray.empty() && !from_.empty();
  if (can_track) {
    cv::calcOpticalFlowPyrLK(previous->gray, current->gray, from_, to_, status_, error_,
                             cv::Size(21, 21), 3);
  }
  size_t next = 0;
  for (Component& component : components_) {
    for (size_t i = 0; i < component.now.size(); ++i) {
      if (!component.alive[i]) continue;
      const size_t k = next++;
      if (can_track && status_[k]) {
        component.now[i] = to_[k];
      } else {
        component.alive[i] = 0;
      }
    }
  }
}

cv::Point2d MaskPropagator::displacement(const Component& component,
                                         const std::optional<Eigen::Matrix3d>& H,
                                         bool& by_flow) const {
  std::vector<double> dx;
  std::vector<double> dy;
  for (size_t i = 0; i < component.now.size(); ++i) {
    if (!component.alive[i]) continue;
    dx.push_back(component.now[i].x - component.origin[i].x);
    dy.push_back(component.now[i].y - component.origin[i].y);
  }
  by_flow = static_cast<int>(dx.size()) >= params_.min_tracked_corners;
  if (by_flow) return {upper_median(dx), upper_median(dy)};
  if (!H) return {0.0, 0.0};
  const Eigen::Vector2d at =
      transfer_point(*H, Eigen::Vector2d(component.centroid.x, component.centroid.y));
  return {at.x() - component.centroid.x, at.y() - component.centroid.y};
}

int MaskPropagator::growth_px(const Component& component, int age_frames) const {
  if (component.depth_m <= 0.0) return params_.max_growth_px;
  const double metres = params_.residual_speed_mps * age_frames * frame_period_s_;
  const double pixels = std::ceil(fx_ * metres / component.depth_m);
  return static_cast<int>(std::clamp(pixels, 0.0, static_cast<double>(params_.max_growth_px)));
}

// ORs `component`, moved by `offset` and grown by `radius` pixels (Euclidean), into `out`.
void MaskPropagator::paint_grown(const Component& component, cv::Point offset, int radius,
                                 cv::Mat& out) {
  const cv::Rect padded(component.box.x + offset.x - radius, component.box.y + offset.y - radius,
                        component.box.width + 2 * radius, component.box.height + 2 * radius);
  const cv::Rect visible = padded & cv::Rect(0, 0, out.cols, out.rows);
  if (visible.empty()) return;
  cv::Mat grown;
  if (radius == 0) {
    grown = component.shape;
  } else {
    // Distance to the shape in a padded canvas: linear in the pixels, whatever the radius.
    cv::Mat outside(padded.size(), CV_8UC1, cv::Scalar(255));
    outside(cv::Rect(radius, radius, component.box.width, component.box.height))
        .setTo(0, component.shape);
    cv::Mat distance;
    cv::distanceTransform(outside, distance, cv::DIST_L2, cv::DIST_MASK_5);
    grown = distance <= radius;
  }
  const cv::Rect source(visible.x - padded.x, visible.y - padded.y, visible.width, visible.height);
  cv::Mat target = out(visible);
  cv::bitwise_or(target, grown(source), target);
}

}  // namespace pspslam
