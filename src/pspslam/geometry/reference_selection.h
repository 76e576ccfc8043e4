#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/geometry/multiview_test.h"

namespace pspslam {

// Chooses the reference views of the multi-view test (paper III.C: "the most overlapping earlier
// keyframes") from a larger pool. Greedy coverage: the first pick is the view that sees the most
// candidate points (DynaSLAM's rule); every further pick maximises the candidates it adds that
// fewer than `wanted_coverage` picks see yet, preferring older views among nearly equal gains;
// once all are covered that often, the remaining picks go by plain overlap. Why not the top-k by
// overlap: after a camera turn the k most overlapping views all miss the same newly visible strip,
// and a point no reference sees can never be found dynamic (docs/geometry.md, diagnosis of the
// synthetic misses). Reusable scratch buffers and a per-view cache; not thread-safe, one per worker
// thread.
class ReferenceSelector {
 public:
  // A candidate is "seen" by a view when it projects inside the view (with `border_px` margin)
  // onto a valid depth reading and the parallax is at most `max_parallax_deg`.
  // `point_stride` subsamples the candidates (coverage is a statistic; 1 = all).
  struct Params {
    int max_views = 5;
    int wanted_coverage = 2;
    int point_stride = 8;
    int border_px = 4;
    double max_parallax_deg = 30.0;
    // A pick goes to the oldest view (latest in the pool) whose gain is at least this share of
    // the best gain: older views give a mover more time to have left, which the depth test
    // needs. 1 = always the most covering view.
    double older_view_gain_share = 1.0;
  };

  ReferenceSelector(PinholeCamera camera, Params params);

  // Indices into `pool` of the chosen views (at most params.max_views, in pick order). When the
  // pool is not larger than max_views every view with a depth image is returned, in pool order.
  const std::vector<int>& select(const Pose& T_world_current,
                                 std::span<const CandidatePoint> points,
                                 std::span<const DepthView> pool);

 private:
  // Per pool view, one validity bit per 8x8 block of its depth image, built the first time the
  // view is seen (look-ups in the full-size depth images of every pool view would mostly miss
  // the cache). Packed bits: a pool's maps take a few kB, so the per-frame look-ups hit L1
  // instead of missing in byte maps 8 times larger.
  struct BlockValidity {
    int blocks_per_row = 0;
    std::vector<std::uint64_t> bits;  // bit by * blocks_per_row + bx: the block's centre is valid
    bool at_pixel(int x, int y) const;
  };
  struct CachedView {
    cv::Mat depth;  // shallow: keeps the buffer, and so the address used as key, alive
    BlockValidity valid;
    bool used = false;
  };
  const BlockValidity& validity(const cv::Mat& depth);
  // Back-projects every point_stride-th candidate with a depth into sampled_.
  void sample_candidates(std::span<const CandidatePoint> points);
  void mark_seen(const Pose& T_world_current, std::span<const DepthView> pool);
  // Greedy picks of the views that add the most coverage, into chosen_.
  void pick_views(std::span<const DepthView> pool);

  PinholeCamera camera_;
  Params params_;
  std::vector<CachedView> cache_;
  std::vector<Eigen::Vector3d> sampled_;  // back-projected sampled candidates
  std::vector<double> sampled_norms_;     // their distances from the camera (parallax test)
  std::vector<std::uint8_t> seen_;        // pool view x sampled point
  std::vector<int> coverage_;             // picks that see each sampled point
  std::vector<std::uint8_t> picked_;
  std::vector<long> gains_;
  std::vector<int> chosen_;
};

}  // namespace pspslam
