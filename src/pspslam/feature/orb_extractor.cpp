#include "pspslam/feature/orb_extractor.h"

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "pspslam/core/error.h"
#include "pspslam/feature/gaussian_blur.h"

namespace pspslam {
namespace {

// Radius of the orientation patch (the 31x31 ORB patch) and of the BRIEF pattern.
constexpr int kPatchRadius = 15;
constexpr float kPatchSize = 2.0f * kPatchRadius + 1.0f;
// cv::FAST never reports corners closer than this to the border of the image it runs on.
constexpr int kFastBorder = 3;
// Reflected border kept around each level: a keypoint at kFastBorder still has its whole
// (rotated) patch of radius kPatchRadius inside the buffer, plus the 3 px the 7x7 blur reads.
constexpr int kLevelBorder = kPatchRadius + 4;
// FAST is run per cell of about this size so that weakly textured cells still get corners.
constexpr int kCellSize = 30;
// The steered pattern is tabulated for this many orientations (3 degree steps): rotating 512
// points per keypoint at run time cost more than the rest of the description. Rounding the angle
// to the nearest step moves a sample at the patch rim by at most 15 * sin(1.5 deg) = 0.4 px.
constexpr int kAngleBins = 120;

void require(bool condition, const std::string& message) {
  if (!condition) throw Error("OrbExtractor: " + message);
}

}  // namespace

OrbExtractor::OrbExtractor(const OrbConfig& config)
    : OrbExtractor(config, make_learned_brief_pattern()) {}

OrbExtractor::OrbExtractor(const OrbConfig& config, const BriefPattern& pattern)
    : config_(config), pattern_(pattern) {
  require(config.n_features > 0,
          "orb.n_features must be > 0, got " + std::to_string(config.n_features));
  require(config.n_levels > 0, "orb.n_levels must be > 0, got " + std::to_string(config.n_levels));
  require(config.scale_factor > 1.0,
          "orb.scale_factor must be > 1, got " + std::to_string(config.scale_factor));
  require(config.initial_fast_threshold >= 1 && config.initial_fast_threshold <= 255,
          "orb.initial_fast_threshold must be in 1..255, got " +
              std::to_string(config.initial_fast_threshold));
  require(
      config.min_fast_threshold >= 1 && config.min_fast_threshold <= config.initial_fast_threshold,
      "orb.min_fast_threshold must be in 1..initial_fast_threshold (" +
          std::to_string(config.initial_fast_threshold) + "), got " +
          std::to_string(config.min_fast_threshold));

  const int n_levels = config.n_levels;
  scale_factors_.resize(n_levels);
  inv_scale_factors_.resize(n_levels);
  double scale = 1.0;
  for (int level = 0; level < n_levels; ++level) {
    scale_factors_[level] = static_cast<float>(scale);
    inv_scale_factors_[level] = static_cast<float>(1.0 / scale);
    scale *= config.scale_factor;
  }

  // Level l has 1/scale^(2l) of the area but features are spread by 1/scale^l (ORB-SLAM2):
  // coarse levels see larger, more distinctive structures, so they get a bit more than their
  // area share. The last level takes the rounding remainder so the total is exact.
  features_per_level_.resize(n_levels);
  const double ratio = 1.0 / config.scale_factor;
  double level_share =
      config.n_features * (1.0 - ratio) / (1.0 - std::pow(ratio, static_cast<double>(n_levels)));
  int assigned = 0;
  for (int level = 0; level < n_levels - 1; ++level) {
    features_per_level_[level] = static_cast<int>(std::lround(level_share));
    assigned += features_per_level_[level];
    level_share *= ratio;
  }
  features_per_level_[n_levels - 1] = std::max(0, config.n_features - assigned);

  // Circular patch: row offset v spans u in [-umax, umax] with u^2 + v^2 <= r^2. The set is
  // symmetric under swapping u and v, which keeps the centroid orientation rotation invariant.
  for (int v = 0; v <= kPatchRadius; ++v) {
    int u = 0;
    while ((u + 1) * (u + 1) + v * v <= kPatchRadius * kPatchRadius) ++u;
    umax_[v] = u;
  }

  rotated_pattern_.resize(static_cast<std::size_t>(kAngleBins) * kBriefPairs);
  for (int bin = 0; bin < kAngleBins; ++bin) {
    const double radians = 2.0 * std::numbers::pi * bin / kAngleBins;
    const double cos_angle = std::cos(radians);
    const double sin_angle = std::sin(radians);
    const auto rotate = [&](float x, float y, std::int8_t& rotated_x, std::int8_t& rotated_y) {
      rotated_x = static_cast<std::int8_t>(std::lround(x * cos_angle - y * sin_angle));
      rotated_y = static_cast<std::int8_t>(std::lround(x * sin_angle + y * cos_angle));
    };
    for (int i = 0; i < kBriefPairs; ++i) {
      const BriefPair& pair = pattern_[i];
      RotatedPair& rotated = rotated_pattern_[static_cast<std::size_t>(bin) * kBriefPairs + i];
      rotate(pair.first_x, pair.first_y, rotated.first_x, rotated.first_y);
      rotate(pair.second_x, pair.second_y, rotated.second_x, rotated.second_y);
    }
  }

  pyramid_.resize(n_levels);
  level_candidates_.resize(n_levels);
  level_available_.resize(n_levels);
  level_budget_ = features_per_level_;
}

void OrbExtractor::build_pyramid(const cv::Mat& gray) {
  for (int level = 0; level < levels(); ++level) {
    PyramidLevel& pyramid_level = pyramid_[level];
    const cv::Size size(static_cast<int>(std::lround(gray.cols * inv_scale_factors_[level])),
                        static_cast<int>(std::lround(gray.rows * inv_scale_factors_[level])));
    if (size.width < 1 || size.height < 1 || (level > 0 && pyramid_[level - 1].image.empty())) {
      // A tiny input runs out of pixels before the last level: such levels stay empty.
      pyramid_level.image = cv::Mat();
      pyramid_level.blurred = cv::Mat();
      continue;
    }
    const cv::Size padded_size(size.width + 2 * kLevelBorder, size.height + 2 * kLevelBorder);
    // create() is a no-op when the size is unchanged: frames of one sequence reuse the buffers.
    pyramid_level.padded.create(padded_size, CV_8UC1);
    pyramid_level.blurred_padded.create(padded_size, CV_8UC1);
    const cv::Rect inner(kLevelBorder, kLevelBorder, size.width, size.height);
    pyramid_level.image = pyramid_level.padded(inner);
    pyramid_level.blurred = pyramid_level.blurred_padded(inner);
    pyramid_level.scale_x = static_cast<float>(gray.cols) / static_cast<float>(size.width);
    pyramid_level.scale_y = static_cast<float>(gray.rows) / static_cast<float>(size.height);

    // Each level is resized from the previous one (cheaper than from level 0 and what ORB-SLAM2
    // does); the resize writes straight into the view inside the padded buffer.
    if (level == 0) {
      gray.copyTo(pyramid_level.image);
    } else {
      cv::resize(pyramid_[level - 1].image, pyramid_level.image, size, 0.0, 0.0, cv::INTER_LINEAR);
    }
    // In place: with BORDER_ISOLATED copyMakeBorder treats the view as the source and only
    // fills the border around it (the inner rows are already where they belong).
    cv::copyMakeBorder(pyramid_level.image, pyramid_level.padded, kLevelBorder, kLevelBorder,
                       kLevelBorder, kLevelBorder, cv::BORDER_REFLECT_101 | cv::BORDER_ISOLATED);
    // BRIEF compares smoothed intensities (7x7, sigma 2, as the ORB paper): single pixels are
    // too noisy for binary tests.
    gaussian_blur_7x7(pyramid_level.padded, blur_scratch_, pyramid_level.blurred_padded);
  }
}

bool OrbExtractor::is_ignored(const cv::Mat& ignore_mask, float level_x, float level_y,
                              const PyramidLevel& level) const {
  if (ignore_mask.empty()) return false;
  // Tested on the level-0 mask at the keypoint's level-0 position rather than on a resized mask:
  // a down-sampled mask can lose thin masked strips, and this is the exact criterion the
  // returned keypoint has to meet anyway.
  const cv::Point2f image = level.to_image(level_x, level_y);
  const int x = std::clamp(static_cast<int>(std::lround(image.x)), 0, ignore_mask.cols - 1);
  const int y = std::clamp(static_cast<int>(std::lround(image.y)), 0, ignore_mask.rows - 1);
  return ignore_mask.ptr<std::uint8_t>(y)[x] != 0;
}

void OrbExtractor::detect_candidates(int level, const cv::Mat& ignore_mask) {
  std::vector<cv::KeyPoint>& candidates = level_candidates_[level];
  candidates.clear();
  const cv::Mat& image = pyramid_[level].image;
  const int region_width = image.cols - 2 * kFastBorder;
  const int region_height = image.rows - 2 * kFastBorder;
  if (region_width <= 0 || region_height <= 0) return;

  const int n_cols = std::max(1, region_width / kCellSize);
  const int n_rows = std::max(1, region_height / kCellSize);
  const int cell_width = (region_width + n_cols - 1) / n_cols;
  const int cell_height = (region_height + n_rows - 1) / n_rows;
  cell_counts_.assign(static_cast<std::size_t>(n_cols) * n_rows, 0);

  // ORB-SLAM2 runs FAST cell by cell. One pass over the whole level at the initial threshold
  // finds the same corners (cells only overlap by FAST's own 3 px margin) without the per-call
  // overhead. Corners found in a masked place do not count, so that a cell whose strong corners
  // are all masked still falls back to weak ones.
  cv::FAST(image, fast_keypoints_, config_.initial_fast_threshold, true);
  for (const cv::KeyPoint& keypoint : fast_keypoints_) {
    if (is_ignored(ignore_mask, keypoint.pt.x, keypoint.pt.y, pyramid_[level])) continue;
    const int col = (static_cast<int>(keypoint.pt.x) - kFastBorder) / cell_width;
    const int row = (static_cast<int>(keypoint.pt.y) - kFastBorder) / cell_height;
    ++cell_counts_[static_cast<std::size_t>(row) * n_cols + col];
    candidates.push_back(keypoint);
  }
  for (int row = 0; row < n_rows; ++row) {
    for (int col = 0; col < n_cols; ++col) {
      if (cell_counts_[static_cast<std::size_t>(row) * n_cols + col] > 0) continue;
      // Cells left empty get a second pass at the minimum threshold. On real frames many cells
      // are empty, so horizontally adjacent empty cells share one FAST call: cheaper than one
      // minimum-threshold pass over the whole level (whose extra corners cost more score
      // computations) and than one call per cell.
      int last_col = col;
      while (last_col + 1 < n_cols &&
             cell_counts_[static_cast<std::size_t>(row) * n_cols + last_col + 1] == 0)
        ++last_col;
      const int min_x = kFastBorder + col * cell_width;
      const int min_y = kFastBorder + row * cell_height;
      const int max_x =
          std::min(kFastBorder + (last_col + 1) * cell_width, image.cols - kFastBorder);
      const int max_y = std::min(min_y + cell_height, image.rows - kFastBorder);
      col = last_col;
      if (max_x <= min_x || max_y <= min_y) continue;
      const cv::Rect window(min_x - kFastBorder, min_y - kFastBorder,
                            max_x - min_x + 2 * kFastBorder, max_y - min_y + 2 * kFastBorder);
      cv::FAST(image(window), fast_keypoints_, config_.min_fast_threshold, true);
      for (cv::KeyPoint keypoint : fast_keypoints_) {
        keypoint.pt.x += static_cast<float>(window.x);
        keypoint.pt.y += static_cast<float>(window.y);
        if (is_ignored(ignore_mask, keypoint.pt.x, keypoint.pt.y, pyramid_[level])) continue;
        candidates.push_back(keypoint);
      }
    }
  }
}

void OrbExtractor::detect_candidates_at_min_threshold(int level, const cv::Mat& ignore_mask) {
  // One pass over the whole level: a FAST score is the highest threshold at which the point is a
  // corner, so this finds every corner of the gridded pass (non-maximum suppression keeps them:
  // a neighbour that outscores one was found before too) plus the weak ones of cells that had a
  // strong corner somewhere. The quadtree still prefers the strongest corner of each node.
  std::vector<cv::KeyPoint>& candidates = level_candidates_[level];
  candidates.clear();
  const cv::Mat& image = pyramid_[level].image;
  if (image.cols <= 2 * kFastBorder || image.rows <= 2 * kFastBorder) return;
  cv::FAST(image, fast_keypoints_, config_.min_fast_threshold, true);
  for (const cv::KeyPoint& keypoint : fast_keypoints_) {
    if (is_ignored(ignore_mask, keypoint.pt.x, keypoint.pt.y, pyramid_[level])) continue;
    candidates.push_back(keypoint);
  }
}

float OrbExtractor::orientation_degrees(const cv::Mat& image, const cv::Point2f& position) const {
  // Intensity centroid (Rosin; ORB paper): the angle of the vector from the patch centre to the
  // centroid of the circular patch's intensity, m01 / m10 moments. Rows are summed in +v / -v
  // pairs to halve the loop.
  const auto step = static_cast<std::ptrdiff_t>(image.step1());
  const std::uint8_t* center = image.ptr<std::uint8_t>(static_cast<int>(std::lround(position.y))) +
                               static_cast<int>(std::lround(position.x));
  int moment_10 = 0;
  int moment_01 = 0;
  for (int u = -kPatchRadius; u <= kPatchRadius; ++u) moment_10 += u * center[u];
  for (int v = 1; v <= kPatchRadius; ++v) {
    int row_difference = 0;
    const std::uint8_t* below = center + v * step;
    const std::uint8_t* above = center - v * step;
    const int half_width = umax_[v];
    for (int u = -half_width; u <= half_width; ++u) {
      const int value_below = below[u];
      const int value_above = above[u];
      row_difference += value_below - value_above;
      moment_10 += u * (value_below + value_above);
    }
    moment_01 += v * row_difference;
  }
  float degrees = static_cast<float>(
      std::atan2(static_cast<double>(moment_01), static_cast<double>(moment_10)) * 180.0 /
      std::numbers::pi);
  if (degrees < 0.0f) degrees += 360.0f;
  if (degrees >= 360.0f) degrees -= 360.0f;
  return degrees;
}

void OrbExtractor::describe(const cv::Mat& blurred, const cv::KeyPoint& keypoint,
                            std::uint8_t* descriptor) const {
  // Steered BRIEF: the pattern is rotated by the keypoint's angle so that the same physical
  // pixels are compared whatever the image rotation.
  int bin = static_cast<int>(keypoint.angle * (kAngleBins / 360.0f) + 0.5f);
  if (bin >= kAngleBins) bin -= kAngleBins;
  const RotatedPair* pairs = &rotated_pattern_[static_cast<std::size_t>(bin) * kBriefPairs];
  const auto step = static_cast<std::ptrdiff_t>(blurred.step1());
  const std::uint8_t* center =
      blurred.ptr<std::uint8_t>(static_cast<int>(std::lround(keypoint.pt.y))) +
      static_cast<int>(std::lround(keypoint.pt.x));
  for (int byte = 0; byte < kOrbDescriptorBytes; ++byte) {
    unsigned bits = 0;
    for (int bit = 0; bit < 8; ++bit) {
      const RotatedPair& pair = pairs[byte * 8 + bit];
      const bool darker =
          center[pair.first_y * step + pair.first_x] < center[pair.second_y * step + pair.second_x];
      bits |= static_cast<unsigned>(darker) << bit;
    }
    descriptor[byte] = static_cast<std::uint8_t>(bits);
  }
}

void OrbExtractor::extract(const cv::Mat& gray, const cv::Mat& ignore_mask, OrbFeatures& out) {
  require(!gray.empty() && gray.type() == CV_8UC1,
          "extract() needs a non-empty CV_8UC1 image, got type " + std::to_string(gray.type()) +
              " size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows));
  require(
      ignore_mask.empty() || (ignore_mask.type() == CV_8UC1 && ignore_mask.size() == gray.size()),
      "extract() ignore_mask must be empty or CV_8UC1 of the image size " +
          std::to_string(gray.cols) + "x" + std::to_string(gray.rows) + ", got type " +
          std::to_string(ignore_mask.type()) + " size " + std::to_string(ignore_mask.cols) + "x" +
          std::to_string(ignore_mask.rows));

  build_pyramid(gray);

  for (int level = 0; level < levels(); ++level) detect_candidates(level, ignore_mask);
  // Mask compensation (OrbConfig::mask_compensation, off by default): a mask over most of the
  // image leaves the levels fewer corners than their shares (frames where people cover most of
  // the image keep well under n_features). A short level is searched again at the minimum
  // threshold, then what is still missing goes to the levels with corners to spare, so that the
  // count stays near n_features. On real crowded frames it keeps the count but costs accuracy in
  // every mode, hence off (docs/decisions/mask-compensation.md).
  // Frames without masked pixels skip this and are extracted exactly as without compensation.
  level_budget_ = features_per_level_;
  if (config_.mask_compensation && !ignore_mask.empty() && cv::countNonZero(ignore_mask) > 0) {
    for (int level = 0; level < levels(); ++level) {
      if (static_cast<int>(level_candidates_[level].size()) < features_per_level_[level]) {
        detect_candidates_at_min_threshold(level, ignore_mask);
      }
      level_available_[level] = static_cast<int>(level_candidates_[level].size());
    }
    share_feature_budget(features_per_level_, level_available_, level_budget_);
  }

  // Pass 1: keypoints of every level, still in level coordinates (the descriptor needs them).
  out.keypoints.clear();
  for (int level = 0; level < levels(); ++level) {
    const cv::Mat& image = pyramid_[level].image;
    const cv::Rect2f area(static_cast<float>(kFastBorder), static_cast<float>(kFastBorder),
                          static_cast<float>(image.cols - 2 * kFastBorder),
                          static_cast<float>(image.rows - 2 * kFastBorder));
    distributor_.distribute(level_candidates_[level], area, level_budget_[level], selected_);
    const float size = kPatchSize * scale_factors_[level];
    for (cv::KeyPoint& keypoint : selected_) {
      keypoint.octave = level;
      keypoint.size = size;
      keypoint.angle = orientation_degrees(image, keypoint.pt);
      out.keypoints.push_back(keypoint);
    }
  }

  // Pass 2: descriptors straight into the output rows, then coordinates to level 0. The rows are
  // reused only when `out` is their sole owner: cv::Mat assignment shares data, and a caller that
  // kept a shallow copy of an earlier result must not see it overwritten.
  if (out.descriptors.u != nullptr && out.descriptors.u->refcount > 1) out.descriptors.release();
  out.descriptors.create(static_cast<int>(out.keypoints.size()), kOrbDescriptorBytes, CV_8UC1);
  for (int i = 0; i < static_cast<int>(out.keypoints.size()); ++i) {
    cv::KeyPoint& keypoint = out.keypoints[i];
    const PyramidLevel& level = pyramid_[keypoint.octave];
    describe(level.blurred, keypoint, out.descriptors.ptr<std::uint8_t>(i));
    keypoint.pt = level.to_image(keypoint.pt.x, keypoint.pt.y);
  }
}

}  // namespace pspslam
