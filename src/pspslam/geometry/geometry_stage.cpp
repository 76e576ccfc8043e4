#include "pspslam/geometry/geometry_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/clock.h"
#include "pspslam/core/error.h"
#include "pspslam/core/thread_cpu_time.h"
#include "pspslam/core/yaml_section.h"

namespace pspslam {
namespace {

// Marks a candidate whose depth has not been read yet (depths are >= 0).
constexpr double kDepthNotRead = -1.0;

// Wall and thread-CPU clocks read together, so each stage part reports both.
struct Stopwatch {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  double cpu = thread_cpu_ms();

  double wall_ms() const { return milliseconds_since(wall); }
  double cpu_ms() const { return thread_cpu_ms() - cpu; }
};

}  // namespace

GeometryParams GeometryParams::from_yaml(YamlSection& section) {
  GeometryParams p;
  YamlSection homography = section.section("homography");
  p.homography = HomographyParams::from_yaml(homography);
  YamlSection multiview = section.section("multiview");
  p.multiview = MultiViewParams::from_yaml(multiview);
  YamlSection search = section.section("search");
  p.search = AntColonyParams::from_yaml(search);
  YamlSection region = section.section("region");
  p.region = RegionGrowParams::from_yaml(region);
  YamlSection references = section.section("references");
  p.references.wanted_coverage =
      references.optional("wanted_coverage", p.references.wanted_coverage);
  references.require(p.references.wanted_coverage >= 1, "wanted_coverage", "must be >= 1");
  p.references.point_stride = references.optional("point_stride", p.references.point_stride);
  references.require(p.references.point_stride >= 1, "point_stride", "must be >= 1");
  p.references.older_view_gain_share =
      references.optional("older_view_gain_share", p.references.older_view_gain_share);
  references.require(
      p.references.older_view_gain_share > 0.0 && p.references.older_view_gain_share <= 1.0,
      "older_view_gain_share", "must be in (0, 1]");
  references.finish();
  p.previous_mask_prior = section.optional("previous_mask_prior", p.previous_mask_prior);
  p.output_warped_previous_mask =
      section.optional("output_warped_previous_mask", p.output_warped_previous_mask);
  section.finish();
  return p;
}

GeometryStage::GeometryStage(PinholeCamera camera, GeometryParams params)
    : camera_(camera),
      params_(params),
      test_(camera, params.multiview),
      selector_(camera,
                {params.multiview.max_reference_views, params.references.wanted_coverage,
                 params.references.point_stride, params.multiview.reference_patch_radius,
                 params.multiview.max_parallax_deg, params.references.older_view_gain_share}),
      search_(params.search),
      grower_(params.region, static_cast<float>(camera.fx)) {}

GeometryFrameResult GeometryStage::process(const GeometryFrameInput& input) {
  const Stopwatch start;
  if (input.depth.type() != CV_32FC1) throw Error("GeometryStage: depth must be CV_32FC1 metres");
  if (!input.keypoint_depths.empty() && input.keypoint_depths.size() != input.keypoints.size()) {
    throw Error("GeometryStage: " + std::to_string(input.keypoint_depths.size()) +
                " keypoint depths for " + std::to_string(input.keypoints.size()) + " keypoints");
  }
  GeometryFrameResult result;
  const std::optional<Eigen::Matrix3d> previous_to_current = compensate_motion(input, result);
  result.timing.homography_ms = start.wall_ms();
  result.timing.homography_cpu_ms = start.cpu_ms();
  prepare_candidates(input, previous_to_current);

  const Stopwatch selection_start;
  const std::span<const DepthView> references = select_references(input);
  result.references_used = static_cast<int>(references.size());
  result.timing.selection_ms = selection_start.wall_ms();
  result.timing.selection_cpu_ms = selection_start.cpu_ms();

  // III.C: reverse ant-colony search driving the multi-view test.
  const Stopwatch search_start;
  test_.set_frame(input.T_world_camera, references);
  const SearchResult& search = search_.run(
      points_, input.depth.size(),
      [&](int index) {
        depth_of(input, static_cast<size_t>(index));
        return test_.is_dynamic(candidates_[index]);
      },
      priority_);
  result.timing.search_ms = search_start.wall_ms();
  result.timing.search_cpu_ms = search_start.cpu_ms();

  const Stopwatch region_start;
  grow_regions(input, search, result.dynamic_mask);
  result.timing.region_ms = region_start.wall_ms();
  result.timing.region_cpu_ms = region_start.cpu_ms();

  mark_dynamic_keypoints(search, result);
  result.timing.total_ms = start.wall_ms();
  result.timing.total_cpu_ms = start.cpu_ms();
  return result;
}

// III.B: camera-motion compensation of the previous frame (eq. 10-11).
std::optional<Eigen::Matrix3d> GeometryStage::compensate_motion(const GeometryFrameInput& input,
                                                                GeometryFrameResult& result) {
  const cv::Mat& previous_mask = input.previous_dynamic_mask;
  std::optional<Eigen::Matrix3d> previous_to_current = input.H_previous_to_current;
  if (!previous_to_current && input.matched_previous.size() >= 4) {
    result.homography = estimate_compensated_homography(input.matched_previous,
                                                        input.matched_current, params_.homography);
    if (result.homography.valid) previous_to_current = result.homography.H;
  }
  if (has_previous_mask(input) && params_.output_warped_previous_mask) {
    result.warped_previous_mask =
        previous_to_current
            ? warp_to_current(previous_mask, *previous_to_current, input.depth.size(), true)
            : previous_mask.clone();
  }
  return previous_to_current;
}

bool GeometryStage::has_previous_mask(const GeometryFrameInput& input) {
  return !input.previous_dynamic_mask.empty() && input.previous_dynamic_mask.type() == CV_8UC1;
}

// Candidates. Work per point that only a tested point needs (its depth: a read at a random
// place of the depth image when the caller gives none) is done lazily in depth_of(), so the
// ant colony pays it only for the points it tests; the exhaustive baseline pays it for all.
void GeometryStage::prepare_candidates(const GeometryFrameInput& input,
                                       const std::optional<Eigen::Matrix3d>& previous_to_current) {
  const cv::Mat& previous_mask = input.previous_dynamic_mask;
  const Eigen::Matrix3d current_to_previous = previous_to_current
                                                  ? Eigen::Matrix3d(previous_to_current->inverse())
                                                  : Eigen::Matrix3d::Identity();
  const size_t n = input.keypoints.size();
  points_.resize(n);
  candidates_.resize(n);
  priority_.clear();
  // Only the ant colony uses the priority points (the exhaustive baseline tests every point).
  const bool use_prior = params_.previous_mask_prior && has_previous_mask(input) &&
                         params_.search.strategy == SearchStrategy::ant_colony;
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d& pixel = input.keypoints[i];
    points_[i] = pixel.cast<float>();
    candidates_[i] = {pixel, kDepthNotRead};
    if (use_prior) {
      // Where was this pixel in the previous frame? (inverse of the compensating homography)
      // Bounds checked on the doubles: inside the image, truncation is the floor (std::floor is
      // a libm call without SSE4.1).
      const Eigen::Vector2d previous = transfer_point(current_to_previous, pixel);
      if (previous.x() >= 0.0 && previous.y() >= 0.0 && previous.x() < previous_mask.cols &&
          previous.y() < previous_mask.rows &&
          previous_mask.ptr<std::uint8_t>(
              static_cast<int>(previous.y()))[static_cast<int>(previous.x())])
        priority_.push_back(static_cast<int>(i));
    }
  }
}

double GeometryStage::depth_of(const GeometryFrameInput& input, size_t i) {
  double& depth = candidates_[i].depth;
  if (depth != kDepthNotRead) return depth;
  depth = 0.0;
  if (!input.keypoint_depths.empty()) {
    depth = input.keypoint_depths[i];
  } else {
    const int u = static_cast<int>(std::lround(candidates_[i].pixel.x()));
    const int v = static_cast<int>(std::lround(candidates_[i].pixel.y()));
    if (u >= 0 && v >= 0 && u < input.depth.cols && v < input.depth.rows)
      depth = input.depth.ptr<float>(v)[u];
  }
  return depth;
}

// Reference views: the most covering ones of a larger pool (DynaSLAM: most overlapping).
// The test gets them oldest first (the pool is ordered newest first): a mover has had the most
// time to leave its place in the oldest view, so that view most often gives the dynamic vote
// that ends the test of a dynamic point early. The verdict does not depend on the order.
std::span<const DepthView> GeometryStage::select_references(const GeometryFrameInput& input) {
  selected_references_.clear();
  if (input.references.size() > static_cast<size_t>(params_.multiview.max_reference_views)) {
    // The selector estimates coverage on every point_stride-th candidate: only those need depths.
    for (size_t i = 0; i < candidates_.size();
         i += static_cast<size_t>(params_.references.point_stride))
      depth_of(input, i);
    selected_pool_indices_ = selector_.select(input.T_world_camera, candidates_, input.references);
    std::sort(selected_pool_indices_.begin(), selected_pool_indices_.end(), std::greater<>());
    for (int v : selected_pool_indices_) selected_references_.push_back(input.references[v]);
  } else {
    selected_references_.assign(input.references.rbegin(), input.references.rend());
  }
  return selected_references_;
}

// Region growing from the dynamic points; verified-static points may act as barriers.
void GeometryStage::grow_regions(const GeometryFrameInput& input, const SearchResult& search,
                                 cv::Mat& mask) {
  seeds_.clear();
  seed_depths_.clear();
  static_points_.clear();
  for (size_t i = 0; i < points_.size(); ++i) {
    if (search.dynamic[i]) {
      seeds_.push_back(points_[i]);
      seed_depths_.push_back(static_cast<float>(depth_of(input, i)));
    } else if (search.tested[i]) {
      static_points_.push_back(points_[i]);
    }
  }
  grower_.grow(input.depth, seeds_, seed_depths_, static_points_, mask);
}

// A keypoint is dynamic when the test found it so or it lies in the grown mask.
void GeometryStage::mark_dynamic_keypoints(const SearchResult& search,
                                           GeometryFrameResult& result) const {
  const size_t n = points_.size();
  result.keypoint_tested = search.tested;
  result.keypoint_tested_dynamic = search.dynamic;
  result.keypoint_dynamic.assign(n, 0);
  result.tested_count = search.tested_count;
  result.tested_dynamic_count = search.dynamic_count;
  result.last_band_tests = search.last_band_tests;
  for (size_t i = 0; i < n; ++i) {
    const int u = static_cast<int>(points_[i].x()), v = static_cast<int>(points_[i].y());
    const bool in_mask = u >= 0 && v >= 0 && u < result.dynamic_mask.cols &&
                         v < result.dynamic_mask.rows && result.dynamic_mask.at<std::uint8_t>(v, u);
    result.keypoint_dynamic[i] = search.dynamic[i] || in_mask;
    result.dynamic_count += result.keypoint_dynamic[i];
  }
}

cv::Mat fuse_dynamic_masks(const cv::Mat& semantic_mask, const cv::Mat& geometry_mask,
                           int dilation_px) {
  if (semantic_mask.empty() && geometry_mask.empty()) return {};
  const cv::Size size = semantic_mask.empty() ? geometry_mask.size() : semantic_mask.size();
  if (!semantic_mask.empty() && !geometry_mask.empty() &&
      semantic_mask.size() != geometry_mask.size()) {
    throw Error("fuse_dynamic_masks: semantic mask " + std::to_string(semantic_mask.cols) + "x" +
                std::to_string(semantic_mask.rows) + " and geometry mask " +
                std::to_string(geometry_mask.cols) + "x" + std::to_string(geometry_mask.rows) +
                " differ in size");
  }
  cv::Mat fused = cv::Mat::zeros(size, CV_8UC1);
  for (const cv::Mat* mask : {&semantic_mask, &geometry_mask}) {
    if (mask->empty()) continue;
    if (mask->type() != CV_8UC1) throw Error("fuse_dynamic_masks: masks must be CV_8UC1");
    fused.setTo(255, *mask);
  }
  if (dilation_px > 0) {
    const int k = 2 * dilation_px + 1;
    cv::dilate(fused, fused, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(k, k)));
  }
  return fused;
}

}  // namespace pspslam
