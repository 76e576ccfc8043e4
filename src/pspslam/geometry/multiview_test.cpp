#include "pspslam/geometry/multiview_test.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pspslam/config/yaml_section.h"
#include "pspslam/core/error.h"

namespace pspslam {
namespace {

// Side of the blocks whose depth bounds are cached per reference (see CachedBounds).
constexpr int kBlock = 8;

void require(bool ok, const YamlSection& section, const std::string& key, const char* what) {
  if (!ok) throw Error(section.file() + ": key '" + section.qualified(key) + "' " + what);
}

}  // namespace

MultiViewParams MultiViewParams::from_yaml(YamlSection& section) {
  MultiViewParams p;
  p.depth_threshold_abs_m = section.optional("depth_threshold_abs_m", p.depth_threshold_abs_m);
  require(p.depth_threshold_abs_m >= 0.0, section, "depth_threshold_abs_m", "must be >= 0");
  p.depth_threshold_relative =
      section.optional("depth_threshold_relative", p.depth_threshold_relative);
  require(p.depth_threshold_relative >= 0.0, section, "depth_threshold_relative", "must be >= 0");
  require(p.depth_threshold_abs_m + p.depth_threshold_relative > 0.0, section,
          "depth_threshold_relative", "and depth_threshold_abs_m cannot both be 0");
  const std::string disagreement = section.optional<std::string>("disagreement", "farther_only");
  if (disagreement == "farther_only") {
    p.disagreement = DepthDisagreement::farther_only;
  } else if (disagreement == "either_sign") {
    p.disagreement = DepthDisagreement::either_sign;
  } else {
    throw Error(section.file() + ": key '" + section.qualified("disagreement") +
                "' must be farther_only or either_sign, not '" + disagreement + "'");
  }
  p.max_parallax_deg = section.optional("max_parallax_deg", p.max_parallax_deg);
  require(p.max_parallax_deg > 0.0 && p.max_parallax_deg <= 180.0, section, "max_parallax_deg",
          "must be in (0, 180]");
  p.reference_patch_radius = section.optional("reference_patch_radius", p.reference_patch_radius);
  require(p.reference_patch_radius >= 0 && p.reference_patch_radius <= 10, section,
          "reference_patch_radius", "must be in [0, 10]");
  p.min_dynamic_vote_fraction =
      section.optional("min_dynamic_vote_fraction", p.min_dynamic_vote_fraction);
  require(p.min_dynamic_vote_fraction > 0.0 && p.min_dynamic_vote_fraction <= 1.0, section,
          "min_dynamic_vote_fraction", "must be in (0, 1]");
  p.max_reference_views = section.optional("max_reference_views", p.max_reference_views);
  require(p.max_reference_views >= 1, section, "max_reference_views", "must be >= 1");
  p.min_depth_m = section.optional("min_depth_m", p.min_depth_m);
  require(p.min_depth_m > 0.0, section, "min_depth_m", "must be > 0");
  p.max_depth_m = section.optional("max_depth_m", p.max_depth_m);
  require(p.max_depth_m > p.min_depth_m, section, "max_depth_m", "must be > min_depth_m");
  section.finish();
  return p;
}

MultiViewTest::MultiViewTest(PinholeCamera camera, MultiViewParams params)
    : camera_(camera), params_(params) {
  cos_max_parallax_ = std::cos(params_.max_parallax_deg * M_PI / 180.0);
}

MultiViewTest::CachedBounds& MultiViewTest::bounds_for(const cv::Mat& depth) {
  for (const std::unique_ptr<CachedBounds>& entry : bounds_cache_) {
    if (entry->depth.data == depth.data && entry->depth.size() == depth.size()) {
      entry->used = true;
      return *entry;
    }
  }
  auto entry = std::make_unique<CachedBounds>();
  entry->depth = depth;
  entry->block_cols = (depth.cols + kBlock - 1) / kBlock;
  const int block_rows = (depth.rows + kBlock - 1) / kBlock;
  entry->blocks.assign(static_cast<size_t>(entry->block_cols) * block_rows,
                       {std::numeric_limits<float>::quiet_NaN(), 0.0f});
  entry->used = true;
  bounds_cache_.push_back(std::move(entry));
  return *bounds_cache_.back();
}

const MultiViewTest::BlockBounds& MultiViewTest::block(CachedBounds& bounds, int block_x,
                                                       int block_y) {
  BlockBounds& b = bounds.blocks[static_cast<size_t>(block_y) * bounds.block_cols + block_x];
  if (std::isnan(b.min)) {
    b = {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
    const int x0 = block_x * kBlock, x1 = std::min(bounds.depth.cols, x0 + kBlock);
    const int y1 = std::min(bounds.depth.rows, (block_y + 1) * kBlock);
    for (int y = block_y * kBlock; y < y1; ++y) {
      const float* row = bounds.depth.ptr<float>(y);
      for (int x = x0; x < x1; ++x) {
        if (!(row[x] > 0.0f)) continue;
        b.min = std::min(b.min, row[x]);
        b.max = std::max(b.max, row[x]);
      }
    }
  }
  return b;
}

void MultiViewTest::set_frame(const Pose& T_world_current, std::span<const DepthView> references) {
  references_.clear();
  for (const std::unique_ptr<CachedBounds>& entry : bounds_cache_) entry->used = false;
  const size_t count =
      std::min(references.size(), static_cast<size_t>(params_.max_reference_views));
  for (size_t i = 0; i < count; ++i) {
    const DepthView& view = references[i];
    if (view.depth.empty()) continue;
    if (view.depth.type() != CV_32FC1) {
      throw Error("MultiViewTest: reference depth must be CV_32FC1 metres");
    }
    const Pose T_ref_current = view.T_world_camera.inverse() * T_world_current;
    const Pose T_current_ref = T_ref_current.inverse();
    references_.push_back({T_ref_current.linear(), T_ref_current.translation(),
                           T_current_ref.translation(), view.depth, &bounds_for(view.depth)});
  }
  // Views that are no longer references leave the cache (and release their depth images).
  std::erase_if(bounds_cache_,
                [](const std::unique_ptr<CachedBounds>& entry) { return !entry->used; });
}

MultiViewVerdict MultiViewTest::evaluate(const CandidatePoint& point) {
  MultiViewVerdict verdict;
  if (!(point.depth >= params_.min_depth_m && point.depth <= params_.max_depth_m)) return verdict;
  const Eigen::Vector3d p_current = camera_.unproject(point.pixel, point.depth);
  const double current_ray_norm = p_current.norm();
  const int r = params_.reference_patch_radius;
  for (const Reference& ref : references_) {
    const Eigen::Vector3d p_ref = ref.R_ref_current * p_current + ref.t_ref_current;
    const double projected_depth = p_ref.z();
    if (projected_depth < params_.min_depth_m || projected_depth > params_.max_depth_m) continue;
    const Eigen::Vector2d pixel = camera_.project(p_ref);
    if (!(pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < ref.depth.cols &&
          pixel.y() < ref.depth.rows))
      continue;
    // Non-negative here, so truncation after +0.5 rounds (std::lround is a libm call).
    const int u = static_cast<int>(pixel.x() + 0.5);
    const int v = static_cast<int>(pixel.y() + 0.5);
    if (u < r || v < r || u >= ref.depth.cols - r || v >= ref.depth.rows - r) continue;
    // Parallax: angle at the point between the rays to the two camera centres.
    const Eigen::Vector3d ray_ref = p_current - ref.center_in_current;
    const double cos_parallax = p_current.dot(ray_ref) / (current_ray_norm * ray_ref.norm());
    if (cos_parallax < cos_max_parallax_) continue;
    const double threshold =
        params_.depth_threshold_abs_m + params_.depth_threshold_relative * projected_depth;
    // A pixel of the patch agrees when it is valid (> 0) and within [lower, upper]; farther_only
    // accepts anything closer than projected + threshold. Float bounds: 1e-7 relative, far below
    // the sensor's 0.2 mm depth quantisation.
    const float upper = static_cast<float>(projected_depth + threshold);
    const float lower = params_.disagreement == DepthDisagreement::farther_only
                            ? 0.0f
                            : static_cast<float>(projected_depth - threshold);
    // The reference agrees when any valid pixel of the patch is consistent with the point. The
    // centre settles it for most static points (one read); the cached block bounds settle most
    // dynamic votes (a dynamic point would otherwise read every pixel: "every valid pixel
    // disagrees"). What is left scans the whole patch without a data-dependent branch: its 2r+1
    // rows lie in different cache lines, and a branch-free scan issues their loads together.
    const float centre = ref.depth.ptr<float>(v)[u];
    bool consistent = centre > 0.0f && centre >= lower && centre <= upper;
    int valid_pixels = centre > 0.0f;
    bool settled = consistent;
    if (!consistent && centre > 0.0f) {
      // The centre is a valid disagreeing pixel. If every valid pixel of the blocks that contain
      // the patch lies outside [lower, upper], so does every pixel of the patch: dynamic vote.
      float block_min = std::numeric_limits<float>::infinity();
      float block_max = -std::numeric_limits<float>::infinity();
      for (int by = (v - r) / kBlock; by <= (v + r) / kBlock; ++by) {
        for (int bx = (u - r) / kBlock; bx <= (u + r) / kBlock; ++bx) {
          const BlockBounds& b = block(*ref.bounds, bx, by);
          block_min = std::min(block_min, b.min);
          block_max = std::max(block_max, b.max);
        }
      }
      settled = block_min > upper || block_max < lower;
    }
    if (!consistent && !settled) {
      int agree = 0;
      for (int dv = -r; dv <= r; ++dv) {
        const float* row = ref.depth.ptr<float>(v + dv) + (u - r);
        for (int k = 0; k <= 2 * r; ++k) {
          const float measured = row[k];
          valid_pixels |= measured > 0.0f;
          agree |= (measured > 0.0f) & (measured >= lower) & (measured <= upper);
        }
      }
      consistent = agree != 0;
    }
    if (valid_pixels == 0) continue;
    ++verdict.valid_references;
    if (!consistent) ++verdict.dynamic_votes;
    // With "any" (fraction reached by one vote) the first dynamic vote decides: no need to
    // look at the remaining references.
    if (verdict.dynamic_votes >= 1 &&
        params_.min_dynamic_vote_fraction * static_cast<double>(references_.size()) <= 1.0)
      break;
  }
  if (verdict.valid_references > 0) {
    const int needed = std::max(
        1, static_cast<int>(
               std::ceil(params_.min_dynamic_vote_fraction * verdict.valid_references - 1e-9)));
    verdict.dynamic = verdict.dynamic_votes >= needed;
  }
  return verdict;
}

}  // namespace pspslam
