#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace pspslam {

// Bytes in one ORB descriptor (256 bits).
inline constexpr int kOrbDescriptorBytes = 32;

namespace detail {

inline int popcount64(std::uint64_t bits) {
#if defined(__GNUC__) && !defined(__clang__) && !defined(__POPCNT__)
  // Without -mpopcnt GCC lowers std::popcount to a libgcc call; this SWAR sum stays inline and
  // branch-free, which matters because matching calls it millions of times per frame.
  bits = bits - ((bits >> 1) & 0x5555555555555555ULL);
  bits = (bits & 0x3333333333333333ULL) + ((bits >> 2) & 0x3333333333333333ULL);
  bits = (bits + (bits >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
  return static_cast<int>((bits * 0x0101010101010101ULL) >> 56);
#else
  return std::popcount(bits);
#endif
}

}  // namespace detail

// Number of differing bits between two 256-bit ORB descriptors (32 bytes each, any alignment).
inline int hamming_distance(const std::uint8_t* a, const std::uint8_t* b) {
  int distance = 0;
  for (int offset = 0; offset < kOrbDescriptorBytes; offset += 8) {
    std::uint64_t word_a = 0;
    std::uint64_t word_b = 0;
    // memcpy instead of a pointer cast: descriptor rows need not be 8-byte aligned, and the
    // compiler turns it into a single unaligned load.
    std::memcpy(&word_a, a + offset, sizeof(word_a));
    std::memcpy(&word_b, b + offset, sizeof(word_b));
    distance += detail::popcount64(word_a ^ word_b);
  }
  return distance;
}

}  // namespace pspslam
