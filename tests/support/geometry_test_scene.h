#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

// A small analytic RGB-D scene with ground-truth dynamic labels, used by the geometry module's
// tests and its timing (bench/bench_geometry_parts.cpp): a room with static furniture, people
// walking (label 15) and a box one person carries (label 100), seen by a moving camera. Depth
// follows a Kinect-like noise model and is quantised to 1/5000 m, as in TUM/Bonn files. Labels use
// the same convention as `pspslam synth` masks: 0 static, 15 person, 100 carried object.
struct GeometryTestSceneParams {
  PinholeCamera camera;
  int people = 2;
  bool carried_object = true;
  double person_speed_mps = 1.0;
  double depth_noise_scale = 1.0;  // multiplies the Kinect noise model sigma(z)
  double fps = 30.0;
  std::uint64_t seed = 1;
};

class GeometryTestScene {
 public:
  explicit GeometryTestScene(GeometryTestSceneParams params);

  Pose camera_pose(int frame) const;  // T_world_camera
  // depth: CV_32FC1 metres (noisy, quantised); labels: CV_8UC1.
  void render(int frame, cv::Mat& depth, cv::Mat& labels) const;

  const GeometryTestSceneParams& params() const { return params_; }

 private:
  struct Box {
    Eigen::Vector3d center;
    Eigen::Vector3d half_size;
    std::uint8_t label;
    // Dynamic boxes walk back and forth along x: center.x + amplitude * sin(omega t + phase).
    double amplitude = 0.0;
    double omega = 0.0;
    double phase = 0.0;
  };
  Eigen::Vector3d box_center(const Box& box, double time) const;

  GeometryTestSceneParams params_;
  std::vector<Box> boxes_;
};

// Candidate keypoints for an evaluation: pixels with valid depth, half drawn uniformly and half on
// depth edges (where real ORB keypoints concentrate and where depth tests are hardest).
std::vector<Eigen::Vector2d> sample_candidate_pixels(const cv::Mat& depth, int count,
                                                     std::uint64_t seed);

}  // namespace pspslam
