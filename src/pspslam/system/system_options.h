#pragma once

#include <filesystem>

#include "pspslam/dynamic/dynamic_pipeline.h"
#include "pspslam/tracking/tracker.h"

namespace pspslam {

// Place recognition: bag-of-words vocabulary and keyframe database.
struct PlaceOptions {
  // Vocabulary file (`pspslam run --vocabulary`); empty = default_vocabulary_path()
  // (models/vocabulary/orb_k10_l5.pspvoc in the source tree).
  std::filesystem::path vocabulary;
  // Relocalise a lost tracker against the keyframe database. Needs the vocabulary, which is
  // then loaded at start-up and every keyframe gets a BoW vector in local mapping.
  bool relocalization = true;
  // Loop closing thread (`pspslam run --loop-closing`): detection, correction, global BA.
  // Needs the vocabulary and local mapping.
  bool loop_closing = true;

  // True when anything needs the vocabulary (relocalisation, loop closing).
  bool needs_vocabulary() const { return relocalization || loop_closing; }
};

enum class BackEndWait { none, local_mapping, whole_back_end };

struct SystemOptions {
  // ORB-SLAM2's virtual stereo baseline for RGB-D (u_r = u - fx * b / z), metres.
  double virtual_baseline = 0.08;
  TrackerOptions tracker;
  // false: keyframes go into the map but no local mapping runs (tests, debugging).
  bool local_mapping = true;
  // What each frame waits for before it is tracked (extraction still overlaps).
  // whole_back_end: local mapping has finished the keyframes before it, loop closing has looked
  // at them and any loop correction and global BA are applied. Offline accuracy runs want this:
  // otherwise the map a frame is tracked against, and whether a keyframe is accepted, depend on
  // how fast this machine is right now (a fast, unpaced run outruns local BA; frames tracked
  // between a loop correction and its global BA's write-back land centimetres off).
  // local_mapping: only local mapping (a camera fed at its own pace: a global BA takes seconds,
  // during which its driver would drop frames). none: a real-time feed never waits.
  BackEndWait back_end_wait = BackEndWait::none;
  // Local BA window size (LocalMappingOptions::max_local_keyframes; 0: every covisible one).
  int local_ba_keyframes = 0;
  // Of the fixed keyframes around the window, the ones that see most of its points (0: all).
  int local_ba_fixed_keyframes = 0;
  // Weight of tracking's relative poses between keyframes in local BA
  // (LocalMappingOptions::tracked_motion_weight; 0: none).
  double ba_tracking_factors = 0.0;
  // Nice increment of the semantic, local mapping and loop closing threads (and of the global
  // BA threads loop closing starts). A live run (--realtime, a camera) sets it so that the
  // caller thread, which must track each frame before the next one arrives, gets a core when
  // it needs one and the background work takes what is left (docs/decisions/realtime-nice.md).
  int background_thread_nice = 0;
  DynamicOptions dynamic;
  PlaceOptions place;
  // Map file to start from (`pspslam run --load-map`, persistence/map_file.h); empty: start a
  // new map. The first frame is relocalised in it (needs place.relocalization).
  std::filesystem::path map_file;
  // Localisation only (`--localization`): track against the map, never insert keyframes; no
  // local mapping and no loop closing run.
  bool localization_only = false;
  // Fill FrameReport::keypoints (pictures of a run, `pspslam run --save-overlays`). Off by
  // default: it costs a second, unmasked ORB extraction per frame with a semantic mask (the
  // keypoints the mask kept the extractor from returning) and a copy of every keypoint position.
  bool record_keypoint_fates = false;
};

}  // namespace pspslam
