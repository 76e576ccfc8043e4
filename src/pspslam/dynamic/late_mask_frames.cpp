#include "pspslam/dynamic/late_mask_frames.h"

namespace pspslam {

void LateMaskFrames::remember(SegmentedFrame frame) {
  frames_.push_back(std::move(frame));
  while (frames_.size() > capacity_) frames_.pop_front();
}

std::optional<SegmentedFrame> LateMaskFrames::take(std::int64_t frame_id) {
  while (!frames_.empty() && frames_.front().id < frame_id) frames_.pop_front();
  if (frames_.empty() || frames_.front().id != frame_id) return std::nullopt;
  SegmentedFrame frame = std::move(frames_.front());
  frames_.pop_front();
  return frame;
}

}  // namespace pspslam
