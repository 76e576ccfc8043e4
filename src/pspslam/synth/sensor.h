#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam::synth {

// What the depth sensor models (the ideal sensor's DepthSensorModel, kinect.h's KinectDepthModel)
// share.
// Pre-drawn standard normal samples indexed by a per-pixel hash: deterministic per pixel and far
// cheaper than Box-Muller for 300k pixels per frame. Index with `hash & (kNormalTableSize - 1)`.
inline constexpr size_t kNormalTableSize = 1 << 16;
std::vector<float> make_normal_table(uint64_t seed);

// A depth jump that mixed pixels and the projector shadow show up at.
inline bool is_depth_jump(float a, float b) {
  return std::abs(a - b) > 0.02f + 0.02f * std::min(a, b);
}

// Clears in `out` what a structured-light sensor cannot measure at the depth jumps of `exact`
// (CV_32F metres): the mixed pixels on both sides of every horizontal and vertical jump, and the
// projector shadow: the background just left of a foreground edge, which the (right-hand) IR
// projector does not light. `shadow_px(z_near, z_far)` is how many pixels left of the mixed
// pixel the shadow covers; it stops early on a surface nearer than the background. Called only
// at jumps.
void clear_depth_discontinuities(const cv::Mat& exact,
                                 const std::function<int(float z_near, float z_far)>& shadow_px,
                                 cv::Mat& out);

// Kinect-v1-like depth sensor applied to an exact depth image.
class DepthSensorModel {
 public:
  explicit DepthSensorModel(uint64_t seed);

  // exact: CV_32F metres; incidence_cos: CV_32F |cos| between ray and surface normal.
  // out: CV_32F metres quantised to 1 / depth_factor, 0 = no reading.
  void apply(const cv::Mat& exact, const cv::Mat& incidence_cos, uint64_t frame_index,
             cv::Mat& out) const;

  static constexpr double kMinRange_m = 0.4;
  static constexpr double kMaxRange_m = 5.0;

 private:
  uint64_t seed_;
  std::vector<float> normals_;  // make_normal_table
};

// Rounds metres to the 16-bit PNG grid (1 / depth_factor m), as the written file stores it.
inline float quantise_depth(float metres, double depth_factor) {
  // Depths are >= 0, so adding 0.5 and truncating rounds to nearest (std::round is slow here).
  const auto units = static_cast<int64_t>(static_cast<double>(metres) * depth_factor + 0.5);
  return static_cast<float>(static_cast<double>(units) / depth_factor);
}

}  // namespace pspslam::synth
