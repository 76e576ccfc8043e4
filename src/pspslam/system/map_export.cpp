#include "pspslam/system/map_export.h"

#include <cmath>
#include <unordered_set>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/map/map_point.h"

namespace pspslam {
namespace {

void set_colour(ColoredPoint& point, const cv::Mat& bgr, int x, int y) {
  if (bgr.empty() || x < 0 || y < 0 || x >= bgr.cols || y >= bgr.rows) return;
  const cv::Vec3b& pixel = bgr.at<cv::Vec3b>(y, x);
  point.blue = pixel[0];
  point.green = pixel[1];
  point.red = pixel[2];
}

// Packs a voxel index into one key; +-2^20 voxels per axis is +-10 km at 1 cm.
std::uint64_t voxel_key(const Eigen::Vector3d& position, double voxel_size) {
  const auto cell = [voxel_size](double v) {
    return static_cast<std::uint64_t>(std::llround(std::floor(v / voxel_size)) + (1 << 20)) &
           0x1FFFFF;
  };
  return cell(position.x()) | (cell(position.y()) << 21) | (cell(position.z()) << 42);
}

}  // namespace

void MapExporter::remember_keyframe(std::uint64_t keyframe_id, const cv::Mat& bgr,
                                    const cv::Mat& depth, const cv::Mat& dynamic_mask) {
  images_[keyframe_id] = {bgr, depth, dynamic_mask};
}

std::vector<ColoredPoint> MapExporter::map_points(const Map& map) const {
  std::vector<ColoredPoint> cloud;
  for (const auto& point : map.map_points()) {
    if (point->is_bad()) continue;
    ColoredPoint& out = cloud.emplace_back();
    out.position = point->position().cast<float>();
    out.red = out.green = out.blue = 160;
    const auto reference = point->reference_keyframe();
    if (!reference) continue;
    const auto images = images_.find(reference->id());
    if (images == images_.end()) continue;
    const auto observations = point->observations();
    const auto observation = observations.find(reference->id());
    if (observation == observations.end()) continue;
    const cv::Point2f& pixel = reference->keypoints()[observation->second.keypoint_index].pt;
    set_colour(out, images->second.bgr, static_cast<int>(std::lround(pixel.x)),
               static_cast<int>(std::lround(pixel.y)));
  }
  return cloud;
}

std::vector<ColoredPoint> MapExporter::dense_cloud(const Map& map,
                                                   const DenseCloudOptions& options) const {
  std::vector<ColoredPoint> cloud;
  std::unordered_set<std::uint64_t> occupied;
  std::vector<cv::Point2f> pixels;
  std::vector<cv::Point2f> undistorted;
  for (const auto& keyframe : map.keyframes()) {
    if (keyframe->is_bad()) continue;
    const auto images = images_.find(keyframe->id());
    if (images == images_.end()) continue;
    const Images& image = images->second;
    const Pose T_world_camera = keyframe->T_world_camera();
    pixels.clear();
    for (int y = 0; y < image.depth.rows; y += options.pixel_stride) {
      for (int x = 0; x < image.depth.cols; x += options.pixel_stride) {
        const float depth = image.depth.at<float>(y, x);
        if (depth <= 0.0f || depth > options.max_depth_m) continue;
        if (!image.dynamic_mask.empty() && image.dynamic_mask.at<std::uint8_t>(y, x)) continue;
        pixels.emplace_back(static_cast<float>(x), static_cast<float>(y));
      }
    }
    undistorted.assign(pixels.begin(), pixels.end());
    camera_.undistort_points(undistorted);
    for (size_t i = 0; i < pixels.size(); ++i) {
      const int x = static_cast<int>(pixels[i].x), y = static_cast<int>(pixels[i].y);
      const Eigen::Vector3d position =
          T_world_camera *
          camera_.unproject({undistorted[i].x, undistorted[i].y}, image.depth.at<float>(y, x));
      if (options.voxel_size_m > 0.0 &&
          !occupied.insert(voxel_key(position, options.voxel_size_m)).second)
        continue;
      ColoredPoint& out = cloud.emplace_back();
      out.position = position.cast<float>();
      set_colour(out, image.bgr, x, y);
    }
  }
  return cloud;
}

}  // namespace pspslam
