#include "pspslam/dynamic/mask_warper.h"

#include "pspslam/geometry/compensated_homography.h"

namespace pspslam {

void HomographyChain::record(std::int64_t frame_id,
                             const std::optional<Eigen::Matrix3d>& H_previous_to_current) {
  if (!steps_.empty() && steps_.back().frame_id + 1 != frame_id) steps_.clear();
  steps_.push_back({frame_id, H_previous_to_current});
  while (steps_.size() > capacity_) steps_.pop_front();
}

std::optional<Eigen::Matrix3d> HomographyChain::between(std::int64_t from_id,
                                                        std::int64_t to_id) const {
  if (from_id == to_id) return Eigen::Matrix3d::Identity();
  if (from_id > to_id || steps_.empty()) return std::nullopt;
  // Steps from_id+1 .. to_id must all be present.
  const std::int64_t first = steps_.front().frame_id;
  if (from_id + 1 < first || to_id > steps_.back().frame_id) return std::nullopt;
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  for (std::int64_t id = from_id + 1; id <= to_id; ++id) {
    const Step& step = steps_[static_cast<size_t>(id - first)];
    if (!step.H) return std::nullopt;
    H = *step.H * H;  // later steps apply after earlier ones
  }
  H /= H(2, 2);
  return H;
}

WarpedMask warp_mask_to_frame(const cv::Mat& mask, std::int64_t mask_frame_id,
                              std::int64_t current_id, const HomographyChain& chain) {
  WarpedMask out;
  out.age_frames = static_cast<int>(current_id - mask_frame_id);
  if (mask.empty()) return out;
  if (mask_frame_id == current_id) {
    out.mask = mask;
    return out;
  }
  const std::optional<Eigen::Matrix3d> H = chain.between(mask_frame_id, current_id);
  if (!H) return out;
  out.mask = warp_to_current(mask, *H, mask.size(), true);
  out.warped = true;
  return out;
}

}  // namespace pspslam
