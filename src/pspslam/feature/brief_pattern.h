#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace pspslam {

// One BRIEF test: compare the (smoothed) intensity at `first` with the one at `second`, both given
// as pixel offsets from the keypoint in the unrotated patch frame. The bit is 1 when first is
// darker.
struct BriefPair {
  float first_x = 0.0f;
  float first_y = 0.0f;
  float second_x = 0.0f;
  float second_y = 0.0f;
};

inline constexpr int kBriefPairs = 256;
// Every sample lies inside this radius so that any rotation of the pattern stays inside the
// 31x31 patch (and inside the image border the extractor keeps around each pyramid level).
inline constexpr float kBriefPatternRadius = 15.0f;
inline constexpr std::uint32_t kDefaultBriefSeed = 0x5eed0b1fu;

using BriefPattern = std::array<BriefPair, kBriefPairs>;

// A random sampling pattern, generated rather than tabulated: both points of each pair are drawn
// from an isotropic Gaussian with sigma = 31/5 (the BRIEF paper's G II, variance S^2/25 for a
// patch of size S = 31), samples outside kBriefPatternRadius are redrawn, and pairs whose two
// points coincide after rounding or that repeat an earlier pair are rejected. The generator only
// uses std::mt19937's raw output (fully specified by the standard) and our own Box-Muller
// transform, so the pattern is bit-identical on every platform and standard library.
BriefPattern make_brief_pattern(std::uint32_t seed = kDefaultBriefSeed);

// Candidate pool for the learned pattern: kBriefCandidateChunks G II patterns with the seeds
// kDefaultBriefSeed + chunk, concatenated (candidate i is pair i % 256 of chunk i / 256).
inline constexpr int kBriefCandidateChunks = 16;
std::vector<BriefPair> make_brief_candidates();

// Steering makes plain G II bits strongly biased: after rotating every patch to its intensity
// centroid, a pair whose second point lies further along the centroid direction is almost
// always brighter. On real images a typical bit is then far from balanced and unrelated
// descriptors differ in well under half of their 256 bits, which defeats the usual 50 / 100 bit
// matching thresholds. The ORB paper's remedy (rBRIEF) picks, from a large pool, tests whose
// mean is near 0.5 and which are mutually uncorrelated; this is that selection:
//
// outcomes[c] holds candidate c's bit on n_samples training keypoints, packed 64 per word.
// Candidates are visited by increasing |mean - 0.5|; one is kept when its absolute correlation
// with every kept one is below a threshold that starts at 0.2 and grows by 0.05 until `count`
// are kept. Unlike the paper, candidates with |mean - 0.5| > max_bias are not visited at all
// (used only if too few remain): otherwise the greedy pass, refusing correlated balanced tests,
// fills up with strongly biased ones, and unrelated descriptors again differ in far fewer than
// half of their bits; with max_bias they differ in close to half.
// Constant tests (mean 0 or 1) have bias 0.5 and are thus never picked unless forced to.
// Returns the kept candidate indices in selection order.
std::vector<int> select_decorrelated_pairs(std::span<const std::vector<std::uint64_t>> outcomes,
                                           int n_samples, int count, double max_bias = 0.15);

// The pattern the extractor uses: the kBriefPairs candidates that select_decorrelated_pairs
// chose on real frames (see tests/feature/learn_brief_pattern.cpp, which regenerates the index
// table in brief_pattern.cpp).
BriefPattern make_learned_brief_pattern();

}  // namespace pspslam
