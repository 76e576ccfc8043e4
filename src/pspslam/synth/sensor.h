#pragma once

#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam::synth {

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
  // Pre-drawn standard normal samples indexed by a per-pixel hash: deterministic per pixel and
  // far cheaper than Box-Muller for 300k pixels per frame.
  std::vector<float> normals_;
};

// Rounds metres to the 16-bit PNG grid (1 / depth_factor m), as the written file stores it.
inline float quantise_depth(float metres, double depth_factor) {
  // Depths are >= 0, so adding 0.5 and truncating rounds to nearest (std::round is slow here).
  const auto units = static_cast<int64_t>(static_cast<double>(metres) * depth_factor + 0.5);
  return static_cast<float>(static_cast<double>(units) / depth_factor);
}

}  // namespace pspslam::synth
