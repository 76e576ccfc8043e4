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
  // at more local BA time: bonn_crowd_dev `full` 0.75 / 0.85 / 0.9 / 0.95 -> 22.0 / 18.7 / 16.6 /
  // 16.8 mm, synthetic static 600 frames 0.75 / 0.85 / 0.9 -> 4.2 / 3.3 / 3.2 mm
  // (docs/benchmarks.md, SLAM core; `pspslam run --keyframe-ratio` sets it).
  double tracked_ratio_to_reference = 0.9;
  double tracked_ratio_to_reference_first_keyframes = 0.4;  // while the map has < 2 keyframes
  // A keyframe once max_frames_between frames have passed, whatever the ratio says. ORB-SLAM2
  // gates even a due keyframe on the ratio, and its reference count (the reference keyframe's
  // points seen by >= 3 keyframes) shrinks with the keyframe density itself on a camera that
  // keeps exploring: sparser keyframes, fewer points seen by three of them, a lower threshold,
  // sparser keyframes. On the synthetic loop (bench/run_loop.sh) keyframes were inserted at ~400
  // tracked points in the first 300 frames and at ~110 later, 1.4-2.4 s apart, and the frames in
  // between, tracked from an ageing local map, ended 6.5 mm RMS off after loop closing against
  // 3.3 mm at the keyframes (docs/benchmarks.md, #15 item 5); with this on, 2.8-4.0 mm with loop
  // closing and 6.8-10.4 mm without on four loop sequences, against 5.1-7.2 and 13.8-20.1 mm. Off
  // by default: on the real clip it moves the final trajectory by tenths of a millimetre, more
  // often up than down (6 of 9 dev cells worse, online within 0.1 mm), and one cell fewer has its
  // keyframes after BA closer to the truth than online (docs/benchmarks.md, sixteenth session).
  // `pspslam run --due-keyframes` sets it.
  bool insert_when_due = false;
  // A wanted keyframe (the ratio test) is also inserted while the mapper is busy, as long as
  // nothing waits in its queue; the bundle adjustment in progress is cut short for it. ORB-SLAM2
  // waits for an idle mapper unless a keyframe is due or tracking is weak. A deterministic run
  // always meets an idle mapper (it waits for local mapping), so this changes nothing there; a
  // real-time run rarely did, and made a third fewer keyframes than the same clip run
  // deterministically (bonn_crowd_dev `full`: 46-50 against 71); with this on, it won the online
  // ATE in 9 of 10 interleaved pairs (docs/benchmarks.md, issue #18 item 1).
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
