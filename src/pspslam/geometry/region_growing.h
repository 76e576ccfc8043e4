#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <opencv2/core.hpp>
#include <span>
#include <utility>
#include <vector>

namespace pspslam {

class YamlSection;

// Growing dynamic keypoints into dynamic regions on the current depth image (paper III.C: whole
// objects, including an object a person carries, are masked, not only their keypoints).
struct RegionGrowParams {
  bool enabled = true;
  // Growth runs on a grid of one depth sample per stride x stride block (speed; the mask is then
  // filled block-wise at full resolution).
  int stride = 4;
  // Neighbouring samples belong to the same surface when their depths differ by at most
  // abs + relative * depth (depth continuity).
  double max_step_abs_m = 0.03;
  double max_step_relative = 0.01;
  // A region stays within this distance in depth of the seed that started it: stops the classic
  // leak from a person's feet along the floor.
  double max_depth_from_seed_m = 0.3;
  // Bounded growth: a seed only claims samples within this image distance of itself. A wrong
  // seed on a wall then marks a small disc, not the wall; a person is covered by many seeds.
  float max_grow_radius_px = 60.0f;
  // The same bound in metres at the seed's depth, used where it is larger than the pixel bound
  // (0 = off): a person 1 m away is four times larger in the image than one 4 m away, so a pixel
  // radius either leaves near people half-masked or lets far seeds leak. Needs the focal length.
  float max_grow_radius_m = 0.5f;
  // A grown region is kept only when at least this many dynamic seeds fall inside it, so one
  // isolated false detection does not mask anything beyond its own keypoint.
  int min_seeds_per_region = 2;
  // Safety bound on samples per seed region.
  int max_region_samples = 40000;
  // Grid samples within this radius (pixels) of a point verified static are barriers.
  float static_barrier_radius_px = 0.0f;
  // Dilation of the mask (pixels). 0 by default: the fill is already pixel-exact and a margin
  // turns background keypoints along every silhouette into false positives (docs/geometry.md);
  // margins for map exclusion belong in fuse_dynamic_masks().
  int dilation_px = 0;

  static RegionGrowParams from_yaml(YamlSection& section);
  bool operator==(const RegionGrowParams&) const = default;
};

// Reusable grower (buffers kept between frames). Not thread-safe; one per worker thread.
class DynamicRegionGrower {
 public:
  // `focal_length_px` converts max_grow_radius_m into pixels (0: the metric bound is unused).
  explicit DynamicRegionGrower(RegionGrowParams params = {}, float focal_length_px = 0.0f);

  // Writes `mask` (CV_8UC1, depth's size, 255 = dynamic). Seeds are pixels of dynamic points
  // with their measured depths (a seed starts at a grid sample on its own surface, never on the
  // background just beside an object edge); `static_points` are pixels of points verified static
  // (barriers when the radius is > 0).
  void grow(const cv::Mat& depth, std::span<const Eigen::Vector2f> seeds,
            std::span<const float> seed_depths, std::span<const Eigen::Vector2f> static_points,
            cv::Mat& mask);

  const RegionGrowParams& params() const { return params_; }

 private:
  // Grid cells in a bounding box.
  struct GridBox {
    int min_x, max_x, min_y, max_y;
    void add(int x, int y) {
      min_x = std::min(min_x, x);
      max_x = std::max(max_x, x);
      min_y = std::min(min_y, y);
      max_y = std::max(max_y, y);
    }
  };
  // The grid cell a seed starts on (x < 0: none) and its depth's distance from the seed's.
  struct StartCell {
    int x, y;
    float gap;
  };

  // Lays the grid out for `depth`, unclaims the cells of the last call and marks the barriers.
  void reset_grid(const cv::Mat& depth, std::span<const Eigen::Vector2f> static_points);
  // Grid row `gy`, sampled from `depth` the first time it is asked for.
  const float* sampled_row(const cv::Mat& depth, int gy);
  StartCell start_cell(const cv::Mat& depth, const Eigen::Vector2f& seed, float wanted);
  // Grows a new region from grid cell (sx, sy), widening `grown` by its cells.
  void grow_region(const cv::Mat& depth, int sx, int sy, GridBox& grown);
  // Paints the supported regions into `mask` at full resolution.
  void fill_mask(const cv::Mat& depth, const GridBox& grown, cv::Mat& mask);

  RegionGrowParams params_;
  float focal_length_px_ = 0.0f;
  cv::Mat grid_depth_;                     // CV_32F, one sample per block, read a row at a time
  std::vector<std::uint8_t> row_sampled_;  // per grid row: grid_depth_ holds its samples
  std::vector<int> region_of_;             // -1 = not visited; otherwise seed region id
  cv::Rect claimed_;                       // grid cells the last call may have claimed
  int claimed_cols_ = 0;                   // grid width region_of_ was laid out for
  std::vector<int> region_seeds_;          // dynamic seeds that fell inside each region
  std::vector<std::uint8_t> barrier_;
  std::vector<std::pair<int, int>> queue_;  // grid (x, y) of cells to expand
  std::vector<float> fill_sample_;          // per pixel column: its block's sample (NaN: not grown)
  std::vector<float> fill_step_;            // per pixel column: its block's continuity step
};

}  // namespace pspslam
