#include "pspslam/geometry/multiview_test.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"

namespace pspslam {

MultiViewParams MultiViewParams::from_yaml(YamlSection& section) {
  MultiViewParams p;
  p.depth_threshold_abs_m = section.optional("depth_threshold_abs_m", p.depth_threshold_abs_m);
  section.require(p.depth_threshold_abs_m >= 0.0, "depth_threshold_abs_m", "must be >= 0");
  p.depth_threshold_relative =
      section.optional("depth_threshold_relative", p.depth_threshold_relative);
  section.require(p.depth_threshold_relative >= 0.0, "depth_threshold_relative", "must be >= 0");
  section.require(p.depth_threshold_abs_m + p.depth_threshold_relative > 0.0,
                  "depth_threshold_relative", "and depth_threshold_abs_m cannot both be 0");
  const std::string disagreement = section.optional<std::string>("disagreement", "farther_only");
  if (disagreement == "farther_only") {
    p.disagreement = DepthDisagreement::farther_only;
  } else if (disagreement == "either_sign") {
    p.disagreement = DepthDisagreement::either_sign;
  } else {
    throw section.invalid("disagreement",
                          "must be farther_only or either_sign, not '" + disagreement + "'");
  }
  p.max_parallax_deg = section.optional("max_parallax_deg", p.max_parallax_deg);
  section.require(p.max_parallax_deg > 0.0 && p.max_parallax_deg <= 180.0, "max_parallax_deg",
                  "must be in (0, 180]");
  p.reference_patch_radius = section.optional("reference_patch_radius", p.reference_patch_radius);
  section.require(p.reference_patch_radius >= 0 && p.reference_patch_radius <= 10,
                  "reference_patch_radius", "must be in [0, 10]");
  p.min_dynamic_vote_fraction =
      section.optional("min_dynamic_vote_fraction", p.min_dynamic_vote_fraction);
  section.require(p.min_dynamic_vote_fraction > 0.0 && p.min_dynamic_vote_fraction <= 1.0,
                  "min_dynamic_vote_fraction", "must be in (0, 1]");
  p.max_reference_views = section.optional("max_reference_views", p.max_reference_views);
  section.require(p.max_reference_views >= 1, "max_reference_views", "must be >= 1");
  p.min_depth_m = section.optional("min_depth_m", p.min_depth_m);
  section.require(p.min_depth_m > 0.0, "min_depth_m", "must be > 0");
  p.max_depth_m = section.optional("max_depth_m", p.max_depth_m);
  section.require(p.max_depth_m > p.min_depth_m, "max_depth_m", "must be > min_depth_m");
  section.finish();
  return p;
}

MultiViewTest::MultiViewTest(PinholeCamera camera, MultiViewParams params)
    : camera_(camera), params_(params) {
  cos_max_parallax_ = std::cos(params_.max_parallax_deg * M_PI / 180.0);
}

void MultiViewTest::set_frame(const Pose& T_world_current, std::span<const DepthView> references) {
  references_.clear();
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
                           T_current_ref.translation(), view.depth});
  }
}

MultiViewVerdict MultiViewTest::evaluate(const CandidatePoint& point) const {
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
    // centre settles it for most static points (one read). Otherwise the whole patch is scanned
    // without a data-dependent branch: its 2r+1 rows lie in different cache lines, and a
    // branch-free scan issues their loads together instead of one after another (a dynamic point
    // must read every pixel anyway: "every valid pixel disagrees"). Per-reference cached 8x8-block
    // depth bounds, to settle dynamic votes without the scan, do not pay for their upkeep
    // (docs/geometry.md).
    const float centre = ref.depth.ptr<float>(v)[u];
    bool consistent = centre > 0.0f && centre >= lower && centre <= upper;
    int valid_pixels = centre > 0.0f;
    if (!consistent) {
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
