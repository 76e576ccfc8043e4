#pragma once

#include <array>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam::synth {

// The faults of a hand-held structured-light RGB-D camera (Kinect v1, as the Bonn and TUM
// recordings have it) that `pspslam synth --sensor kinect` renders, each with its own switch so
// its share of the tracking error can be measured (`--no-fault NAME`).
struct KinectFaults {
  bool depth_noise = true;      // sigma_z ~ z^2, quantised in disparity (1/8 px)
  bool holes = true;            // projector shadow at depth edges, dark and grazing surfaces
  bool sync_offset = true;      // depth captured up to +-16 ms away from colour
  bool rolling_shutter = true;  // colour rows read out over 30 ms
  bool motion_blur = true;      // colour blurred along the image motion during the exposure
  bool exposure = true;         // slow gain drift plus occasional steps
  bool distortion = true;       // radial-tangential lens distortion (coefficients in config.yaml)
  bool handheld_motion = true;  // the Bonn clip's speeds and hand shake
  bool marker = true;           // groundtruth.txt is a motion-capture marker body, not the camera

  // Fault names as the CLI spells them, in a fixed order.
  static const std::vector<std::string>& names();
  // Switches one fault by its CLI name; throws pspslam::Error naming --no-fault otherwise.
  void set(const std::string& name, bool on);
  bool is_on(const std::string& name) const;
  // "depth-noise,holes,...": the faults that are on ("none" when none is).
  std::string describe() const;
  bool operator==(const KinectFaults&) const = default;
};

// Kinect v1 geometry: the depth is triangulated between the IR projector and the IR camera,
// 7.5 cm apart; disparities are reported in 1/8 px steps.
inline constexpr double kKinectBaseline_m = 0.075;
inline constexpr double kKinectDisparityStep_px = 1.0 / 8.0;
inline constexpr double kKinectSyncOffsetMax_s = 0.016;
inline constexpr double kKinectReadout_s = 0.030;
inline constexpr double kKinectExposure_s = 0.016;
// Lens distortion of the colour camera (k1 k2 p1 p2 k3): the Bonn dataset's published
// calibration, so the synthetic images are bent as much as the real clip's.
inline constexpr std::array<double, 5> kKinectDistortion = {0.039903, -0.099343, -0.00073,
                                                            -0.000144, 0.0};

// Kinect v1 axial noise, sigma_z = 1.425e-3 z^2 m (Khoshelham & Elberink 2012, Nguyen et al.
// 2012).
inline float kinect_sigma(float z) { return 1.425e-3f * z * z; }

// The depth measurement of a Kinect v1 from an exact depth image (all CV_32F metres, 0 = no
// reading) registered to colour. Every random draw is a hash of (seed, frame, pixel).
class KinectDepthModel {
 public:
  KinectDepthModel(uint64_t seed, double focal_px);

  struct Switches {
    bool noise = true;         // Gaussian sigma_z(z)
    bool quantisation = true;  // disparity b f / z rounded to 1/8 px
    bool holes = true;
  };
  // exact: CV_32F metres; incidence_cos: CV_32F |cos| between ray and surface normal; grey:
  // CV_8UC3 colour of the same surfaces (dark = little IR reflected). out: CV_32F metres.
  void apply(const cv::Mat& exact, const cv::Mat& incidence_cos, const cv::Mat& bgr,
             uint64_t frame_index, const Switches& switches, cv::Mat& out) const;

  // Shadow band width (px) on the background beside a foreground edge: the part of the
  // background the projector cannot see, f b (1/z_near - 1/z_far).
  double shadow_width_px(double z_near, double z_far) const;
  double quantise(double z) const;  // through the 1/8 px disparity grid

  static constexpr float kMinRange_m = 0.5f;
  static constexpr float kMaxRange_m = 4.5f;
  static constexpr float kMinIncidenceCos = 0.2f;  // ~78 deg: the speckles smear out
  static constexpr int kDarkGrey = 28;             // mean BGR below this: too little IR back

 private:
  uint64_t seed_;
  double focal_px_;
  std::vector<float> normals_;
};

// Colour/depth capture offset of frame `index` in seconds, uniform in +-16 ms.
double kinect_sync_offset(uint64_t seed, size_t index);
// Colour gain at time t: a slow drift (+-8 %, ~9 s period) times a step that changes on some
// 2 s boundaries (auto-exposure settling on a new level).
double kinect_exposure_gain(uint64_t seed, double t);

// Blurs `bgr` in place along the image motion of a pure rotation `omega_camera` (rad/s in the
// camera frame) during `exposure_s`, as the flow at the principal point gives it: a line kernel,
// cheap, and a fair model of hand-held blur (rotation dominates the image motion).
void kinect_motion_blur(cv::Mat& bgr, const Eigen::Vector3d& omega_camera, double focal_px,
                        double exposure_s);

// Maps that bend an ideal pinhole image into the distorted one (cv::remap): for every distorted
// pixel, where its ray falls in the ideal image.
struct DistortionMaps {
  cv::Mat map_x, map_y;  // CV_32F
  DistortionMaps(int width, int height, double fx, double fy, double cx, double cy,
                 const std::array<double, 5>& coeffs);
};

}  // namespace pspslam::synth
