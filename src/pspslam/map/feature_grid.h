#pragma once

#include <cstdint>
#include <opencv2/core/types.hpp>
#include <vector>

namespace pspslam {

// Bucket index of keypoints over the image for radius queries (matching by projection).
// Stored as one sorted index array plus per-cell offsets (CSR), so building it costs two
// allocations whatever the number of keypoints, and copying it into a keyframe is cheap.
class FeatureGrid {
 public:
  static constexpr int kCols = 64;
  static constexpr int kRows = 48;

  FeatureGrid() = default;
  // Keypoints outside [min_x,max_x) x [min_y,max_y) are left out of the grid.
  FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, double min_x, double max_x, double min_y,
              double max_y);

  // Appends to `out` (cleared first) the indices of keypoints within a square of half-size
  // `radius` around (x, y) whose octave is in [min_level, max_level] (max_level < 0: any).
  void query(const std::vector<cv::KeyPoint>& keypoints, double x, double y, double radius,
             int min_level, int max_level, std::vector<int>& out) const;

 private:
  double min_x_ = 0.0;
  double min_y_ = 0.0;
  double inv_cell_width_ = 0.0;
  double inv_cell_height_ = 0.0;
  std::vector<std::uint32_t> cell_start_;  // kCols*kRows + 1 offsets into indices_
  std::vector<std::uint32_t> indices_;
};

}  // namespace pspslam
