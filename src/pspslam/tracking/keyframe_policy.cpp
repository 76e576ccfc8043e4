#include "pspslam/tracking/keyframe_policy.h"

namespace pspslam {

KeyFrameDecision decide_keyframe(const KeyFrameEvidence& e, const KeyFramePolicyOptions& o) {
  // Right after relocalisation the pose is fragile: no keyframe from it while the map is big.
  if (e.last_relocalisation_frame_id > 0 &&
      e.frame_id < e.last_relocalisation_frame_id + o.max_frames_between &&
      e.keyframes_in_map > o.max_frames_between) {
    return KeyFrameDecision::kSkip;
  }
  const bool need_close = e.tracked_close_points < o.close_tracked_limit &&
                          e.untracked_close_points > o.close_untracked_min;
  const double ratio_threshold = e.keyframes_in_map < 2
                                     ? o.tracked_ratio_to_reference_first_keyframes
                                     : o.tracked_ratio_to_reference;
  const bool due = e.frame_id >= e.last_keyframe_frame_id + o.max_frames_between;
  const bool mapper_can_take_one = e.mapper_idle || (o.insert_while_mapping && e.mapper_queue == 0);
  const bool mapper_ready_and_allowed =
      e.frame_id >= e.last_keyframe_frame_id + o.min_frames_between && mapper_can_take_one;
  const bool weak = e.tracked_inliers < e.reference_tracked_points * 0.25 || need_close;
  const bool fewer_than_reference =
      (e.tracked_inliers < e.reference_tracked_points * ratio_threshold || need_close) &&
      e.tracked_inliers > 15;
  const bool due_anyway = o.insert_when_due && due && e.tracked_inliers > 15;
  if (!due_anyway && !((due || mapper_ready_and_allowed || weak) && fewer_than_reference)) {
    return KeyFrameDecision::kSkip;
  }
  if (e.mapper_idle) return KeyFrameDecision::kInsert;
  return e.mapper_queue < o.max_queued_keyframes ? KeyFrameDecision::kInsertInterruptingMapper
                                                 : KeyFrameDecision::kInterruptMapper;
}

}  // namespace pspslam
