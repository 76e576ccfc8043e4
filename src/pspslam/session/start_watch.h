#pragma once

#include <cstddef>
#include <string>

#include "pspslam/tracking/tracker.h"

namespace pspslam {

// Watches the frames before the first map. A sequence without depth readings never starts; the
// user is told so (once, after `warn_after` such frames, and again at the end) with the best
// frame's depth count, not left with an empty trajectory and no reason.
class StartWatch {
 public:
  explicit StartWatch(size_t warn_after) : warn_after_(warn_after) {}

  // True when this frame is the one after which to warn.
  bool update(const TrackResult& result);
  bool never_started() const { return !started_ && waiting_ > 0; }
  std::string reason() const;

 private:
  size_t warn_after_;
  size_t waiting_ = 0;
  int best_ = 0;
  int needed_ = 0;
  bool started_ = false;
};

}  // namespace pspslam
