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
  // Implied points: an unvisited point within this distance of a dynamic point found earlier in
  // the frame, whose depth continues that point's surface (one region-growing depth step), is not
  // tested: GeometryStage gives it to region growing as a seed, as it would a tested dynamic
  // point (docs/geometry.md, "Implied points"). 0 = test every visited point.
  float implied_radius_px = 0.0f;
  // DEV: implied points (see run()) join their community's hull like found dynamic points.
  bool implied_join_community = true;
  bool implied_static = true;            // DEV
  int implied_static_min_valid = 0;      // DEV
  float implied_static_guard_px = 0.0f;  // DEV

  // Reads the optional keys of a `search:` section (strategy: ant_colony | exhaustive).
  static AntColonyParams from_yaml(YamlSection& section);
};

struct SearchResult {
  std::vector<std::uint8_t> dynamic;  // 1 = tested and found dynamic; untested count as static
  std::vector<std::uint8_t> tested;
  // Not tested because the caller's `implied` gave the verdict: 1 = dynamic (the point continues
  // the surface of a dynamic point found earlier), 2 = static; 0 = tested or not visited.
  std::vector<std::uint8_t> implied;
  int tested_count = 0;
  int implied_count = 0;         // implied dynamic
  int implied_static_count = 0;  // not tested, implied static (count as static like untested)
  int dynamic_count = 0;
  int communities = 0;  // dynamic clusters grown from a path node or a priority point
  int band_rounds = 0;  // hull-band rounds over all communities
  // Tests made in the band rounds that found nothing (each community's last round): the most a
  // sparser last band could save.
  int last_band_tests = 0;
};

// Index of a candidate point -> is it dynamic (the multi-view test). Called at most once per point.
using PointPredicate = std::function<bool(int)>;

// What a point's surroundings already say about it, so that it needs no test.
enum class ImpliedVerdict : std::uint8_t {
  none,     // unknown: test it
  dynamic,  // it continues the surface of a dynamic point found earlier
  static_,  // it continues the surface of a point tested static (and of no dynamic one)
};
using PointImplication = std::function<ImpliedVerdict(int)>;

// Reusable searcher: buffers (grid buckets, hull, community) are kept between frames so a frame
// costs no allocation once sizes have settled. Not thread-safe; use one per worker thread.
class DynamicPointSearch {
 public:
  explicit DynamicPointSearch(AntColonyParams params = {});

  // `points` are pixel positions inside `image_size`. `priority` indices (e.g. points inside the
  // previous frame's dynamic mask warped by the compensated homography) are tested before the
  // path, each a potential community seed. The returned reference stays valid until the next run.
  //
  // `implied` (optional, ant colony only) is asked before each test: a point it calls dynamic or
  // static is not tested and not visited again; an implied dynamic point counts as a find of its
  // community (its hull grows over it as over a tested one).
  const SearchResult& run(std::span<const Eigen::Vector2f> points, cv::Size image_size,
                          const PointPredicate& is_dynamic, std::span<const int> priority = {},
                          const PointImplication& implied = {});

  const AntColonyParams& params() const { return params_; }

 private:
  void build_grid(std::span<const Eigen::Vector2f> points, cv::Size image_size);
  void build_paths(cv::Size image_size);
  // Visits an unvisited point: implied (no test) or tested. Returns whether it counts as a find of
  // the current community (tested dynamic, or implied when implied points join communities).
  bool visit(int index);
  // Visits the unvisited points of one grid cell that pass `in_band`; finds go to found_.
  template <typename InBand>
  void visit_cell(int cell, std::span<const Eigen::Vector2f> points, const InBand& in_band);
  // Grows the community whose first dynamic points are in community_ until a band adds nothing.
  void grow_community(std::span<const Eigen::Vector2f> points);

  AntColonyParams params_;
  SearchResult result_;
  const PointPredicate* is_dynamic_ = nullptr;  // the predicates of the current run()
  const PointImplication* implied_ = nullptr;
  std::vector<std::uint8_t> visited_;  // tested or implied
  // Grid buckets in compressed form: points of cell c are cell_points_[cell_start_[c] ..
  // cell_start_[c + 1]).
  float cell_size_ = 1.0f;
  int grid_cols_ = 0;
  int grid_rows_ = 0;
  std::vector<int> cell_start_;
  std::vector<int> cell_points_;
  std::vector<int> point_cell_;
  std::vector<int> cell_cursor_;
  std::vector<int> cell_unvisited_;
  cv::Size path_size_;
  // Two phases of the path (lanes shifted by half a lane spacing), used on alternate runs.
  std::vector<Eigen::Vector2f> path_nodes_[2];
  unsigned run_count_ = 0;
  std::vector<Eigen::Vector2f> community_;
  std::vector<Eigen::Vector2f> hull_;
  std::vector<Eigen::Vector2f> hull_scratch_;
  // Per hull edge: outward unit normal (x, y), offset + dZ (z), half the cell's extent along the
  // normal (w: a cell is wholly inside the band when its centre is w inside every edge line).
  std::vector<Eigen::Vector4f> edges_;
  std::vector<int> found_;
};

}  // namespace pspslam
