#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "pspslam/camera/pinhole_camera.h"

namespace YAML {
class Node;
}

namespace pspslam {

// What the camera delivers (key `camera.type`, default rgbd). Every difference between the
// sensors past the config lives in one place, the per-sensor frame builder
// (system/frame_builder.h).
enum class SensorType { rgbd, stereo, monocular };
SensorType parse_sensor_type(const std::string& name, const std::string& where);
std::string to_string(SensorType type);

// Sensor description (YAML section `camera:`; all keys but `name` and `k3` are required).
// rgbd needs depth_factor and depth_threshold; stereo needs exactly one of `baseline` (metres)
// and `bf` (fx * baseline, pixel metres) and refuses the depth-image keys; its depth_threshold is
// optional (default 40 baselines: farther stereo depth is too coarse to make a point from one
// view, ORB-SLAM2's rule). monocular needs neither and refuses both (colour images only).
struct CameraConfig {
  std::string name = "unnamed";
  SensorType type = SensorType::rgbd;
  // Stereo only: distance between the centres of the rectified left and right cameras. The
  // images are rectified (rows aligned, same intrinsics `pinhole`, no distortion).
  double baseline = 0.0;
  PinholeCamera pinhole;
  double fps = 30.0;
  // Seconds the (left) colour sensor takes to read its rows top to bottom (optional key
  // `rolling_shutter_readout`, any sensor type; 0 = global shutter, the default; negative: the
  // bottom row is read first). Keypoints are moved to the frame's instant with the rotation rate
  // tracking measures (camera/rolling_shutter.h, optimize/rolling_shutter_pose.h).
  double rolling_shutter_readout_s = 0.0;
  double depth_factor = 5000.0;  // depth image units per metre (5000 for TUM and Bonn)
  double depth_threshold = 4.0;  // metres: closer points are "close" (reliable) points
  // How a depth reading is weighed against the pixel in pose optimisation and bundle adjustment
  // (optional keys `depth_noise: none | kinect_v1`, `depth_noise_scale`). none: ORB-SLAM2's
  // virtual right coordinate, as firm as a pixel. kinect_v1: a disparity row whitened by the
  // Kinect v1 axial noise model times depth_noise_scale (optimize/depth_noise_model.h): 2 for
  // depth registered and synchronised with colour (the synthetic sequences), 16 for the Bonn
  // sensor's real depth (config/bonn.yaml).
  enum class DepthNoise { none, kinect_v1 };
  DepthNoise depth_noise = DepthNoise::none;
  double depth_noise_scale = 2.0;
  // Residual misregistration of a depth image that the sensor registered to the colour image
  // (optional key `depth_registration_shift_px: [dx, dy]`): the depth of colour pixel (u, v) is
  // read at depth pixel (u + dx, v + dy). Measured per sensor by
  // tools/calibration/depth_registration_shift.py (edge alignment); 0, 0 = registered exactly.
  int depth_shift_x = 0;
  int depth_shift_y = 0;
};

class YamlSection;

// A section of the config document that a module owns (`orb:`, `geometry:`), kept as YAML until
// that module reads it with its own keys and checks (feature/orb_config.h,
// geometry/geometry_config.h), as each module owns its parameters. An empty section reads as
// every key at its default.
class ConfigSection {
 public:
  ConfigSection() = default;
  // `document` names the config in errors (its file); `key` is the section's top-level key.
  ConfigSection(const YAML::Node& node, std::string document, std::string key);

  // A strict reader of the section (core/yaml_section.h): errors name the document, the line and
  // the key; finish() refuses the keys its module did not read.
  YamlSection reader() const;
  bool empty() const { return node_ == nullptr; }
  const YAML::Node* node() const { return node_.get(); }

 private:
  std::shared_ptr<const YAML::Node> node_;  // shared: a config is copied freely, never changed
  std::string document_;
  std::string key_;
};

// The config document: the camera, which every module needs and config/ reads, and the
// sections each module reads itself.
struct SystemConfig {
  CameraConfig camera;
  // ORB extraction (feature/orb_config.h), all keys optional.
  ConfigSection orb;
  // The OC multi-view geometry stage (paper III.B/C; geometry/geometry_config.h), with the
  // sub-sections homography, multiview, search, region, references, every key optional.
  ConfigSection geometry;
};

// Loads a config file. Any missing required key, unknown key or invalid value raises
// pspslam::Error naming the file, the line and the key.
SystemConfig load_config(const std::filesystem::path& file);
// The same from YAML text (a config built in memory, e.g. a Python dict); errors name `name`
// where load_config names the file.
SystemConfig parse_config(const std::string& yaml, const std::string& name);

// Writes a config that load_config reads back to the same values (the module sections as they
// were read).
void save_config(const std::filesystem::path& file, const SystemConfig& config);

}  // namespace pspslam
