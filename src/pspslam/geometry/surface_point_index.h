#pragma once

#include <Eigen/Core>
#include <array>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam {

// The dynamic points found so far in a frame, for the question "does this untested point
// continue the surface of a dynamic point right beside it?" (within `radius_px` in the image and
// one depth step of the region grower, abs + relative * depth, of that point's depth). Region
// growing would grow such a point's surface from the found point anyway, so the ant colony can
// hand it to region growing as a seed instead of testing it (docs/geometry.md, "Implied points").
// Bucketed on a grid of radius_px cells, a fixed number of points per cell: no allocation per
// point once the grid is sized. Not thread-safe; one per worker thread.
class SurfacePointIndex {
 public:
  SurfacePointIndex(float radius_px, double max_step_abs_m, double max_step_relative);

  void reset(cv::Size image_size);  // forgets every point; once per frame
  void add(const Eigen::Vector2f& pixel, float depth);
  // True when a point added earlier lies within radius_px of `pixel` and `depth` is within one
  // depth step of that point's depth. A point without depth (<= 0) continues nothing.
  bool continues(const Eigen::Vector2f& pixel, float depth) const;
  // True when a point added earlier lies within `radius_px` of `pixel`, whatever its depth.
  bool any_within(const Eigen::Vector2f& pixel, float radius_px) const;

 private:
  // A cell keeps the first few points added in it: in a cell radius_px wide, more would add
  // little coverage (they are all within about one radius of each other).
  static constexpr int kPointsPerCell = 4;
  struct Found {
    float x, y, depth, step;
  };
  struct Cell {
    int count = 0;
    std::array<Found, kPointsPerCell> points;
  };
  int cell_index(float x, float y) const;

  float radius_px_;
  float radius2_;
  float step_abs_, step_relative_;
  int cols_ = 0, rows_ = 0;
  std::vector<Cell> cells_;
  std::vector<int> used_cells_;  // cells with points, cleared by reset()
};

}  // namespace pspslam
