#include "pspslam/feature/gaussian_blur.h"

#include <cstdint>

namespace pspslam {
namespace {

// exp(-x^2 / (2 * 2^2)) for x = 0..3, normalised to sum 256 over the 7 taps.
constexpr std::uint16_t kCenterWeight = 56;
constexpr std::uint16_t kWeight1 = 49;
constexpr std::uint16_t kWeight2 = 33;
constexpr std::uint16_t kWeight3 = 18;
static_assert(kCenterWeight + 2 * (kWeight1 + kWeight2 + kWeight3) == 256);

// 255 * 256 + 128 < 65536: the weighted sum and its rounding fit in 16 bits, so the compiler can
// use 8 or 16 lanes per instruction instead of 4 for 32-bit arithmetic.
inline std::uint8_t weighted_sum(std::uint16_t center, std::uint16_t pair1, std::uint16_t pair2,
                                 std::uint16_t pair3) {
  const auto sum = static_cast<std::uint16_t>(kCenterWeight * center + kWeight1 * pair1 +
                                              kWeight2 * pair2 + kWeight3 * pair3 + 128);
  return static_cast<std::uint8_t>(sum >> 8);
}

}  // namespace

void gaussian_blur_7x7(const cv::Mat& src, cv::Mat& vertical_pass, cv::Mat& dst) {
  CV_Assert(src.type() == CV_8UC1);
  vertical_pass.create(src.size(), CV_8UC1);
  dst.create(src.size(), CV_8UC1);
  constexpr int radius = kDescriptorBlurRadius;
  const int rows = src.rows;
  const int cols = src.cols;
  if (rows <= 2 * radius || cols <= 2 * radius) return;

  // Vertical pass over whole rows (contiguous, vectorises across x).
  for (int y = radius; y < rows - radius; ++y) {
    const std::uint8_t* up3 = src.ptr<std::uint8_t>(y - 3);
    const std::uint8_t* up2 = src.ptr<std::uint8_t>(y - 2);
    const std::uint8_t* up1 = src.ptr<std::uint8_t>(y - 1);
    const std::uint8_t* center = src.ptr<std::uint8_t>(y);
    const std::uint8_t* down1 = src.ptr<std::uint8_t>(y + 1);
    const std::uint8_t* down2 = src.ptr<std::uint8_t>(y + 2);
    const std::uint8_t* down3 = src.ptr<std::uint8_t>(y + 3);
    std::uint8_t* out = vertical_pass.ptr<std::uint8_t>(y);
    for (int x = 0; x < cols; ++x) {
      out[x] = weighted_sum(center[x], static_cast<std::uint16_t>(up1[x] + down1[x]),
                            static_cast<std::uint16_t>(up2[x] + down2[x]),
                            static_cast<std::uint16_t>(up3[x] + down3[x]));
    }
  }
  // Horizontal pass on the rows the vertical pass produced.
  for (int y = radius; y < rows - radius; ++y) {
    const std::uint8_t* in = vertical_pass.ptr<std::uint8_t>(y);
    std::uint8_t* out = dst.ptr<std::uint8_t>(y);
    for (int x = radius; x < cols - radius; ++x) {
      out[x] = weighted_sum(in[x], static_cast<std::uint16_t>(in[x - 1] + in[x + 1]),
                            static_cast<std::uint16_t>(in[x - 2] + in[x + 2]),
                            static_cast<std::uint16_t>(in[x - 3] + in[x + 3]));
    }
  }
}

}  // namespace pspslam
