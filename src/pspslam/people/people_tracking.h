#pragma once

#include <optional>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/people/people_tracker.h"
#include "pspslam/people/person_detector.h"

namespace pspslam {

// The people of one frame: the confirmed tracks seen in it (world frame of the run's map).
struct PeopleFrame {
  std::vector<TrackedPerson> people;
  bool observed = false;  // the frame had a fresh person mask, depth and a pose
  int instances = 0;      // person instances found in it (confirmed or not)
  double cpu_ms = 0.0;    // detection + tracking, this thread's CPU time
};

// Person instances of each frame linked into tracks (PersonDetector, PeopleTracker): what the
// tracking module runs after a frame's pose.
class PeopleTracking {
 public:
  PeopleTracking(const PinholeCamera& camera, int person_label, PersonDetectorParams detector = {},
                 PeopleTrackerParams tracker = {})
      : camera_(camera), person_label_(person_label), detector_(detector), tracker_(tracker) {}

  // `labels`: the class labels of this frame's own segmentation (empty when the frame has none,
  // e.g. a live run's stale mask: tracks then only coast); `depth`: CV_32FC1 metres (empty:
  // monocular); `T_world_camera`: the frame's pose (none: lost).
  PeopleFrame process(Timestamp timestamp, const cv::Mat& labels, const cv::Mat& depth,
                      const std::optional<Pose>& T_world_camera);
  // The map's world frame was replaced (a new map of the atlas): tracks in the old one end.
  void reset() { tracker_ = PeopleTracker(tracker_.params()); }

  const PeopleTracker& tracker() const { return tracker_; }

 private:
  PinholeCamera camera_;
  int person_label_;
  PersonDetector detector_;
  PeopleTracker tracker_;
};

}  // namespace pspslam
