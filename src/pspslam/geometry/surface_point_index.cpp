#include "pspslam/geometry/surface_point_index.h"

#include <algorithm>
#include <cmath>

#include "pspslam/core/error.h"

namespace pspslam {

SurfacePointIndex::SurfacePointIndex(float radius_px, double max_step_abs_m,
                                     double max_step_relative)
    : radius_px_(radius_px),
      radius2_(radius_px * radius_px),
      step_abs_(static_cast<float>(max_step_abs_m)),
      step_relative_(static_cast<float>(max_step_relative)) {
  if (!(radius_px > 0.0f)) throw Error("SurfacePointIndex: radius_px must be > 0");
}

void SurfacePointIndex::reset(cv::Size image_size) {
  const int cols = std::max(1, static_cast<int>(std::ceil(image_size.width / radius_px_)));
  const int rows = std::max(1, static_cast<int>(std::ceil(image_size.height / radius_px_)));
  if (cols != cols_ || rows != rows_) {
    cols_ = cols;
    rows_ = rows;
    cells_.assign(static_cast<size_t>(cols) * rows, Cell{});
  } else {
    for (int c : used_cells_) cells_[c].count = 0;
  }
  used_cells_.clear();
}

int SurfacePointIndex::cell_index(float x, float y) const {
  const int col = std::clamp(static_cast<int>(x / radius_px_), 0, cols_ - 1);
  const int row = std::clamp(static_cast<int>(y / radius_px_), 0, rows_ - 1);
  return row * cols_ + col;
}

void SurfacePointIndex::add(const Eigen::Vector2f& pixel, float depth) {
  if (!(depth > 0.0f) || cells_.empty()) return;
  const int index = cell_index(pixel.x(), pixel.y());
  Cell& cell = cells_[index];
  if (cell.count == kPointsPerCell) return;
  if (cell.count == 0) used_cells_.push_back(index);
  cell.points[cell.count++] = {pixel.x(), pixel.y(), depth, step_abs_ + step_relative_ * depth};
}

bool SurfacePointIndex::continues(const Eigen::Vector2f& pixel, float depth) const {
  if (!(depth > 0.0f) || used_cells_.empty()) return false;
  // Cells are radius_px wide, so every point within radius_px is in the 3x3 block around it.
  const int col = std::clamp(static_cast<int>(pixel.x() / radius_px_), 0, cols_ - 1);
  const int row = std::clamp(static_cast<int>(pixel.y() / radius_px_), 0, rows_ - 1);
  for (int r = std::max(0, row - 1); r <= std::min(rows_ - 1, row + 1); ++r) {
    for (int c = std::max(0, col - 1); c <= std::min(cols_ - 1, col + 1); ++c) {
      const Cell& cell = cells_[static_cast<size_t>(r) * cols_ + c];
      for (int k = 0; k < cell.count; ++k) {
        const Found& f = cell.points[k];
        const float dx = f.x - pixel.x(), dy = f.y - pixel.y();
        if (dx * dx + dy * dy <= radius2_ && std::abs(depth - f.depth) <= f.step) return true;
      }
    }
  }
  return false;
}

bool SurfacePointIndex::any_within(const Eigen::Vector2f& pixel, float radius_px) const {
  if (used_cells_.empty()) return false;
  const int reach = static_cast<int>(std::ceil(radius_px / radius_px_));
  const float radius2 = radius_px * radius_px;
  const int col = std::clamp(static_cast<int>(pixel.x() / radius_px_), 0, cols_ - 1);
  const int row = std::clamp(static_cast<int>(pixel.y() / radius_px_), 0, rows_ - 1);
  for (int r = std::max(0, row - reach); r <= std::min(rows_ - 1, row + reach); ++r) {
    for (int c = std::max(0, col - reach); c <= std::min(cols_ - 1, col + reach); ++c) {
      const Cell& cell = cells_[static_cast<size_t>(r) * cols_ + c];
      for (int k = 0; k < cell.count; ++k) {
        const float dx = cell.points[k].x - pixel.x(), dy = cell.points[k].y - pixel.y();
        if (dx * dx + dy * dy <= radius2) return true;
      }
    }
  }
  return false;
}

}  // namespace pspslam
