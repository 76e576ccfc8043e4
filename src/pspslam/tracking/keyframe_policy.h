#pragma once

#include <cstdint>

namespace pspslam {

// ORB-SLAM2's RGB-D keyframe criteria, as a pure function of one frame's tracking statistics.
struct KeyFramePolicyOptions {
  int min_frames_between = 0;   // frames since the last keyframe before an idle mapper may get one
  int max_frames_between = 30;  // frames after which a keyframe is due (camera fps)
  int max_queued_keyframes = 3;
  int close_tracked_limit = 100;  // fewer tracked close points than this ...
  int close_untracked_min = 70;   // ... and more untracked close ones: need a keyframe
  // A keyframe is wanted when the frame tracks fewer than this share of the reference keyframe's
  // points (ORB-SLAM2: 0.75 for RGB-D). Denser keyframes lower the ATE of a slow hand-held camera
  // at the price of more local BA time (docs/decisions/keyframe-policy.md; `pspslam run
  // --keyframe-ratio` sets it).
  double tracked_ratio_to_reference = 0.9;
  double tracked_ratio_to_reference_first_keyframes = 0.4;  // while the map has < 2 keyframes
  // A keyframe once max_frames_between frames have passed, whatever the ratio says. ORB-SLAM2
  // gates even a due keyframe on the ratio, and its reference count (the reference keyframe's
  // points seen by >= 3 keyframes) shrinks with the keyframe density itself on a camera that
  // keeps exploring: sparser keyframes, fewer points seen by three of them, a lower threshold,
  // sparser keyframes. Without this rule the frames between sparse keyframes, tracked from an
  // ageing local map, end well off the keyframes; with it loop sequences gain. Off by default: on
  // the real clip it is not a clear gain (docs/decisions/due-keyframes.md). `pspslam run
  // --due-keyframes` sets it.
  bool insert_when_due = false;
  // A wanted keyframe (the ratio test) is also inserted while the mapper is busy, as long as
  // nothing waits in its queue; the bundle adjustment in progress is cut short for it. ORB-SLAM2
  // waits for an idle mapper unless a keyframe is due or tracking is weak. A deterministic run
  // always meets an idle mapper (it waits for local mapping), so this changes nothing there; a
  // real-time run rarely meets one and would make far fewer keyframes than a deterministic run of
  // the same clip; inserting while mapping keeps them dense and lowers the online ATE
  // (docs/decisions/realtime-nice.md).
  bool insert_while_mapping = true;
};

struct KeyFrameEvidence {
  std::uint64_t frame_id = 0;
  std::uint64_t last_keyframe_frame_id = 0;
  std::uint64_t last_relocalisation_frame_id = 0;
  int keyframes_in_map = 0;
  int tracked_inliers = 0;           // matched map points after local map tracking
  int reference_tracked_points = 0;  // points of the reference keyframe with enough observations
  int tracked_close_points = 0;      // depth in (0, depth_threshold) and matched
  int untracked_close_points = 0;    // depth in (0, depth_threshold) and unmatched
  bool mapper_idle = true;
  int mapper_queue = 0;
};

enum class KeyFrameDecision {
  kSkip,
  kInsert,
  kInsertInterruptingMapper,  // wanted while the mapper is busy: stop its BA, queue the keyframe
  kInterruptMapper,           // wanted, queue full: stop its BA, try again next frame
};

KeyFrameDecision decide_keyframe(const KeyFrameEvidence& evidence,
                                 const KeyFramePolicyOptions& options);

}  // namespace pspslam
