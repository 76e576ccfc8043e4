#include "pspslam/synth/sensor.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "pspslam/synth/texture.h"

namespace pspslam::synth {
namespace {

constexpr size_t kNormalTableSize = 1 << 16;
constexpr double kDepthFactor = 5000.0;
constexpr double kFocal_px = 525.0;
constexpr double kProjectorBaseline_m = 0.075;  // Kinect v1 IR projector to IR camera
constexpr float kMinIncidenceCos = 0.12f;       // ~83 deg: the speckle pattern is lost

// Axial noise of Kinect v1 (Nguyen, Izadi, Lovell 2012): sigma(z) = 1.2 mm + 1.9 mm (z - 0.4)^2.
float axial_sigma(float z) {
  const float d = z - 0.4f;
  return 0.0012f + 0.0019f * d * d;
}

bool is_jump(float a, float b) { return std::abs(a - b) > 0.02f + 0.02f * std::min(a, b); }

}  // namespace

DepthSensorModel::DepthSensorModel(uint64_t seed) : seed_(mix_hash(seed, 0x5E4502u)) {
  normals_.resize(kNormalTableSize);
  for (size_t i = 0; i < kNormalTableSize; i += 2) {
    // Box-Muller once, at construction.
    const double u1 = std::max(1e-12, hash_to_unit(mix_hash(seed_, i)));
    const double u2 = hash_to_unit(mix_hash(seed_, i + 1));
    const double radius = std::sqrt(-2.0 * std::log(u1));
    normals_[i] = static_cast<float>(radius * std::cos(2.0 * M_PI * u2));
    normals_[i + 1] = static_cast<float>(radius * std::sin(2.0 * M_PI * u2));
  }
}

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

  // Depth discontinuities: mixed pixels on both sides of every jump, and the projector shadow:
  // background just left of a foreground edge is not lit by the (right-hand) IR projector.
  for (int y = 0; y < height; ++y) {
    const float* z_row = exact.ptr<float>(y);
    float* out_row = out.ptr<float>(y);
    for (int x = 1; x < width; ++x) {
      const float left = z_row[x - 1], right = z_row[x];
      if (!is_jump(left, right)) continue;
      out_row[x - 1] = 0.0f;
      out_row[x] = 0.0f;
      if (left > right && right > 0.0f) {
        const double shadow_px =
            0.5 * kFocal_px * kProjectorBaseline_m * (1.0 / right - 1.0 / left);
        const int shadow = std::min(24, static_cast<int>(std::lround(shadow_px)));
        for (int k = x - 2; k >= std::max(0, x - 1 - shadow); --k) {
          if (!is_jump(z_row[k], right)) break;
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
      if (is_jump(above[x], here[x])) {
        out_above[x] = 0.0f;
        out_here[x] = 0.0f;
      }
    }
  }

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
