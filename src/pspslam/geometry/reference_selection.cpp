#include "pspslam/geometry/reference_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pspslam {
namespace {

// Validity maps sample one depth pixel per kBlock x kBlock block.
constexpr int kBlock = 8;

}  // namespace

ReferenceSelector::ReferenceSelector(PinholeCamera camera, Params params)
    : camera_(camera), params_(params) {}

bool ReferenceSelector::BlockValidity::at_pixel(int x, int y) const {
  const int block = (y / kBlock) * blocks_per_row + x / kBlock;
  return (bits[static_cast<size_t>(block) >> 6] >> (block & 63)) & 1u;
}

const ReferenceSelector::BlockValidity& ReferenceSelector::validity(const cv::Mat& depth) {
  for (CachedView& view : cache_) {
    if (view.depth.data == depth.data && view.depth.size() == depth.size()) {
      view.used = true;
      return view.valid;
    }
  }
  // A keyframe stays in the pool for many frames: its map is built once. The cache holds a
  // shallow copy of the depth image, so the buffer (and thus its address) cannot be reused
  // while the entry exists.
  CachedView view{depth, {}, true};
  const int block_rows = (depth.rows + kBlock - 1) / kBlock;
  view.valid.blocks_per_row = (depth.cols + kBlock - 1) / kBlock;
  view.valid.bits.assign((static_cast<size_t>(block_rows) * view.valid.blocks_per_row + 63) / 64,
                         0);
  for (int by = 0; by < block_rows; ++by) {
    const float* row = depth.ptr<float>(std::min(by * kBlock + kBlock / 2, depth.rows - 1));
    for (int bx = 0; bx < view.valid.blocks_per_row; ++bx) {
      const size_t block = static_cast<size_t>(by) * view.valid.blocks_per_row + bx;
      if (row[std::min(bx * kBlock + kBlock / 2, depth.cols - 1)] > 0.0f)
        view.valid.bits[block >> 6] |= std::uint64_t{1} << (block & 63);
    }
  }
  cache_.push_back(std::move(view));
  return cache_.back().valid;
}

const std::vector<int>& ReferenceSelector::select(const Pose& T_world_current,
                                                  std::span<const CandidatePoint> points,
                                                  std::span<const DepthView> pool) {
  chosen_.clear();
  const int views = static_cast<int>(pool.size());
  if (views <= params_.max_views) {
    for (int v = 0; v < views; ++v)
      if (!pool[v].depth.empty()) chosen_.push_back(v);
    return chosen_;
  }
  sample_candidates(points);
  mark_seen(T_world_current, pool);
  pick_views(pool);
  return chosen_;
}

void ReferenceSelector::sample_candidates(std::span<const CandidatePoint> points) {
  // Back-project the sampled candidates once; each view then only transforms and projects.
  const size_t stride = static_cast<size_t>(std::max(1, params_.point_stride));
  sampled_.clear();
  sampled_norms_.clear();
  for (size_t i = 0; i < points.size(); i += stride) {
    if (points[i].depth > 0.0) {
      sampled_.push_back(camera_.unproject(points[i].pixel, points[i].depth));
      sampled_norms_.push_back(sampled_.back().norm());
    }
  }
}

// Per view and sampled candidate: the view sees it (in front, inside the border, on a depth
// reading, within the parallax limit).
void ReferenceSelector::mark_seen(const Pose& T_world_current, std::span<const DepthView> pool) {
  const int views = static_cast<int>(pool.size());
  const size_t sampled = sampled_.size();
  seen_.assign(static_cast<size_t>(views) * sampled, 0);
  const double cos_max_parallax = std::cos(params_.max_parallax_deg * M_PI / 180.0);
  const double border = params_.border_px;
  for (CachedView& view : cache_) view.used = false;
  for (int v = 0; v < views; ++v) {
    const cv::Mat& depth = pool[v].depth;
    if (depth.empty()) continue;
    // A view without a depth reading there (beyond the sensor's range, a hole) cannot test the
    // point: leaving this check out cost 0.14 of the test's recall (docs/geometry.md).
    const BlockValidity& valid = validity(depth);
    const Pose T_ref_current = pool[v].T_world_camera.inverse() * T_world_current;
    const Eigen::Matrix3d R = T_ref_current.linear();
    const Eigen::Vector3d t = T_ref_current.translation();
    // Reference camera centre in current coordinates, for the parallax angle.
    const Eigen::Vector3d centre = -(R.transpose() * t);
    std::uint8_t* seen = seen_.data() + static_cast<size_t>(v) * sampled;
    for (size_t s = 0; s < sampled; ++s) {
      const Eigen::Vector3d& p = sampled_[s];
      const Eigen::Vector3d q = R * p + t;
      if (q.z() <= 0.1) continue;
      const Eigen::Vector2d pixel = camera_.project(q);
      if (!(pixel.x() >= border && pixel.y() >= border && pixel.x() < depth.cols - border &&
            pixel.y() < depth.rows - border))
        continue;
      if (!valid.at_pixel(static_cast<int>(pixel.x()), static_cast<int>(pixel.y()))) continue;
      const Eigen::Vector3d ray = p - centre;
      if (p.dot(ray) < cos_max_parallax * sampled_norms_[s] * ray.norm()) continue;
      seen[s] = 1;
    }
  }
  // Views that left the pool leave the cache (and release their depth images).
  std::erase_if(cache_, [](const CachedView& view) { return !view.used; });
}

void ReferenceSelector::pick_views(std::span<const DepthView> pool) {
  const int views = static_cast<int>(pool.size());
  const size_t sampled = sampled_.size();
  coverage_.assign(sampled, 0);
  picked_.assign(static_cast<size_t>(views), 0);
  gains_.assign(static_cast<size_t>(views), 0);
  // Once every candidate has its wanted coverage, the remaining picks go by plain overlap: each
  // further reference is one more moment at which a mover may have been elsewhere.
  int wanted = params_.wanted_coverage;
  for (int pick = 0; pick < params_.max_views; ++pick) {
    long best_gain = 0;
    for (int attempt = 0; attempt < 2 && best_gain == 0; ++attempt) {
      if (attempt == 1) wanted = std::numeric_limits<int>::max();
      for (int v = 0; v < views; ++v) {
        gains_[v] = 0;
        if (picked_[v] || pool[v].depth.empty()) continue;
        const std::uint8_t* seen = seen_.data() + static_cast<size_t>(v) * sampled;
        long gain = 0;
        // Bitwise &: no branch per point, so this hot loop vectorises.
        for (size_t s = 0; s < sampled; ++s) gain += seen[s] & (coverage_[s] < wanted);
        gains_[v] = gain;
        best_gain = std::max(best_gain, gain);
      }
    }
    if (best_gain == 0) break;  // no remaining view sees any candidate
    // The pool is ordered newest first: the last view within the gain share is the oldest.
    int choice = -1;
    for (int v = 0; v < views; ++v) {
      if (!picked_[v] && !pool[v].depth.empty() &&
          static_cast<double>(gains_[v]) >= params_.older_view_gain_share * best_gain)
        choice = v;
    }
    picked_[choice] = 1;
    chosen_.push_back(choice);
    const std::uint8_t* seen = seen_.data() + static_cast<size_t>(choice) * sampled;
    for (size_t s = 0; s < sampled; ++s) coverage_[s] += seen[s];
  }
}

}  // namespace pspslam
