#pragma once

// Matching between a keyframe and the map around a loop candidate (ORB-SLAM2 ORBmatcher's
// SearchByBoW, SearchBySim3 and SearchByProjection with a given pose; the loop transform is a
// Sim(3), of scale 1 for RGB-D and stereo).
// Results are written per keypoint of `keyframe`: matched[i] = map point matched to keypoint i
// (nullptr: none). `matched` must have keyframe.size() entries; existing entries are kept and
// their keypoints / map points are not matched again.

#include <memory>
#include <vector>

#include "pspslam/core/similarity.h"
#include "pspslam/core/types.h"

namespace pspslam {

class KeyFrame;
class MapPoint;

struct LoopMatchingOptions {
  int max_distance_strict = 50;  // descriptor-only matching and projection search (TH_LOW)
  int max_distance_loose = 100;  // guided search with the estimated transform (TH_HIGH)
  double nn_ratio = 0.75;        // ORB-SLAM2 uses 0.75 to seed the loop transform
  bool check_orientation = true;
};

// Map-point-carrying keypoints of `keyframe` against those of `candidate`, by descriptor alone:
// restricted to keypoints under the same vocabulary node when both keyframes have a BoW
// feature vector, all pairs otherwise. Ratio test, one-to-one, rotation consistency.
int match_by_descriptor(const KeyFrame& keyframe, const KeyFrame& candidate,
                        std::vector<std::shared_ptr<MapPoint>>& matched,
                        const LoopMatchingOptions& options = {});

// Guided search with S_keyframe_candidate: the candidate's map points are predicted in
// `keyframe` and the keyframe's in the candidate, within radius · scale(level) pixels; only
// mutual matches are added. Returns the number added.
int match_by_transform(const KeyFrame& keyframe, const KeyFrame& candidate,
                       const Sim3& S_keyframe_candidate,
                       std::vector<std::shared_ptr<MapPoint>>& matched, double radius,
                       const LoopMatchingOptions& options = {});

// Projects `points` into `keyframe` placed at T_camera_world (not its own pose: the corrected
// one) and matches unmatched keypoints within radius · scale(level). Returns the number added.
int match_by_projection(const KeyFrame& keyframe, const Pose& T_camera_world,
                        const std::vector<std::shared_ptr<MapPoint>>& points,
                        std::vector<std::shared_ptr<MapPoint>>& matched, double radius,
                        const LoopMatchingOptions& options = {});

}  // namespace pspslam
