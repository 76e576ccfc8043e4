#include "pspslam/synth/sensor.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "pspslam/synth/texture.h"

namespace pspslam::synth {
namespace {

constexpr double kDepthFactor = 5000.0;
constexpr double kFocal_px = 525.0;
constexpr double kProjectorBaseline_m = 0.075;  // Kinect v1 IR projector to IR camera
constexpr float kMinIncidenceCos = 0.12f;       // ~83 deg: the speckle pattern is lost

// Axial noise of Kinect v1 (Nguyen, Izadi, Lovell 2012): sigma(z) = 1.2 mm + 1.9 mm (z - 0.4)^2.
float axial_sigma(float z) {
  const float d = z - 0.4f;
  return 0.0012f + 0.0019f * d * d;
}

}  // namespace

std::vector<float> make_normal_table(uint64_t seed) {
  std::vector<float> normals(kNormalTableSize);
  for (size_t i = 0; i < kNormalTableSize; i += 2) {
    // Box-Muller once, at construction.
    const double u1 = std::max(1e-12, hash_to_unit(mix_hash(seed, i)));
    const double u2 = hash_to_unit(mix_hash(seed, i + 1));
    const double radius = std::sqrt(-2.0 * std::log(u1));
    normals[i] = static_cast<float>(radius * std::cos(2.0 * M_PI * u2));
    normals[i + 1] = static_cast<float>(radius * std::sin(2.0 * M_PI * u2));
  }
  return normals;
}

void clear_depth_discontinuities(const cv::Mat& exact,
                                 const std::function<int(float z_near, float z_far)>& shadow_px,
                                 cv::Mat& out) {
  const int width = exact.cols, height = exact.rows;
  for (int y = 0; y < height; ++y) {
    const float* z_row = exact.ptr<float>(y);
    float* out_row = out.ptr<float>(y);
    for (int x = 1; x < width; ++x) {
      const float left = z_row[x - 1], right = z_row[x];
      if (!is_depth_jump(left, right)) continue;
      out_row[x - 1] = 0.0f;
      out_row[x] = 0.0f;
      if (left > right && right > 0.0f) {
        const int shadow = shadow_px(right, left);
        for (int k = x - 2; k >= std::max(0, x - 1 - shadow); --k) {
          if (!is_depth_jump(z_row[k], right)) break;  // the shadow ends on nearer surfaces
          out_row[k] = 0.0f;
        }
      }
    }
  }
  for (int y = 1; y < height; ++y) {
    const float* above = exact.ptr<float>(y - 1);
    const float* here = exact.ptr<float>(y);
    float* out_above = out.ptr<float>(y - 1);
    float* out_here = out.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      if (is_depth_jump(above[x], here[x])) {
        out_above[x] = 0.0f;
        out_here[x] = 0.0f;
      }
    }
  }
}

DepthSensorModel::DepthSensorModel(uint64_t seed)
    : seed_(mix_hash(seed, 0x5E4502u)), normals_(make_normal_table(seed_)) {}

void DepthSensorModel::apply(const cv::Mat& exact, const cv::Mat& incidence_cos,
                             uint64_t frame_index, cv::Mat& out) const {
  CV_Assert(exact.type() == CV_32F && incidence_cos.type() == CV_32F);
  out.create(exact.size(), CV_32F);
  const int width = exact.cols, height = exact.rows;
  const uint64_t frame_seed = mix_hash(seed_, frame_index);

  // Per-pixel effects: range limits, grazing angles, isolated dropouts, depth noise.
  for (int y = 0; y < height; ++y) {
    const float* z_row = exact.ptr<float>(y);
    const float* cos_row = incidence_cos.ptr<float>(y);
    float* out_row = out.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      const float z = z_row[x];
      const uint64_t h = mix_hash(frame_seed, static_cast<uint64_t>(y) * width + x);
      if (z < kMinRange_m || z > kMaxRange_m || cos_row[x] < kMinIncidenceCos || (h & 1023) < 3) {
        out_row[x] = 0.0f;
        continue;
      }
      const float noisy = z + axial_sigma(z) * normals_[(h >> 10) & (kNormalTableSize - 1)];
      out_row[x] = quantise_depth(noisy, kDepthFactor);
    }
  }

  // Mixed pixels and the projector shadow at depth jumps; half the geometric shadow width
  // f b (1/z_near - 1/z_far), at most 24 px.
  clear_depth_discontinuities(
      exact,
      [](float z_near, float z_far) {
        const double shadow_px =
            0.5 * kFocal_px * kProjectorBaseline_m * (1.0 / z_near - 1.0 / z_far);
        return std::min(24, static_cast<int>(std::lround(shadow_px)));
      },
      out);

  // Small blob dropouts (specular / dark spots), a few dozen per frame.
  for (uint64_t i = 0; i < 30; ++i) {
    const uint64_t h = mix_hash(frame_seed, 0xD120Fu, i);
    const cv::Point centre(static_cast<int>(h % static_cast<uint64_t>(width)),
                           static_cast<int>((h >> 20) % static_cast<uint64_t>(height)));
    cv::circle(out, centre, 1 + static_cast<int>((h >> 40) % 4), cv::Scalar(0), cv::FILLED,
               cv::LINE_8);
  }
}

}  // namespace pspslam::synth
