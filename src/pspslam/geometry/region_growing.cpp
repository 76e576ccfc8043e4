#include "pspslam/geometry/region_growing.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"

namespace pspslam {

RegionGrowParams RegionGrowParams::from_yaml(YamlSection& section) {
  RegionGrowParams p;
  p.enabled = section.optional("enabled", p.enabled);
  p.stride = section.optional("stride", p.stride);
  section.require(p.stride >= 1 && p.stride <= 16, "stride", "must be in [1, 16]");
  p.max_step_abs_m = section.optional("max_step_abs_m", p.max_step_abs_m);
  section.require(p.max_step_abs_m >= 0.0, "max_step_abs_m", "must be >= 0");
  p.max_step_relative = section.optional("max_step_relative", p.max_step_relative);
  section.require(p.max_step_relative >= 0.0, "max_step_relative", "must be >= 0");
  p.max_depth_from_seed_m = section.optional("max_depth_from_seed_m", p.max_depth_from_seed_m);
  section.require(p.max_depth_from_seed_m > 0.0, "max_depth_from_seed_m", "must be > 0");
  p.max_grow_radius_px = section.optional("max_grow_radius_px", p.max_grow_radius_px);
  section.require(p.max_grow_radius_px > 0.0f, "max_grow_radius_px", "must be > 0");
  p.max_grow_radius_m = section.optional("max_grow_radius_m", p.max_grow_radius_m);
  section.require(p.max_grow_radius_m >= 0.0f, "max_grow_radius_m", "must be >= 0");
  p.min_seeds_per_region = section.optional("min_seeds_per_region", p.min_seeds_per_region);
  section.require(p.min_seeds_per_region >= 1, "min_seeds_per_region", "must be >= 1");
  p.max_region_samples = section.optional("max_region_samples", p.max_region_samples);
  section.require(p.max_region_samples >= 1, "max_region_samples", "must be >= 1");
  p.static_barrier_radius_px =
      section.optional("static_barrier_radius_px", p.static_barrier_radius_px);
  section.require(p.static_barrier_radius_px >= 0.0f, "static_barrier_radius_px", "must be >= 0");
  p.dilation_px = section.optional("dilation_px", p.dilation_px);
  section.require(p.dilation_px >= 0, "dilation_px", "must be >= 0");
  section.finish();
  return p;
}

DynamicRegionGrower::DynamicRegionGrower(RegionGrowParams params, float focal_length_px)
    : params_(params), focal_length_px_(focal_length_px) {}

void DynamicRegionGrower::grow(const cv::Mat& depth, std::span<const Eigen::Vector2f> seeds,
                               std::span<const float> seed_depths,
                               std::span<const Eigen::Vector2f> static_points, cv::Mat& mask) {
  if (depth.type() != CV_32FC1) throw Error("DynamicRegionGrower: depth must be CV_32FC1 metres");
  if (seed_depths.size() != seeds.size()) {
    throw Error("DynamicRegionGrower: " + std::to_string(seed_depths.size()) + " seed depths for " +
                std::to_string(seeds.size()) + " seeds");
  }
  mask.create(depth.size(), CV_8UC1);
  mask.setTo(0);
  if (!params_.enabled || seeds.empty()) return;
  reset_grid(depth, static_points);

  region_seeds_.clear();
  // Bounding box of all grown cells: the full-resolution fill only visits it.
  GridBox grown{.min_x = grid_depth_.cols, .max_x = -1, .min_y = grid_depth_.rows, .max_y = -1};
  for (size_t seed_index = 0; seed_index < seeds.size(); ++seed_index) {
    const float wanted = seed_depths[seed_index];
    const double tolerance = params_.max_step_abs_m + params_.max_step_relative * wanted;
    const auto [sx, sy, gap] = start_cell(depth, seeds[seed_index], wanted);
    if (sx < 0 || gap > tolerance) continue;
    const size_t start = static_cast<size_t>(sy) * grid_depth_.cols + sx;
    if (region_of_[start] >= 0) {  // inside an earlier seed's region: one more vote for it
      ++region_seeds_[region_of_[start]];
      continue;
    }
    grow_region(depth, sx, sy, grown);
  }
  if (grown.max_x < 0) return;
  claimed_ = cv::Rect(grown.min_x, grown.min_y, grown.max_x - grown.min_x + 1,
                      grown.max_y - grown.min_y + 1);
  fill_mask(depth, grown, mask);
  if (params_.dilation_px > 0) {
    const int k = 2 * params_.dilation_px + 1;
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  }
}

void DynamicRegionGrower::reset_grid(const cv::Mat& depth,
                                     std::span<const Eigen::Vector2f> static_points) {
  const int s = params_.stride;
  const int cols = (depth.cols + s - 1) / s;
  const int rows = (depth.rows + s - 1) / s;
  // Nearest sampling (block centre) keeps depth edges sharp, unlike area averaging. A grid row is
  // sampled as a whole when growth first reaches it (sampled_row).
  grid_depth_.create(rows, cols, CV_32FC1);
  row_sampled_.assign(static_cast<size_t>(rows), 0);
  const size_t cells = static_cast<size_t>(rows) * cols;
  // Only the cells the last call claimed (its bounding box) need clearing; a full clear wrote the
  // whole grid every frame.
  if (region_of_.size() != cells || claimed_cols_ != cols) {
    region_of_.assign(cells, -1);
    claimed_cols_ = cols;
  } else {
    for (int gy = claimed_.y; gy < claimed_.y + claimed_.height; ++gy)
      std::fill_n(region_of_.begin() + static_cast<long>(gy) * cols + claimed_.x, claimed_.width,
                  -1);
  }
  claimed_ = {};
  const bool barriers = params_.static_barrier_radius_px > 0.0f;
  barrier_.assign(barriers ? cells : 0, 0);
  if (!barriers) return;
  const int radius = static_cast<int>(std::ceil(params_.static_barrier_radius_px / s));
  for (const Eigen::Vector2f& p : static_points) {
    const int cx = static_cast<int>(p.x()) / s, cy = static_cast<int>(p.y()) / s;
    for (int y = std::max(0, cy - radius); y <= std::min(rows - 1, cy + radius); ++y)
      for (int x = std::max(0, cx - radius); x <= std::min(cols - 1, cx + radius); ++x)
        barrier_[static_cast<size_t>(y) * cols + x] = 1;
  }
}

// A grid row's samples lie on one pixel row, so the reads stream through consecutive cache lines
// (sampling cell by cell, in growth order, stalled on a cache miss every few cells; sampling
// every row up front read rows no region reaches).
const float* DynamicRegionGrower::sampled_row(const cv::Mat& depth, int gy) {
  float* samples = grid_depth_.ptr<float>(gy);
  if (!row_sampled_[gy]) {
    row_sampled_[gy] = 1;
    const int s = params_.stride;
    const float* pixels = depth.ptr<float>(std::min(gy * s + s / 2, depth.rows - 1));
    for (int gx = 0; gx < grid_depth_.cols; ++gx)
      samples[gx] = pixels[std::min(gx * s + s / 2, depth.cols - 1)];
  }
  return samples;
}

// Start on the 3x3 grid neighbour whose depth is closest to the seed's own depth: next to an
// object edge the block sample may lie on the background.
DynamicRegionGrower::StartCell DynamicRegionGrower::start_cell(const cv::Mat& depth,
                                                               const Eigen::Vector2f& seed,
                                                               float wanted) {
  const int s = params_.stride;
  const int cols = grid_depth_.cols, rows = grid_depth_.rows;
  const int cx = std::clamp(static_cast<int>(seed.x()) / s, 0, cols - 1);
  const int cy = std::clamp(static_cast<int>(seed.y()) / s, 0, rows - 1);
  StartCell best{.x = -1, .y = -1, .gap = std::numeric_limits<float>::infinity()};
  for (int y = std::max(0, cy - 1); y <= std::min(rows - 1, cy + 1); ++y) {
    const float* samples = sampled_row(depth, y);
    for (int x = std::max(0, cx - 1); x <= std::min(cols - 1, cx + 1); ++x) {
      const float gap = std::abs(samples[x] - wanted);
      if (samples[x] > 0.0f && gap < best.gap) best = {.x = x, .y = y, .gap = gap};
    }
  }
  return best;
}

void DynamicRegionGrower::grow_region(const cv::Mat& depth, int sx, int sy, GridBox& grown) {
  const int s = params_.stride;
  const int cols = grid_depth_.cols, rows = grid_depth_.rows;
  const bool barriers = params_.static_barrier_radius_px > 0.0f;
  const float seed_depth = grid_depth_.at<float>(sy, sx);
  const float radius_px = std::max(params_.max_grow_radius_px,
                                   focal_length_px_ * params_.max_grow_radius_m / seed_depth);
  const float radius_cells = radius_px / static_cast<float>(s);
  const float radius2 = radius_cells * radius_cells;
  const int region_id = static_cast<int>(region_seeds_.size());
  region_seeds_.push_back(1);
  region_of_[static_cast<size_t>(sy) * cols + sx] = region_id;
  // Queue entries are (x, y) pairs, so popping a cell needs no division by the grid width.
  queue_.assign(1, {sx, sy});
  grown.add(sx, sy);
  size_t head = 0;
  // Breadth-first over the 4-neighbourhood. A neighbour joins when it is inside the seed's disc,
  // unclaimed, valid, continuous with this cell and near the seed's depth.
  const auto visit = [&](int nx, int ny, float d, double step) {
    // Claimed first: inside a region most neighbours already are.
    const size_t next = static_cast<size_t>(ny) * cols + nx;
    if (region_of_[next] >= 0 || (barriers && barrier_[next])) return;
    const float dx = static_cast<float>(nx - sx), dy = static_cast<float>(ny - sy);
    if (dx * dx + dy * dy > radius2) return;
    const float nd = sampled_row(depth, ny)[nx];
    if (!(nd > 0.0f) || std::abs(nd - d) > step ||
        std::abs(nd - seed_depth) > params_.max_depth_from_seed_m)
      return;
    region_of_[next] = region_id;
    queue_.push_back({nx, ny});
    grown.add(nx, ny);
  };
  while (head < queue_.size() && static_cast<int>(queue_.size()) < params_.max_region_samples) {
    const auto [x, y] = queue_[head++];
    const float d = grid_depth_.ptr<float>(y)[x];  // sampled when the cell joined
    const double step = params_.max_step_abs_m + params_.max_step_relative * d;
    if (x + 1 < cols) visit(x + 1, y, d, step);
    if (x > 0) visit(x - 1, y, d, step);
    if (y + 1 < rows) visit(x, y + 1, d, step);
    if (y > 0) visit(x, y - 1, d, step);
  }
}

// Full-resolution fill: a pixel of a grown block joins only if its own depth is continuous with
// the block's sample, so silhouettes stay pixel-sharp although growth ran on the coarse grid.
// Regions that too few seeds support are not painted. Per grid row, each pixel column gets its
// block's sample and step (NaN sample outside painted blocks: never continuous), so the s pixel
// rows below are one branch-free loop each over the row's run of painted blocks, which the
// compiler vectorises (a loop per 4x4 block did not).
void DynamicRegionGrower::fill_mask(const cv::Mat& depth, const GridBox& grown, cv::Mat& mask) {
  const int s = params_.stride;
  const int cols = grid_depth_.cols;
  const float step_abs = static_cast<float>(params_.max_step_abs_m);
  const float step_relative = static_cast<float>(params_.max_step_relative);
  const float not_painted = std::numeric_limits<float>::quiet_NaN();
  fill_sample_.resize(static_cast<size_t>(depth.cols));
  fill_step_.resize(static_cast<size_t>(depth.cols));
  const auto painted = [&](int region) {
    return region >= 0 && region_seeds_[region] >= params_.min_seeds_per_region;
  };
  for (int gy = grown.min_y; gy <= grown.max_y; ++gy) {
    const int* regions = region_of_.data() + static_cast<size_t>(gy) * cols;
    int first = grown.min_x;
    while (first <= grown.max_x && !painted(regions[first])) ++first;
    if (first > grown.max_x) continue;
    int last = grown.max_x;
    while (!painted(regions[last])) --last;
    const float* samples = grid_depth_.ptr<float>(gy);
    const int x0 = first * s, x1 = std::min(depth.cols, (last + 1) * s);
    for (int gx = first; gx <= last; ++gx) {
      const float value = painted(regions[gx]) ? samples[gx] : not_painted;
      const int begin = gx * s, count = std::min(x1, begin + s) - begin;
      std::fill_n(fill_sample_.begin() + begin, count, value);
      std::fill_n(fill_step_.begin() + begin, count, step_abs + step_relative * value);
    }
    const float* block_samples = fill_sample_.data();
    const float* block_steps = fill_step_.data();
    for (int y = gy * s; y < std::min(depth.rows, (gy + 1) * s); ++y) {
      const float* row = depth.ptr<float>(y);
      std::uint8_t* out = mask.ptr<std::uint8_t>(y);
      for (int x = x0; x < x1; ++x) {
        // Bitwise &, not &&: no branch, so the loop vectorises.
        const bool joins =
            (row[x] > 0.0f) & (std::abs(row[x] - block_samples[x]) <= block_steps[x]);
        out[x] = static_cast<std::uint8_t>(-static_cast<int>(joins));
      }
    }
  }
}

}  // namespace pspslam
