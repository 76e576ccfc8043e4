#include "pspslam/map/feature_grid.h"

#include <algorithm>
#include <cmath>

namespace pspslam {

FeatureGrid::FeatureGrid(const std::vector<cv::KeyPoint>& keypoints, double min_x, double max_x,
                         double min_y, double max_y)
    : min_x_(min_x),
      min_y_(min_y),
      inv_cell_width_(kCols / (max_x - min_x)),
      inv_cell_height_(kRows / (max_y - min_y)) {
  constexpr int kCells = kCols * kRows;
  cell_start_.assign(kCells + 1, 0);
  // Two passes (count, then place) so the index array is allocated once.
  auto cell_of = [&](const cv::KeyPoint& kp) -> int {
    const int col = static_cast<int>(std::floor((kp.pt.x - min_x_) * inv_cell_width_));
    const int row = static_cast<int>(std::floor((kp.pt.y - min_y_) * inv_cell_height_));
    if (col < 0 || col >= kCols || row < 0 || row >= kRows) return -1;
    return row * kCols + col;
  };
  for (const cv::KeyPoint& kp : keypoints) {
    const int cell = cell_of(kp);
    if (cell >= 0) ++cell_start_[cell + 1];
  }
  for (int c = 0; c < kCells; ++c) cell_start_[c + 1] += cell_start_[c];
  indices_.resize(cell_start_[kCells]);
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int cell = cell_of(keypoints[i]);
    if (cell >= 0) indices_[fill[cell]++] = static_cast<std::uint32_t>(i);
  }
}

void FeatureGrid::query(const std::vector<cv::KeyPoint>& keypoints, double x, double y,
                        double radius, int min_level, int max_level, std::vector<int>& out) const {
  out.clear();
  if (cell_start_.empty()) return;
  const int min_col =
      std::max(0, static_cast<int>(std::floor((x - radius - min_x_) * inv_cell_width_)));
  const int max_col =
      std::min(kCols - 1, static_cast<int>(std::ceil((x + radius - min_x_) * inv_cell_width_)));
  const int min_row =
      std::max(0, static_cast<int>(std::floor((y - radius - min_y_) * inv_cell_height_)));
  const int max_row =
      std::min(kRows - 1, static_cast<int>(std::ceil((y + radius - min_y_) * inv_cell_height_)));
  if (min_col > max_col || min_row > max_row) return;
  const bool check_levels = min_level > 0 || max_level >= 0;
  for (int row = min_row; row <= max_row; ++row) {
    for (int col = min_col; col <= max_col; ++col) {
      const int cell = row * kCols + col;
      for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const std::uint32_t i = indices_[k];
        const cv::KeyPoint& kp = keypoints[i];
        if (check_levels) {
          if (kp.octave < min_level) continue;
          if (max_level >= 0 && kp.octave > max_level) continue;
        }
        if (std::abs(kp.pt.x - x) < radius && std::abs(kp.pt.y - y) < radius) {
          out.push_back(static_cast<int>(i));
        }
      }
    }
  }
}

}  // namespace pspslam
