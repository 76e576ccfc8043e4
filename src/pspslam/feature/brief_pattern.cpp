#include "pspslam/feature/brief_pattern.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <tuple>

namespace pspslam {
namespace {

// Uniform in (0, 1]: built from the raw 32-bit output so that it does not depend on the
// implementation-defined std::uniform_real_distribution / generate_canonical.
double uniform_open_zero(std::mt19937& engine) {
  return (static_cast<double>(engine()) + 1.0) / 4294967296.0;
}

struct GaussianSampler {
  std::mt19937 engine;
  double sigma = 0.0;

  // Box-Muller; uses one of the two normals per call, which keeps the code obvious and costs
  // nothing that matters (the pattern is built once per extractor).
  float sample() {
    const double radius = std::sqrt(-2.0 * std::log(uniform_open_zero(engine)));
    const double angle = 2.0 * std::numbers::pi * uniform_open_zero(engine);
    return static_cast<float>(sigma * radius * std::cos(angle));
  }
};

// Learned by select_decorrelated_pairs on bonn_crowd_dev (50000 training keypoints from 50 frames;
// regenerate with tests/feature/learn_brief_pattern.cpp): indices into make_brief_candidates().
constexpr std::array<std::uint16_t, kBriefPairs> kLearnedPairIndices = {
    2658, 3050, 3465, 2971, 74,   2838, 81,   2545, 1975, 1008, 2258, 1814, 1889, 4009, 2679, 2001,
    2731, 1227, 3672, 1816, 3549, 3660, 3924, 2761, 18,   2945, 3628, 3314, 1404, 51,   1491, 577,
    561,  2992, 492,  77,   909,  1532, 3148, 2134, 2376, 998,  3608, 2951, 3918, 3394, 531,  2797,
    3409, 2874, 1172, 889,  3214, 554,  1341, 3282, 335,  1467, 2896, 1177, 2787, 416,  1504, 2754,
    3248, 1375, 1704, 288,  3528, 2537, 607,  3280, 1603, 2155, 3467, 62,   3535, 1198, 1080, 69,
    2384, 1477, 3200, 500,  3424, 1446, 2926, 1749, 774,  4058, 1287, 2342, 3113, 2836, 409,  459,
    220,  3422, 672,  1774, 368,  2529, 2606, 1345, 1262, 1587, 0,    4036, 3098, 3533, 976,  2224,
    512,  2015, 1154, 3501, 515,  1751, 1718, 3108, 3651, 3129, 2223, 570,  1200, 3914, 2334, 3140,
    1090, 3770, 2135, 3762, 3406, 3572, 3944, 1537, 432,  2539, 1701, 815,  2341, 1558, 2312, 2175,
    1980, 2814, 817,  1735, 1794, 707,  2466, 3302, 3700, 1529, 322,  3022, 2609, 3603, 2510, 3456,
    3689, 1954, 3650, 367,  2764, 410,  994,  14,   4093, 1741, 1273, 1777, 400,  467,  967,  2978,
    2027, 2618, 3673, 583,  912,  1657, 798,  2019, 2508, 1695, 1608, 323,  424,  2686, 2558, 2244,
    2182, 861,  3076, 786,  1948, 1738, 1428, 630,  3437, 1030, 2310, 1527, 2325, 3681, 1162, 3753,
    3631, 3935, 3951, 429,  2385, 759,  228,  453,  3161, 158,  778,  2789, 2301, 245,  1499, 392,
    1007, 700,  3514, 2271, 1195, 2733, 1507, 100,  2748, 2923, 4085, 472,  2826, 1750, 3975, 3474,
    1605, 1785, 964,  1224, 970,  2208, 708,  3459, 3448, 3739, 496,  1289, 2887, 1137, 2443, 3727,
};

int popcount(std::uint64_t bits) {
  bits = bits - ((bits >> 1) & 0x5555555555555555ULL);
  bits = (bits & 0x3333333333333333ULL) + ((bits >> 2) & 0x3333333333333333ULL);
  bits = (bits + (bits >> 4)) & 0x0F0F0F0F0F0F0F0FULL;
  return static_cast<int>((bits * 0x0101010101010101ULL) >> 56);
}

}  // namespace

BriefPattern make_brief_pattern(std::uint32_t seed) {
  constexpr double kPatchSize = 31.0;
  GaussianSampler sampler{std::mt19937(seed), kPatchSize / 5.0};

  // Integer sample positions: the extractor rounds rotated offsets anyway, and integer centres
  // make "same point" and "same pair" well defined.
  const auto sample_point = [&sampler](float& x, float& y) {
    do {
      x = std::round(sampler.sample());
      y = std::round(sampler.sample());
    } while (x * x + y * y > kBriefPatternRadius * kBriefPatternRadius);
  };

  BriefPattern pattern{};
  std::set<std::tuple<float, float, float, float>> used;
  for (BriefPair& pair : pattern) {
    while (true) {
      sample_point(pair.first_x, pair.first_y);
      sample_point(pair.second_x, pair.second_y);
      if (pair.first_x == pair.second_x && pair.first_y == pair.second_y) continue;
      // A pair and its swap test the same thing (the bit is just inverted): reject both.
      const auto forward =
          std::make_tuple(pair.first_x, pair.first_y, pair.second_x, pair.second_y);
      const auto swapped =
          std::make_tuple(pair.second_x, pair.second_y, pair.first_x, pair.first_y);
      if (used.contains(forward) || used.contains(swapped)) continue;
      used.insert(forward);
      break;
    }
  }
  return pattern;
}

std::vector<BriefPair> make_brief_candidates() {
  std::vector<BriefPair> candidates;
  candidates.reserve(static_cast<std::size_t>(kBriefCandidateChunks) * kBriefPairs);
  for (int chunk = 0; chunk < kBriefCandidateChunks; ++chunk) {
    const BriefPattern pattern =
        make_brief_pattern(kDefaultBriefSeed + static_cast<std::uint32_t>(chunk));
    candidates.insert(candidates.end(), pattern.begin(), pattern.end());
  }
  return candidates;
}

std::vector<int> select_decorrelated_pairs(std::span<const std::vector<std::uint64_t>> outcomes,
                                           int n_samples, int count, double max_bias) {
  const int n_candidates = static_cast<int>(outcomes.size());
  std::vector<double> mean(n_candidates);
  for (int c = 0; c < n_candidates; ++c) {
    int ones = 0;
    for (const std::uint64_t word : outcomes[c]) ones += popcount(word);
    mean[c] = static_cast<double>(ones) / n_samples;
  }
  std::vector<int> order(n_candidates);
  for (int c = 0; c < n_candidates; ++c) order[c] = c;
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(mean[a] - 0.5) < std::abs(mean[b] - 0.5); });

  const auto correlation = [&](int a, int b) {
    int both = 0;
    for (std::size_t w = 0; w < outcomes[a].size(); ++w)
      both += popcount(outcomes[a][w] & outcomes[b][w]);
    const double covariance = static_cast<double>(both) / n_samples - mean[a] * mean[b];
    const double variance = mean[a] * (1.0 - mean[a]) * mean[b] * (1.0 - mean[b]);
    return variance > 0.0 ? covariance / std::sqrt(variance) : 1.0;
  };

  std::vector<int> selected;
  // Integer steps: an accumulated 0.2 + 16 * 0.05 can exceed 1.0 and then admit exact copies.
  for (int step = 0; step <= 16; ++step) {
    const double threshold = 0.2 + 0.05 * step;
    selected.clear();
    for (const int candidate : order) {
      if (std::abs(mean[candidate] - 0.5) > max_bias) break;  // `order` is by increasing bias
      const bool independent = std::all_of(selected.begin(), selected.end(), [&](int kept) {
        return std::abs(correlation(candidate, kept)) < threshold;
      });
      if (!independent) continue;
      selected.push_back(candidate);
      if (static_cast<int>(selected.size()) == count) return selected;
    }
  }
  // Too few candidates within max_bias: complete with the least biased of the others.
  for (const int candidate : order) {
    if (static_cast<int>(selected.size()) == count) break;
    if (std::find(selected.begin(), selected.end(), candidate) == selected.end()) {
      selected.push_back(candidate);
    }
  }
  return selected;
}

BriefPattern make_learned_brief_pattern() {
  const std::vector<BriefPair> candidates = make_brief_candidates();
  BriefPattern pattern{};
  for (int i = 0; i < kBriefPairs; ++i) pattern[i] = candidates[kLearnedPairIndices[i]];
  return pattern;
}

}  // namespace pspslam
