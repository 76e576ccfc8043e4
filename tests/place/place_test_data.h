#pragma once

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "pspslam/feature/hamming.h"

namespace pspslam::testing_place {

// n uniformly random 256-bit descriptors (n x 32 CV_8UC1).
inline cv::Mat random_descriptors(int n, std::mt19937_64& rng) {
  cv::Mat out(n, kOrbDescriptorBytes, CV_8UC1);
  std::uniform_int_distribution<int> byte(0, 255);
  for (int r = 0; r < n; ++r) {
    for (int c = 0; c < kOrbDescriptorBytes; ++c) {
      out.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(byte(rng));
    }
  }
  return out;
}

// Flips `bits` distinct bits of a 32-byte descriptor.
inline void flip_random_bits(std::uint8_t* descriptor, int bits, std::mt19937_64& rng) {
  std::vector<int> positions(kOrbDescriptorBytes * 8);
  std::iota(positions.begin(), positions.end(), 0);
  std::shuffle(positions.begin(), positions.end(), rng);
  for (int i = 0; i < bits; ++i) {
    descriptor[positions[i] / 8] ^= static_cast<std::uint8_t>(1u << (positions[i] % 8));
  }
}

}  // namespace pspslam::testing_place
