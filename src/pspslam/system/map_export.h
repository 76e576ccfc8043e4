#pragma once

#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/io/point_cloud_ply.h"

namespace pspslam {

class Map;

struct DenseCloudOptions {
  int pixel_stride = 4;        // every stride-th pixel in x and y of each keyframe
  double max_depth_m = 4.0;    // farther readings are too noisy for a map
  double voxel_size_m = 0.01;  // one point per voxel (first keyframe wins); 0 keeps all
};

// Static map export (`pspslam run --export-map`). Remembers the images of the frames that became
// keyframes, with their fused dynamic masks, and turns the final map into point clouds: the map
// points (dynamic ones never entered the map or were culled from it), and optionally a dense cloud
// back-projected from the keyframes' depth at their final, BA-refined poses with the dynamic pixels
// left out. Keyframes culled by local mapping are skipped.
class MapExporter {
 public:
  explicit MapExporter(PinholeCamera camera) : camera_(std::move(camera)) {}

  // `bgr`, `depth` (CV_32F metres) and `dynamic_mask` (CV_8U, non-zero = dynamic; may be empty)
  // are shared, not copied: the caller must not write into them afterwards.
  void remember_keyframe(std::uint64_t keyframe_id, const cv::Mat& bgr, const cv::Mat& depth,
                         const cv::Mat& dynamic_mask);

  // Map points that are not bad, coloured from the image of their reference keyframe (grey
  // when that keyframe's image was not remembered).
  std::vector<ColoredPoint> map_points(const Map& map) const;
  std::vector<ColoredPoint> dense_cloud(const Map& map, const DenseCloudOptions& options) const;

  size_t remembered_keyframes() const { return images_.size(); }

 private:
  struct Images {
    cv::Mat bgr, depth, dynamic_mask;
  };
  PinholeCamera camera_;
  std::map<std::uint64_t, Images> images_;
};

}  // namespace pspslam
