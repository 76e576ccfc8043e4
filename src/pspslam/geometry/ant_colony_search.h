#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace pspslam {

class YamlSection;

enum class SearchStrategy {
  ant_colony,  // paper Fig. 6: test along a meandering path, grow convex hulls around finds
  exhaustive,  // DynaSLAM baseline: test every point
};

// Parameters of the reverse ant-colony search (paper III.C, Fig. 6). Defaults: docs/geometry.md.
struct AntColonyParams {
  SearchStrategy strategy = SearchStrategy::ant_colony;
  float search_radius_px = 12.0f;  // R: points within R of a path node K_i are tested
  float band_width_px = 80.0f;     // dZ: band around a community's convex hull tested per round
  // s: distance between consecutive nodes along a lane. 2R: the discs touch, so a lane still
  // covers a continuous strip (~2R tall at the nodes) with fewer points tested than at 16 px
  // (sweep in docs/geometry.md: tested 0.316 vs 0.336, kept 0.987 vs 0.990).
  float node_spacing_px = 24.0f;
  // Distance between the horizontal boustrophedon lanes of the path L. Lanes run across the
  // image, so a standing person (~220 px tall at 4 m; the gap between lane bands is
  // 128 - 2R = 104 px) always crosses one of them; alternate_lanes halves the gap over 2 frames.
  float lane_spacing_px = 128.0f;
  // Shift the lanes by half a lane spacing on every other run(): a mover the path passes by in
  // one frame lies on a lane of the next one, and once found it is followed by the priority
  // points (previous mask) instead of the path.
  bool alternate_lanes = true;
  int max_band_rounds = 256;  // safety bound; a round that finds nothing ends growth anyway

  // Reads the optional keys of a `search:` section (strategy: ant_colony | exhaustive).
  static AntColonyParams from_yaml(YamlSection& section);
  bool operator==(const AntColonyParams&) const = default;
};

struct SearchResult {
  std::vector<std::uint8_t> dynamic;  // 1 = tested and found dynamic; untested count as static
  std::vector<std::uint8_t> tested;
  int tested_count = 0;
  int dynamic_count = 0;
  int communities = 0;  // dynamic clusters grown from a path node or a priority point
  int band_rounds = 0;  // hull-band rounds over all communities
  // Tests made in the band rounds that found nothing (each community's last round): the most a
  // sparser last band could save.
  int last_band_tests = 0;
};

// Index of a candidate point -> is it dynamic (the multi-view test). Called at most once per point.
using PointPredicate = std::function<bool(int)>;

// Reusable searcher: buffers (grid buckets, hull, community) are kept between frames so a frame
// costs no allocation once sizes have settled. Not thread-safe; use one per worker thread.
class DynamicPointSearch {
 public:
  explicit DynamicPointSearch(AntColonyParams params = {});

  // `points` are pixel positions inside `image_size`. `priority` indices (e.g. points inside the
  // previous frame's dynamic mask warped by the compensated homography) are tested before the
  // path, each a potential community seed. The returned reference stays valid until the next run.
  const SearchResult& run(std::span<const Eigen::Vector2f> points, cv::Size image_size,
                          const PointPredicate& is_dynamic, std::span<const int> priority = {});

  const AntColonyParams& params() const { return params_; }

  // The path the last run() walked (nodes in walking order, pixels); empty after an exhaustive
  // run or one without points. For pictures of the search (the live viewer); valid until the
  // next run.
  std::span<const Eigen::Vector2f> last_path() const {
    return last_phase_ < 0 ? std::span<const Eigen::Vector2f>() : path_nodes_[last_phase_];
  }

 private:
  void build_grid(std::span<const Eigen::Vector2f> points, cv::Size image_size);
  void build_paths(cv::Size image_size);
  bool test(int index, const PointPredicate& is_dynamic);
  // Tests the untested points of one grid cell; `exact` = check each point against the band.
  template <typename InBand>
  void test_cell(int cell, std::span<const Eigen::Vector2f> points,
                 const PointPredicate& is_dynamic, const InBand& in_band);
  // Grows the community whose first dynamic points are in community_ until a band adds nothing.
  void grow_community(std::span<const Eigen::Vector2f> points, const PointPredicate& is_dynamic);
  // Reduces community_ to its convex hull and lays out the band's edges_; true when the hull is
  // a polygon (else the band is measured by distance to the hull).
  bool reduce_to_hull();
  // Tests the untested points in the band around the hull; the dynamic ones go to found_.
  void test_band(std::span<const Eigen::Vector2f> points, const PointPredicate& is_dynamic,
                 bool polygon);
  // Narrows [first, last] to the grid columns of `row` the band can reach (x_lo, x_hi: the
  // band's bounding box); false when it reaches none.
  bool clip_row(int row, float x_lo, float x_hi, int& first, int& last) const;
  enum class CellInBand { outside, inside, crossing };
  CellInBand classify_cell(int col, int row, bool polygon) const;

  AntColonyParams params_;
  SearchResult result_;
  // Grid buckets in compressed form: points of cell c are cell_points_[cell_start_[c] ..
  // cell_start_[c + 1]).
  float cell_size_ = 1.0f;
  int grid_cols_ = 0;
  int grid_rows_ = 0;
  std::vector<int> cell_start_;
  std::vector<int> cell_points_;
  std::vector<int> point_cell_;
  std::vector<int> cell_cursor_;
  std::vector<int> cell_untested_;
  cv::Size path_size_;
  // Two phases of the path (lanes shifted by half a lane spacing), used on alternate runs.
  std::vector<Eigen::Vector2f> path_nodes_[2];
  unsigned run_count_ = 0;
  int last_phase_ = -1;  // phase of the path the last run walked; -1: none
  std::vector<Eigen::Vector2f> community_;
  std::vector<Eigen::Vector2f> hull_;
  std::vector<Eigen::Vector2f> hull_scratch_;
  // Per hull edge: outward unit normal (x, y), offset + dZ (z), half the cell's extent along the
  // normal (w: a cell is wholly inside the band when its centre is w inside every edge line).
  std::vector<Eigen::Vector4f> edges_;
  std::vector<int> found_;
};

}  // namespace pspslam
