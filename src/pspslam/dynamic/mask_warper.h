#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>

namespace pspslam {

// Frame-to-frame compensated homographies (paper eq. 10-11) of the recent frames, so that a mask
// computed for an older frame can be brought into the current one (real-time policy:
// segmentation is slower than tracking, so the newest mask is often a few frames old).
class HomographyChain {
 public:
  explicit HomographyChain(size_t capacity = 64) : capacity_(capacity) {}

  // H maps pixels of frame `frame_id - 1` to frame `frame_id`; nullopt when it could not be
  // estimated (the chain through this frame is then broken). Ids must increase by one; a gap
  // breaks the chain too.
  void record(std::int64_t frame_id, const std::optional<Eigen::Matrix3d>& H_previous_to_current);

  // H mapping frame `from_id` pixels to frame `to_id` pixels (product of the recorded steps);
  // identity when from == to; nullopt when a step is missing or too old.
  std::optional<Eigen::Matrix3d> between(std::int64_t from_id, std::int64_t to_id) const;

 private:
  struct Step {
    std::int64_t frame_id = 0;
    std::optional<Eigen::Matrix3d> H;
  };
  size_t capacity_;
  std::deque<Step> steps_;  // increasing frame ids
};

struct WarpedMask {
  cv::Mat mask;         // CV_8UC1 in the current frame, empty when none could be made
  int age_frames = 0;   // current frame id - the mask's frame id
  bool warped = false;  // false: the mask is the current frame's own (or copied unwarped)
};

// Brings `mask` (computed for frame `mask_frame_id`) into frame `current_id` through `chain`
// (nearest neighbour, no invented values). When the chain is broken the mask is dropped rather
// than used misaligned: an unaligned person mask would hide static structure and keep the person.
WarpedMask warp_mask_to_frame(const cv::Mat& mask, std::int64_t mask_frame_id,
                              std::int64_t current_id, const HomographyChain& chain);

}  // namespace pspslam
