#include <gtest/gtest.h>

#include <array>
#include <bit>
#include <cstdint>
#include <random>

#include "pspslam/feature/hamming.h"

namespace pspslam {
namespace {

int naive_bit_difference(const std::uint8_t* a, const std::uint8_t* b) {
  int count = 0;
  for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
    for (int bit = 0; bit < 8; ++bit) count += ((a[byte] >> bit) & 1) != ((b[byte] >> bit) & 1);
  }
  return count;
}

TEST(Hamming, MatchesNaiveBitCountOnRandomAndUnalignedDescriptors) {
  std::mt19937 engine(42);
  // One spare byte in front so that odd offsets test unaligned rows.
  std::array<std::uint8_t, kOrbDescriptorBytes + 1> a{};
  std::array<std::uint8_t, kOrbDescriptorBytes + 1> b{};
  for (int trial = 0; trial < 2000; ++trial) {
    for (auto& byte : a) byte = static_cast<std::uint8_t>(engine());
    for (auto& byte : b) byte = static_cast<std::uint8_t>(engine());
    const int offset = trial % 2;
    ASSERT_EQ(hamming_distance(a.data() + offset, b.data() + offset),
              naive_bit_difference(a.data() + offset, b.data() + offset))
        << "trial " << trial;
  }
}

TEST(Hamming, ExtremesAndSingleBits) {
  std::array<std::uint8_t, kOrbDescriptorBytes> zeros{};
  std::array<std::uint8_t, kOrbDescriptorBytes> ones{};
  ones.fill(0xFF);
  EXPECT_EQ(hamming_distance(zeros.data(), zeros.data()), 0);
  EXPECT_EQ(hamming_distance(zeros.data(), ones.data()), 256);
  for (int bit = 0; bit < 256; bit += 37) {
    std::array<std::uint8_t, kOrbDescriptorBytes> single{};
    single[bit / 8] = static_cast<std::uint8_t>(1u << (bit % 8));
    EXPECT_EQ(hamming_distance(zeros.data(), single.data()), 1) << "bit " << bit;
    EXPECT_EQ(hamming_distance(ones.data(), single.data()), 255) << "bit " << bit;
  }
}

TEST(Hamming, Popcount64AgreesWithStdPopcount) {
  std::mt19937_64 engine(3);
  for (int trial = 0; trial < 1000; ++trial) {
    const std::uint64_t value = engine();
    ASSERT_EQ(detail::popcount64(value), std::popcount(value)) << value;
  }
  EXPECT_EQ(detail::popcount64(~0ULL), 64);
}

}  // namespace
}  // namespace pspslam
