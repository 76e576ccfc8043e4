#pragma once

// Keyframe-to-keyframe matching used by local mapping: epipolar-guided matching of unmatched
// keypoints for triangulation, and projection of map points into a keyframe for fusion. No
// vocabulary (ORB-SLAM2 narrows the candidates by BoW nodes; here the epipolar test comes first
// and the Hamming distance is computed only for keypoints near the line).

#include <memory>
#include <utility>
#include <vector>

namespace pspslam {

class KeyFrame;
class Map;
class MapPoint;

struct KeypointMatch {
  int index1 = -1;
  int index2 = -1;
};

// Matches keypoints of `first` and `second` that carry no map point yet, under the epipolar
// constraint of their current poses (squared distance to the line < 3.84 σ² of the level in
// `second`) and descriptor distance <= max_descriptor_distance; one-to-one.
std::vector<KeypointMatch> search_for_triangulation(const KeyFrame& first, const KeyFrame& second,
                                                    int max_descriptor_distance);

// Projects `points` into `keyframe` and fuses each with the best matching keypoint within
// radius · scale(level): if that keypoint has no map point the point gains the observation,
// otherwise the one with fewer observations is merged into the other and erased from `map`.
// Returns the number of fused points.
int fuse_into_keyframe(Map& map, const std::shared_ptr<KeyFrame>& keyframe,
                       const std::vector<std::shared_ptr<MapPoint>>& points, double radius,
                       int max_descriptor_distance);

}  // namespace pspslam
