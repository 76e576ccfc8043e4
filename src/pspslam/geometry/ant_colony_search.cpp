#include "pspslam/geometry/ant_colony_search.h"

#include <algorithm>
#include <cmath>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/geometry/convex_hull.h"

namespace pspslam {

AntColonyParams AntColonyParams::from_yaml(YamlSection& section) {
  AntColonyParams p;
  const std::string strategy = section.optional<std::string>("strategy", "ant_colony");
  if (strategy == "ant_colony") {
    p.strategy = SearchStrategy::ant_colony;
  } else if (strategy == "exhaustive") {
    p.strategy = SearchStrategy::exhaustive;
  } else {
    throw section.invalid("strategy", "must be ant_colony or exhaustive, not '" + strategy + "'");
  }
  p.search_radius_px = section.optional("search_radius_px", p.search_radius_px);
  section.require(p.search_radius_px > 0.0f, "search_radius_px", "must be > 0");
  p.band_width_px = section.optional("band_width_px", p.band_width_px);
  section.require(p.band_width_px > 0.0f, "band_width_px", "must be > 0");
  p.node_spacing_px = section.optional("node_spacing_px", p.node_spacing_px);
  section.require(p.node_spacing_px > 0.0f, "node_spacing_px", "must be > 0");
  p.lane_spacing_px = section.optional("lane_spacing_px", p.lane_spacing_px);
  section.require(p.lane_spacing_px > 0.0f, "lane_spacing_px", "must be > 0");
  p.alternate_lanes = section.optional("alternate_lanes", p.alternate_lanes);
  p.max_band_rounds = section.optional("max_band_rounds", p.max_band_rounds);
  section.require(p.max_band_rounds >= 1, "max_band_rounds", "must be >= 1");
  section.finish();
  return p;
}

DynamicPointSearch::DynamicPointSearch(AntColonyParams params) : params_(params) {}

void DynamicPointSearch::build_grid(std::span<const Eigen::Vector2f> points, cv::Size image_size) {
  // Cells of side 2R: a radius-R query touches at most 2x2 cells, and a hull band of a
  // person-sized community spans ~100 cells instead of ~400 with side R (the band scan, not the
  // path, dominated the search's own cost).
  cell_size_ = std::max(2.0f * params_.search_radius_px, 8.0f);
  grid_cols_ = std::max(1, static_cast<int>(std::ceil(image_size.width / cell_size_)));
  grid_rows_ = std::max(1, static_cast<int>(std::ceil(image_size.height / cell_size_)));
  const size_t cells = static_cast<size_t>(grid_cols_) * grid_rows_;
  cell_start_.assign(cells + 1, 0);
  point_cell_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const int col = std::clamp(static_cast<int>(points[i].x() / cell_size_), 0, grid_cols_ - 1);
    const int row = std::clamp(static_cast<int>(points[i].y() / cell_size_), 0, grid_rows_ - 1);
    point_cell_[i] = row * grid_cols_ + col;
    ++cell_start_[point_cell_[i] + 1];
  }
  for (size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  cell_points_.resize(points.size());
  // Untested points per cell: cells a community has exhausted are skipped without a look at
  // their points in later band rounds and path nodes.
  cell_untested_.resize(cells);
  for (size_t c = 0; c < cells; ++c) cell_untested_[c] = cell_start_[c + 1] - cell_start_[c];
  cell_cursor_.assign(cell_start_.begin(), cell_start_.end() - 1);
  for (size_t i = 0; i < points.size(); ++i) {
    cell_points_[cell_cursor_[point_cell_[i]]++] = static_cast<int>(i);
  }
}

void DynamicPointSearch::build_paths(cv::Size image_size) {
  if (image_size == path_size_ && !path_nodes_[0].empty()) return;
  path_size_ = image_size;
  // Boustrophedon path L from A (top-left) to B: lanes left-to-right then right-to-left, so
  // consecutive nodes K_i, K_{i+1} are always one node spacing apart (paper Fig. 6). Phase 1 is
  // the same path with every lane moved down by half a lane spacing.
  const float lane = params_.lane_spacing_px;
  for (int phase = 0; phase < 2; ++phase) {
    std::vector<Eigen::Vector2f>& nodes = path_nodes_[phase];
    nodes.clear();
    bool left_to_right = true;
    for (float y = lane / 2.0f + phase * lane / 2.0f; y < image_size.height; y += lane) {
      const size_t lane_start = nodes.size();
      for (float x = params_.node_spacing_px / 2.0f; x < image_size.width;
           x += params_.node_spacing_px)
        nodes.emplace_back(x, y);
      if (!left_to_right) std::reverse(nodes.begin() + static_cast<long>(lane_start), nodes.end());
      left_to_right = !left_to_right;
    }
  }
}

bool DynamicPointSearch::test(int index, const PointPredicate& is_dynamic) {
  result_.tested[index] = 1;
  ++result_.tested_count;
  if (!point_cell_.empty()) --cell_untested_[point_cell_[index]];
  const bool dynamic = is_dynamic(index);
  if (dynamic) {
    result_.dynamic[index] = 1;
    ++result_.dynamic_count;
  }
  return dynamic;
}

template <typename InBand>
void DynamicPointSearch::test_cell(int cell, std::span<const Eigen::Vector2f> points,
                                   const PointPredicate& is_dynamic, const InBand& in_band) {
  for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
    const int index = cell_points_[k];
    if (result_.tested[index] || !in_band(points[index])) continue;
    if (test(index, is_dynamic)) found_.push_back(index);
  }
}

void DynamicPointSearch::grow_community(std::span<const Eigen::Vector2f> points,
                                        const PointPredicate& is_dynamic) {
  ++result_.communities;
  for (int round = 0; round < params_.max_band_rounds; ++round) {
    ++result_.band_rounds;
    const int tested_before = result_.tested_count;
    const bool polygon = reduce_to_hull();
    found_.clear();
    test_band(points, is_dynamic, polygon);
    if (found_.empty()) {  // a band without new dynamic points ends this community
      result_.last_band_tests += result_.tested_count - tested_before;
      return;
    }
    for (int index : found_) community_.push_back(points[index]);
  }
}

bool DynamicPointSearch::reduce_to_hull() {
  const float band = params_.band_width_px;
  const float half_cell = cell_size_ / 2.0f;
  // The hull of (previous hull vertices + new finds) is the hull of every find so far, so the
  // community is reduced to its hull vertices each round: sorting stays cheap.
  convex_hull(community_, hull_scratch_, hull_);
  community_.assign(hull_.begin(), hull_.end());
  // Band membership: distance to the hull <= dZ. For a proper polygon the test is "every edge
  // line is within dZ" (the outward offset with mitred corners, a slightly larger band near
  // vertices): one dot product per edge with an early exit, instead of point-segment distances.
  const bool polygon = hull_.size() >= 3;
  edges_.clear();
  if (polygon) {
    for (size_t i = 0; i < hull_.size(); ++i) {
      const Eigen::Vector2f d = hull_[(i + 1) % hull_.size()] - hull_[i];
      const Eigen::Vector2f outward = Eigen::Vector2f(d.y(), -d.x()).normalized();
      edges_.emplace_back(outward.x(), outward.y(), outward.dot(hull_[i]) + band,
                          half_cell * (std::abs(outward.x()) + std::abs(outward.y())));
    }
  }
  return polygon;
}

void DynamicPointSearch::test_band(std::span<const Eigen::Vector2f> points,
                                   const PointPredicate& is_dynamic, bool polygon) {
  const float band = params_.band_width_px;
  const auto in_band = [&](const Eigen::Vector2f& p) {
    if (!polygon) return distance_to_convex_hull(hull_, p) <= band;
    for (const Eigen::Vector4f& e : edges_) {
      if (e.x() * p.x() + e.y() * p.y() > e.z()) return false;
    }
    return true;
  };
  const auto anywhere = [](const Eigen::Vector2f&) { return true; };
  Eigen::Vector2f lo = hull_[0], hi = hull_[0];
  for (const Eigen::Vector2f& v : hull_) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  lo.array() -= band;
  hi.array() += band;
  const int col0 = std::clamp(static_cast<int>(lo.x() / cell_size_), 0, grid_cols_ - 1);
  const int col1 = std::clamp(static_cast<int>(hi.x() / cell_size_), 0, grid_cols_ - 1);
  const int row0 = std::clamp(static_cast<int>(lo.y() / cell_size_), 0, grid_rows_ - 1);
  const int row1 = std::clamp(static_cast<int>(hi.y() / cell_size_), 0, grid_rows_ - 1);
  // The band is every untested point within dZ of the hull, interior included: points the hull
  // swallowed in one jump would otherwise never be tested. Whole grid cells are classified
  // first (outside / inside / crossing the band's edge), so only the points of crossing cells
  // are tested against the band one by one, and exhausted cells cost one counter look-up.
  for (int row = row0; row <= row1; ++row) {
    int first = col0, last = col1;
    if (polygon && !clip_row(row, lo.x(), hi.x(), first, last)) continue;
    for (int col = first; col <= last; ++col) {
      const int cell = row * grid_cols_ + col;
      if (cell_untested_[cell] == 0) continue;
      const CellInBand place = classify_cell(col, row, polygon);
      if (place == CellInBand::outside) continue;
      if (place == CellInBand::inside)
        test_cell(cell, points, is_dynamic, anywhere);
      else
        test_cell(cell, points, is_dynamic, in_band);
    }
  }
}

// The band is convex, so its cells in a row form one run: clip the row's x-range by every
// edge's half-plane (loosest over the row's height; crossing cells are exact in test_band).
bool DynamicPointSearch::clip_row(int row, float x_lo, float x_hi, int& first, int& last) const {
  const float y0 = row * cell_size_, y1 = y0 + cell_size_;
  for (const Eigen::Vector4f& e : edges_) {
    const float slack = e.z() - std::min(e.y() * y0, e.y() * y1);
    if (std::abs(e.x()) < 1e-6f) {
      if (slack < 0.0f) x_lo = x_hi + 1.0f;  // the whole row is beyond this edge
    } else if (e.x() > 0.0f) {
      x_hi = std::min(x_hi, slack / e.x());
    } else {
      x_lo = std::max(x_lo, slack / e.x());
    }
  }
  if (x_lo > x_hi) return false;
  first = std::max(first, static_cast<int>(x_lo / cell_size_));
  last = std::min(last, static_cast<int>(x_hi / cell_size_));
  return true;
}

DynamicPointSearch::CellInBand DynamicPointSearch::classify_cell(int col, int row,
                                                                 bool polygon) const {
  const float band = params_.band_width_px;
  const Eigen::Vector2f centre((col + 0.5f) * cell_size_, (row + 0.5f) * cell_size_);
  if (!polygon) {
    const float half_diagonal = cell_size_ / 2.0f * std::sqrt(2.0f);
    const float d = distance_to_convex_hull(hull_, centre);
    if (d - half_diagonal > band) return CellInBand::outside;
    return d + half_diagonal <= band ? CellInBand::inside : CellInBand::crossing;
  }
  bool inside = true;
  for (const Eigen::Vector4f& e : edges_) {
    const float excess = e.x() * centre.x() + e.y() * centre.y() - e.z();
    if (excess > e.w()) return CellInBand::outside;
    if (excess > -e.w()) inside = false;
  }
  return inside ? CellInBand::inside : CellInBand::crossing;
}

const SearchResult& DynamicPointSearch::run(std::span<const Eigen::Vector2f> points,
                                            cv::Size image_size, const PointPredicate& is_dynamic,
                                            std::span<const int> priority) {
  const size_t n = points.size();
  result_.dynamic.assign(n, 0);
  result_.tested.assign(n, 0);
  result_.tested_count = result_.dynamic_count = result_.communities = result_.band_rounds =
      result_.last_band_tests = 0;
  last_phase_ = -1;
  if (n == 0) return result_;

  if (params_.strategy == SearchStrategy::exhaustive) {
    point_cell_.clear();  // no grid bookkeeping in the baseline
    for (size_t i = 0; i < n; ++i) test(static_cast<int>(i), is_dynamic);
    return result_;
  }

  build_grid(points, image_size);
  build_paths(image_size);
  const int phase = params_.alternate_lanes ? static_cast<int>(run_count_++ & 1u) : 0;
  last_phase_ = phase;

  for (int index : priority) {
    if (index < 0 || static_cast<size_t>(index) >= n || result_.tested[index]) continue;
    if (!test(index, is_dynamic)) continue;
    community_.assign(1, points[index]);
    grow_community(points, is_dynamic);
  }

  const float radius2 = params_.search_radius_px * params_.search_radius_px;
  for (const Eigen::Vector2f& node : path_nodes_[phase]) {
    const float radius = params_.search_radius_px;
    const int col0 =
        std::clamp(static_cast<int>((node.x() - radius) / cell_size_), 0, grid_cols_ - 1);
    const int col1 =
        std::clamp(static_cast<int>((node.x() + radius) / cell_size_), 0, grid_cols_ - 1);
    const int row0 =
        std::clamp(static_cast<int>((node.y() - radius) / cell_size_), 0, grid_rows_ - 1);
    const int row1 =
        std::clamp(static_cast<int>((node.y() + radius) / cell_size_), 0, grid_rows_ - 1);
    found_.clear();
    const auto near_node = [&](const Eigen::Vector2f& p) {
      return (p - node).squaredNorm() <= radius2;
    };
    for (int r = row0; r <= row1; ++r) {
      for (int c = col0; c <= col1; ++c) {
        const int cell = r * grid_cols_ + c;
        if (cell_untested_[cell] != 0) test_cell(cell, points, is_dynamic, near_node);
      }
    }
    // A find leaves the path: grow this community's hull, then go on at K_{i+1}.
    if (found_.empty()) continue;
    community_.clear();
    for (int index : found_) community_.push_back(points[index]);
    grow_community(points, is_dynamic);
  }
  return result_;
}

}  // namespace pspslam
