#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>

#include "pspslam/feature/hamming.h"

namespace pspslam {

// One 256-bit ORB descriptor stored by value (a map point keeps its representative one without
// a heap allocation).
using OrbDescriptor = std::array<std::uint8_t, 32>;

inline OrbDescriptor descriptor_from_row(const cv::Mat& descriptors, int row) {
  OrbDescriptor d;
  std::memcpy(d.data(), descriptors.ptr<std::uint8_t>(row), d.size());
  return d;
}

inline int descriptor_distance(const std::uint8_t* a, const std::uint8_t* b) {
  return hamming_distance(a, b);
}

inline int descriptor_distance(const OrbDescriptor& a, const std::uint8_t* b) {
  return descriptor_distance(a.data(), b);
}

}  // namespace pspslam
