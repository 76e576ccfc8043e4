#pragma once

#include <array>
#include <memory>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam {

class Frame;
class KeyFrame;
class MapPoint;

// ORB-SLAM2's matching thresholds on the 256-bit Hamming distance.
struct MatcherOptions {
  int max_distance_strict = 50;   // matches that seed a pose (previous frame, keyframe)
  int max_distance_loose = 100;   // projection search of an already well-predicted point
  double nn_ratio = 0.8;          // best / second best (Lowe's ratio test)
  bool check_orientation = true;  // rotation-consistency histogram
};

// A map point predicted in a frame (computed by project_map_point): where to search and at
// which pyramid level.
struct ProjectedPoint {
  std::shared_ptr<MapPoint> point;
  double u = 0.0;
  double v = 0.0;
  double right_u = -1.0;  // predicted virtual right coordinate
  int predicted_level = 0;
  double view_cos = 1.0;  // cos of the angle between the viewing ray and the point's normal
};

// Predicts `point` in a frame with pose T_camera_world (the frame must have a pose): false when
// it is behind the camera, outside the image, outside its scale-invariance distance range, or
// seen at more than 60 degrees from its mean viewing direction (ORB-SLAM2's frustum test).
bool project_map_point(const std::shared_ptr<MapPoint>& point, const Frame& frame,
                       ProjectedPoint& out);

// Keeps only the keypoint matches that agree with the dominant rotation change: histogram of
// the angle difference (30 bins), the three most populated bins are kept (a bin smaller than a
// tenth of the largest is not). Used by every matcher below.
class RotationHistogram {
 public:
  static constexpr int kBins = 30;
  void clear();
  void add(float angle_from_degrees, float angle_to_degrees, int match_index);
  // Indices (as passed to add) of matches outside the kept bins.
  std::vector<int> rejected() const;

 private:
  std::array<std::vector<int>, kBins> bins_;
};

// Search by projection of local map points into a frame that already has a pose estimate;
// fills frame.map_points for keypoints that have none. `radius_scale` widens the window
// (ORB-SLAM2: 1 normally, larger right after relocalisation). Returns the number of matches.
int search_by_projection(Frame& frame, const std::vector<ProjectedPoint>& projected,
                         double radius_scale, const MatcherOptions& options = {});

// Motion-model tracking: projects the previous frame's (inlier) map points into `current`
// using current's predicted pose; the search window is `radius` pixels times the keypoint
// level scale. Returns the number of matches.
int search_previous_frame(Frame& current, const Frame& previous, double radius,
                          const MatcherOptions& options = {});

// Reference-keyframe tracking without a vocabulary: brute-force descriptor matching of the
// keyframe's keypoints that carry a map point against all keypoints of the frame, with ratio
// test and rotation consistency. It needs no pose prediction, which is the point of this
// fallback (it runs when the motion model failed). O(N*M) Hamming distances: about a million
// popcounts for two 1000-keypoint sets, affordable because it runs only on fallback frames. Returns
// the number of matches written into frame.map_points.
int search_keyframe_brute_force(Frame& frame, const KeyFrame& keyframe,
                                const MatcherOptions& options = {});

}  // namespace pspslam
