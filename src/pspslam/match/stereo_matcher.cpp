#include "pspslam/match/stereo_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "pspslam/feature/hamming.h"

namespace pspslam {
namespace {

struct Candidate {
  int left = -1;
  float right_u = 0.0f;
  float sad = 0.0f;
};

// Zero-mean SAD of the (2h+1)^2 patches centred at (ul, v) on the left and (ur, v) on the right:
// removing each patch's mean absorbs a gain/offset difference between the two cameras.
float zero_mean_sad(const cv::Mat& left, const cv::Mat& right, int ul, int ur, int v, int h) {
  int sum_left = 0, sum_right = 0;
  for (int dy = -h; dy <= h; ++dy) {
    const std::uint8_t* l = left.ptr<std::uint8_t>(v + dy) + ul;
    const std::uint8_t* r = right.ptr<std::uint8_t>(v + dy) + ur;
    for (int dx = -h; dx <= h; ++dx) {
      sum_left += l[dx];
      sum_right += r[dx];
    }
  }
  const int n = (2 * h + 1) * (2 * h + 1);
  const float offset = static_cast<float>(sum_left - sum_right) / static_cast<float>(n);
  float sad = 0.0f;
  for (int dy = -h; dy <= h; ++dy) {
    const std::uint8_t* l = left.ptr<std::uint8_t>(v + dy) + ul;
    const std::uint8_t* r = right.ptr<std::uint8_t>(v + dy) + ur;
    for (int dx = -h; dx <= h; ++dx) sad += std::abs(static_cast<float>(l[dx] - r[dx]) - offset);
  }
  return sad / static_cast<float>(n);
}

// Right keypoints by the rows their band covers: the lookup per left keypoint is one row.
// Two flat arrays (row y's keypoints are keypoints[start[y], start[y + 1]), in ascending index)
// rather than a vector per row: no allocation per keypoint.
struct RowIndex {
  std::vector<int> start;
  std::vector<int> keypoints;
};

RowIndex index_by_row(const std::vector<cv::KeyPoint>& right, const ScalePyramid& pyramid,
                      int rows) {
  const auto band_rows = [&](const cv::KeyPoint& keypoint) {
    const float band = 2.0f * static_cast<float>(pyramid.scale[keypoint.octave]);
    return std::pair{std::max(0, static_cast<int>(std::floor(keypoint.pt.y - band))),
                     std::min(rows - 1, static_cast<int>(std::ceil(keypoint.pt.y + band)))};
  };
  RowIndex index;
  std::vector<int>& row_start = index.start;
  row_start.assign(static_cast<size_t>(rows) + 1, 0);
  for (const cv::KeyPoint& keypoint : right) {
    const auto [first, last] = band_rows(keypoint);
    for (int y = first; y <= last; ++y) ++row_start[static_cast<size_t>(y) + 1];
  }
  for (int y = 0; y < rows; ++y)
    row_start[static_cast<size_t>(y) + 1] += row_start[static_cast<size_t>(y)];
  index.keypoints.resize(static_cast<size_t>(row_start.back()));
  std::vector<int> row_fill(row_start.begin(), row_start.end() - 1);
  for (size_t j = 0; j < right.size(); ++j) {
    const auto [first, last] = band_rows(right[j]);
    for (int y = first; y <= last; ++y)
      index.keypoints[static_cast<size_t>(row_fill[static_cast<size_t>(y)]++)] =
          static_cast<int>(j);
  }
  return index;
}

// The right keypoint on `row` nearest in descriptor to the left one, within a level of its
// octave and a disparity in [0, max_disparity]; -1 for none within max_descriptor_distance.
int best_descriptor_match(const cv::KeyPoint& kl, const std::uint8_t* descriptor, int row,
                          const std::vector<cv::KeyPoint>& right, const cv::Mat& right_descriptors,
                          const RowIndex& index, float max_disparity, int max_descriptor_distance) {
  int best_distance = max_descriptor_distance + 1;
  int best = -1;
  for (int r = index.start[static_cast<size_t>(row)]; r < index.start[static_cast<size_t>(row) + 1];
       ++r) {
    const int j = index.keypoints[static_cast<size_t>(r)];
    const cv::KeyPoint& kr = right[static_cast<size_t>(j)];
    if (std::abs(kr.octave - kl.octave) > 1) continue;
    const float disparity = kl.pt.x - kr.pt.x;
    if (disparity < 0.0f || disparity > max_disparity) continue;
    const int distance = hamming_distance(descriptor, right_descriptors.ptr<std::uint8_t>(j));
    if (distance < best_distance) {
      best_distance = distance;
      best = j;
    }
  }
  return best;
}

// SAD search around the descriptor match (right column ur0), on the full-resolution images,
// with a parabola through the best SAD and its neighbours for the sub-pixel disparity. False
// when the window leaves the image, the curve is flat or the disparity is out of range.
bool refine_by_sad(const cv::Mat& left_gray, const cv::Mat& right_gray, const cv::KeyPoint& kl,
                   int ur0, int search, int h, float max_disparity, std::vector<float>& sad_curve,
                   Candidate& candidate) {
  const int rows = right_gray.rows;
  const int cols = right_gray.cols;
  const int row = cvRound(kl.pt.y);
  const int uc = cvRound(kl.pt.x);
  if (row - h < 0 || row + h >= rows || uc - h < 0 || uc + h >= cols) return false;
  if (ur0 - search - 1 - h < 0 || ur0 + search + 1 + h >= cols) return false;
  sad_curve.resize(static_cast<size_t>(2 * search + 3));
  for (int k = -search - 1; k <= search + 1; ++k) {
    sad_curve[static_cast<size_t>(k + search + 1)] =
        zero_mean_sad(left_gray, right_gray, uc, ur0 + k, row, h);
  }
  // Best inside the searched range; its two neighbours (always present) fit the parabola.
  int best_k = 0;
  for (int k = -search; k <= search; ++k) {
    if (sad_curve[static_cast<size_t>(k + search + 1)] <
        sad_curve[static_cast<size_t>(best_k + search + 1)])
      best_k = k;
  }
  const float s0 = sad_curve[static_cast<size_t>(best_k + search)];
  const float s1 = sad_curve[static_cast<size_t>(best_k + search + 1)];
  const float s2 = sad_curve[static_cast<size_t>(best_k + search + 2)];
  const float curvature = s0 - 2.0f * s1 + s2;
  if (!(curvature > 0.0f)) return false;  // flat: no texture to place the match on
  const float delta = 0.5f * (s0 - s2) / curvature;
  if (std::abs(delta) > 1.0f) return false;
  // The patch sits at the rounded left position: the disparity is measured there, and the
  // keypoint's own right coordinate keeps that disparity.
  const float disparity = static_cast<float>(uc - (ur0 + best_k)) - delta;
  if (disparity <= 0.0f || disparity > max_disparity) return false;
  candidate.right_u = kl.pt.x - disparity;
  candidate.sad = s1;
  return true;
}

// Reject matches whose appearance differs much more than the pair's typical match; the others
// give their keypoint its depth.
void keep_typical_matches(const std::vector<Candidate>& candidates,
                          const std::vector<cv::KeyPoint>& left, double bf,
                          double max_sad_to_median, StereoDepths& out) {
  std::vector<float> sads(candidates.size());
  for (size_t c = 0; c < candidates.size(); ++c) sads[c] = candidates[c].sad;
  std::nth_element(sads.begin(), sads.begin() + static_cast<std::ptrdiff_t>(sads.size() / 2),
                   sads.end());
  // (At least one grey level per pixel: a noiseless rendered pair has a median near 0.)
  const float limit = std::max(1.0f, static_cast<float>(max_sad_to_median) * sads[sads.size() / 2]);
  for (const Candidate& c : candidates) {
    if (c.sad > limit) continue;
    const size_t i = static_cast<size_t>(c.left);
    const float disparity = left[i].pt.x - c.right_u;
    out.depth[i] = static_cast<float>(bf / disparity);
    out.right_u[i] = c.right_u;
    ++out.matched;
  }
}

}  // namespace

void match_stereo(const std::vector<cv::KeyPoint>& left, const cv::Mat& left_descriptors,
                  const std::vector<cv::KeyPoint>& right, const cv::Mat& right_descriptors,
                  const cv::Mat& left_gray, const cv::Mat& right_gray, const ScalePyramid& pyramid,
                  double bf, const StereoMatchOptions& options, StereoDepths& out) {
  const size_t n = left.size();
  out.depth.assign(n, -1.0f);
  out.right_u.assign(n, std::numeric_limits<float>::quiet_NaN());
  out.matched = 0;
  if (n == 0 || right.empty()) return;
  const int rows = right_gray.rows;
  const RowIndex index = index_by_row(right, pyramid, rows);

  const float max_disparity = static_cast<float>(bf / options.min_depth_m);
  std::vector<Candidate> candidates;
  candidates.reserve(n);
  std::vector<float> sad_curve;
  for (size_t i = 0; i < n; ++i) {
    const cv::KeyPoint& kl = left[i];
    const int row = cvRound(kl.pt.y);
    if (row < 0 || row >= rows) continue;
    const int best = best_descriptor_match(
        kl, left_descriptors.ptr<std::uint8_t>(static_cast<int>(i)), row, right, right_descriptors,
        index, max_disparity, options.max_descriptor_distance);
    if (best < 0) continue;
    const int ur0 = cvRound(right[static_cast<size_t>(best)].pt.x);
    const int search = std::max(
        1, static_cast<int>(std::lround(options.sad_search_px * pyramid.scale[kl.octave])));
    Candidate candidate{.left = static_cast<int>(i)};
    if (refine_by_sad(left_gray, right_gray, kl, ur0, search, options.sad_half_window,
                      max_disparity, sad_curve, candidate))
      candidates.push_back(candidate);
  }
  if (candidates.empty()) return;
  keep_typical_matches(candidates, left, bf, options.max_sad_to_median, out);
}

}  // namespace pspslam
