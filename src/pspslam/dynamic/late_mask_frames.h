#pragma once

#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>

#include "pspslam/core/types.h"

namespace pspslam {

// A frame a live run handed to the semantic thread, as tracking left it.
struct SegmentedFrame {
  std::int64_t id = 0;
  std::uint32_t map_id = 0;  // poses of another map of the atlas are in another world frame
  Pose T_world_camera;
  cv::Mat depth;  // shared, not copied: frames are loaded fresh and never written to
};

// A live run's segmented frames until their masks arrive, frames after the frame was tracked. A
// mask is exact for its own frame only, so it is judged there: at that frame's pose and depth
// (DynamicOptions::cull_with_late_masks).
class LateMaskFrames {
 public:
  // A mask older than `capacity` segmented frames is not waited for.
  explicit LateMaskFrames(size_t capacity = 64) : capacity_(capacity) {}

  // Frames must come in increasing id order.
  void remember(SegmentedFrame frame);

  // The frame a mask arrived for, the first time it arrives, or nothing. Frames older than it
  // are forgotten: the thread works on the newest frame, so it skipped them.
  std::optional<SegmentedFrame> take(std::int64_t frame_id);

 private:
  size_t capacity_;
  std::deque<SegmentedFrame> frames_;  // oldest first
};

}  // namespace pspslam
