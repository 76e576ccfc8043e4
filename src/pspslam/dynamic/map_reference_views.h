#pragma once

#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/geometry/multiview_test.h"

namespace pspslam {

class KeyFrame;
class Map;

// Reference views for the geometry stage in localisation mode. A live run feeds the
// multi-view test the depth images of the keyframes it inserts; localisation inserts none, and a
// map file keeps no depth images. What it keeps per keyframe is the measured depth of every
// keypoint, so a reference depth image is rebuilt from those: each keypoint's depth is splatted
// over a small square (nearest surface wins), the rest of the image reads "no depth" (0), which
// the test skips. A person now standing where the keyframe saw the wall behind still meets the
// wall's keypoints there and gets the dynamic vote; a static point meets its own surface.
struct MapReferenceParams {
  // Half-size of the square each keypoint's depth covers. ORB keeps ~1000 keypoints on a
  // 640x480 image (one per ~17 px square); 6 px leaves the test's 9x9 patch a reading near most
  // textured places without smearing a depth edge far.
  int splat_radius_px = 6;
  // Keyframes whose optical axis turns more than this from the frame's see another part of
  // the scene; the pool is the nearest keyframes (camera centres) among the others.
  double max_axis_angle_deg = 60.0;
};

// The sparse depth image (CV_32FC1 metres, 0 = none) of one keyframe, in the distorted pixel
// frame the live depth images use (keyframe keypoints are stored undistorted).
cv::Mat rebuild_reference_depth(const KeyFrame& keyframe, const PinholeCamera& camera,
                                int splat_radius_px);

// All keyframes of a (loaded) map with their rebuilt depth, and the per-frame choice of a pool
// among them: the geometry stage then picks its views from the pool by coverage, as in SLAM.
class MapReferenceViews {
 public:
  MapReferenceViews(const Map& map, const PinholeCamera& camera, MapReferenceParams params = {});

  // Up to `pool_size` views nearest to T_world_camera (closest first). Keyframe poses are read
  // now: nothing refines them in localisation, but the read is cheap and always current.
  void pool(const Pose& T_world_camera, size_t pool_size, std::vector<DepthView>& out) const;

  size_t size() const { return views_.size(); }

 private:
  struct View {
    std::weak_ptr<KeyFrame> keyframe;
    cv::Mat depth;
  };
  MapReferenceParams params_;
  std::vector<View> views_;
};

}  // namespace pspslam
