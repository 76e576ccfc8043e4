#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

struct PersonDetectorParams {
  // The mask and depth are read every `grid_step` pixels in both directions: a person close
  // enough to matter covers thousands of pixels, and the frame path has no time for all of them.
  int grid_step = 4;
  // Instances smaller than this (in full-resolution pixels with depth) are dropped: fragments
  // of a silhouette, a hand at the image border.
  int min_pixels = 400;
  // Neighbouring samples belong to one instance when their depths differ by at most
  // abs + rel * depth: a person in front of another is cut from her by the depth jump.
  float depth_jump_abs_m = 0.15f;
  float depth_jump_rel = 0.05f;
  float max_depth_m = 10.0f;
  // The camera sees a person's front surface; her centre lies this far behind it on the ray
  // (between the half depth and the half width of a torso: people are seen from any side).
  double body_radius_m = 0.15;
  // A person stands in front of what is behind her: around an instance (its box grown by
  // standout_window of its size on each side) at least min_standout of the other samples with
  // depth must lie farther than the depth jump behind its median depth. A segmentation that
  // paints "person" on a wall or a poster lies at the depth of its surroundings and is dropped.
  double standout_window = 0.3;
  double min_standout = 0.35;
  // Instances whose centres are this close along the camera's x (side), y (height) and z
  // (depth) axes are one person: legs or an arm cut off the torso by their depth jump, a body
  // split by an occluder. Two people side by side stand wider apart; one behind the other, deeper.
  double merge_side_m = 0.35;
  double merge_height_m = 1.0;
  double merge_depth_m = 0.5;
};

// One person seen in one frame.
struct PersonObservation {
  Eigen::Vector3d position_camera = Eigen::Vector3d::Zero();  // robust centre, metres
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
  double extent_m = 0.0;   // the larger of the visible part's height and width (10-90 %)
  int visible_pixels = 0;  // full-resolution pixels of the instance with a depth reading
  cv::Rect box;            // image rectangle of the instance (full resolution)
};

// Splits a frame's person mask into person instances by connected regions and depth, and gives
// each a 3D centre: the median pixel of the instance, undistorted, at its median depth plus
// the body radius, moved into the world by the frame's pose. Keeps its buffers between frames.
class PersonDetector {
 public:
  explicit PersonDetector(PersonDetectorParams params = {}) : params_(params) {}

  // `labels`: CV_8UC1 of any size (read at the depth pixel's scaled position); a pixel is a
  // person where it equals `person_label` (or, with person_label < 0, where it is non-zero).
  // `depth`: CV_32FC1 metres (0 = no reading) in the camera's image size.
  std::vector<PersonObservation> detect(const cv::Mat& labels, int person_label,
                                        const cv::Mat& depth, const PinholeCamera& camera,
                                        const Pose& T_world_camera);

  const PersonDetectorParams& params() const { return params_; }

 private:
  struct Instance {
    std::vector<float> u, v, depth;
    int min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  };
  void sample(const cv::Mat& labels, int person_label, const cv::Mat& depth);
  void label_components();
  // The share of the samples around `instance` (id `id`) that lie behind it.
  double standout(const Instance& instance, std::int32_t id) const;
  PersonObservation observe(Instance& instance, const PinholeCamera& camera) const;

  PersonDetectorParams params_;
  int grid_w_ = 0, grid_h_ = 0;
  std::vector<float> grid_depth_;      // per sample: depth of a person pixel, 0 otherwise
  std::vector<float> all_depth_;       // per sample: its depth, 0 = no reading
  std::vector<std::int32_t> grid_id_;  // per sample: instance, -1 none
  std::vector<std::int32_t> queue_;
  std::vector<Instance> instances_;
};

}  // namespace pspslam
