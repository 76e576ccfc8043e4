#include "pspslam/session/start_watch.h"

#include <algorithm>

namespace pspslam {

bool StartWatch::update(const TrackResult& result) {
  if (result.state != TrackingState::kNotInitialized) started_ = true;
  if (started_ || result.keypoints_with_depth_needed == 0) return false;
  best_ = std::max(best_, result.keypoints_with_depth);
  needed_ = result.keypoints_with_depth_needed;
  return ++waiting_ == warn_after_;
}

std::string StartWatch::reason() const {
  return "no map after " + std::to_string(waiting_) + " frames: the best frame had " +
         std::to_string(best_) + " keypoints with a depth reading, " + std::to_string(needed_) +
         " are needed to start one (are the depth images listed in depth.txt empty?)";
}

}  // namespace pspslam
