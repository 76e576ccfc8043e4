#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <span>
#include <string>

#include "pspslam/config/config.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/io/input_frame.h"
#include "pspslam/loop/loop_closing.h"
#include "pspslam/map/frame.h"
#include "pspslam/mapping/local_mapping_options.h"
#include "pspslam/system/system_options.h"
#include "pspslam/tracking/map_initializer.h"

namespace pspslam {

// Everything that differs between sensors from the images to the Frame the tracker sees, in one
// place: past the Frame, tracking, mapping and loop closing treat every keypoint alike, with a
// depth and a right coordinate u_r = u - bf / z (measured for stereo, derived from the depth image
// with a virtual baseline for RGB-D), so the same stereo reprojection residual serves both sensors
// in pose optimisation and bundle adjustment. A monocular keypoint has no depth (< 0, right u NaN)
// and gets the 2-row residual everywhere; the sensors also differ in how the map starts
// (make_map_initializer) and in a few local mapping rules (adapt).
//
// System drives it per frame: extract -> [dynamic pipeline: depth_image, remove_dynamic] -> build.
class FrameBuilder {
 public:
  virtual ~FrameBuilder() = default;

  // ORB features of the (left) image, none on `mask` (may be empty). `gray` is the frame's
  // (left) image in grey.
  virtual void extract(const InputFrame& frame, const cv::Mat& gray, const cv::Mat& mask,
                       OrbFeatures& features) = 0;

  // The frame will be extracted after the one in progress (deterministic runs announce each
  // frame before the one before it is processed): work that needs only its images may start
  // now. Frames are announced in the order they are extracted; one never announced is
  // extracted all the same.
  virtual void prepare(const InputFrame&) {}

  // The frame's depth image (CV_32FC1 metres, 0 = none) for the dynamic pipeline: the geometry
  // stage compares it with its reference views around projected pixels and the culler reads it
  // at map points, so it must be dense. RGB-D: the sensor's image; stereo: computed here.
  virtual cv::Mat depth_image(const InputFrame& frame) = 0;

  // Each extracted keypoint's own depth measurement (metres, <= 0: none), in extraction order,
  // for the geometry stage's candidates; empty: the stage reads depth_image() at the keypoint's
  // pixel (RGB-D, where that is the measurement).
  virtual std::span<const float> keypoint_depths() const { return {}; }

  // The tracked frame from the features left after dynamic removal (an order-preserving subset
  // of the extracted ones). `depth` is what depth_image() returned, or empty when no dynamic
  // pipeline runs. `angular_velocity` (rad/s, camera frame): the tracker's, for the
  // rolling-shutter correction of a camera that has one (map/frame.h).
  virtual Frame build(std::uint64_t id, const InputFrame& frame, OrbFeatures&& features,
                      const cv::Mat& depth, const Eigen::Vector3d& angular_velocity) = 0;

  // How the map starts: one frame with depth (RGB-D, stereo) or two views (monocular).
  virtual std::unique_ptr<MapInitializer> make_map_initializer(
      const TrackerOptions& options) const {
    return make_depth_map_initializer(options.min_initial_depth_points, options.pose_optimizer);
  }
  // Local mapping rules that depend on depth readings.
  virtual void adapt(LocalMappingOptions&) const {}
  // Loop closing: whether the loop transform has a scale (Sim(3)) and how it is verified.
  virtual void adapt(LoopClosingOptions&) const {}
};

// What a sensor cannot run, taken out of the run's options before the System starts, with the
// reason the run summary prints (empty: nothing changed).
struct SensorLimits {
  DynamicMode requested_mode = DynamicMode::off;
  std::string dynamic_note;  // e.g. "full runs as semantic (monocular: ...)"
};
SensorLimits apply_sensor_limits(SensorType type, SystemOptions& options);

// The builder of `config.camera.type`. `dense_depth`: depth_image() will be called every frame
// (a dynamic pipeline runs), so a stereo builder computes it beside the extraction.
std::unique_ptr<FrameBuilder> make_frame_builder(const SystemConfig& config,
                                                 std::shared_ptr<const CameraModel> camera,
                                                 std::shared_ptr<const ScalePyramid> pyramid,
                                                 bool dense_depth);

}  // namespace pspslam
