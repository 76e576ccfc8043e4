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
    2658, 3050, 3465, 2971, 74,   2838, 2545, 1975, 1008, 1889, 4009, 2731, 1227, 3672, 3549, 2945,
    3628, 51,   2992, 1532, 998,  420,  1467, 1856, 416,  2754, 3248, 288,  3280, 62,   2384, 1477,
    3200, 500,  3424, 4058, 368,  2606, 1345, 1587, 1154, 3651, 2135, 3944, 2539, 1529, 1954, 367,
    3896, 994,  1521, 967,  2618, 3673, 912,  291,  861,  164,  3753, 429,  3161, 158,  778,  2301,
    1007, 3514, 2733, 1507, 2826, 3474, 925,  1475, 1846, 3981, 789,  1972, 309,  211,  3704, 3490,
    2567, 317,  2303, 2353, 1825, 3864, 1652, 1541, 1015, 1827, 381,  942,  2514, 1101, 1698, 1291,
    684,  3099, 2062, 908,  520,  185,  1320, 4067, 2147, 3105, 628,  1072, 1756, 797,  41,   3623,
    2469, 2284, 3425, 1483, 2682, 284,  933,  3884, 1928, 1451, 2345, 1851, 1964, 230,  1578, 2954,
    2875, 623,  3539, 2506, 3417, 3381, 1496, 2486, 3866, 1293, 260,  6,    2043, 983,  1660, 853,
    602,  2298, 539,  1170, 2067, 713,  1471, 3756, 3785, 3480, 3186, 945,  2579, 1989, 3327, 1482,
    1867, 517,  236,  2701, 2825, 4080, 573,  3060, 4065, 3867, 3084, 2676, 3203, 1543, 2596, 2909,
    279,  2209, 1932, 1714, 3583, 3037, 768,  3399, 3802, 732,  733,  2189, 2860, 1420, 2128, 3777,
    1792, 3457, 1114, 1116, 3827, 2011, 1645, 1733, 1265, 631,  3846, 115,  1299, 3451, 1237, 3654,
    738,  1384, 3908, 2205, 1439, 1772, 1062, 2620, 3331, 3790, 1403, 907,  2069, 396,  781,  338,
    1356, 813,  3473, 2320, 2359, 2375, 1148, 941,  3434, 3090, 1368, 2717, 2780, 1638, 2694, 1052,
    1717, 2959, 3048, 3590, 2876, 3289, 3761, 2918, 1613, 1829, 3041, 93,   3611, 3932, 1153, 2758,
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
  for (double threshold = 0.2; threshold <= 1.0 + 1e-9; threshold += 0.05) {
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
