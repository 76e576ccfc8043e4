#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace pspslam::synth {

// How a procedural texture looks. Static surfaces get dense, high-contrast detail so ORB finds
// corners everywhere; clothes and skin get softer detail, as real people show fewer corners.
struct TextureRecipe {
  cv::Vec3b colour_a{0, 0, 0};
  cv::Vec3b colour_b{255, 255, 255};
  double noise_contrast = 1.0;  // 0..1: how far the value noise spreads between the two colours
  double blobs_per_m2 = 20.0;   // filled ellipses of random colour
  double lines_per_m2 = 10.0;   // straight strokes
  double rects_per_m2 = 3.0;    // tiles / posters / labels
  double glyphs_per_m2 = 4.0;   // short strings of letters: sharp corners at many scales
  double saturation = 1.0;      // 0 = grey accents, 1 = colourful accents
};

// Random recipe for a static surface (wall, floor, furniture): every surface gets its own.
TextureRecipe static_surface_recipe(uint64_t seed);

// Texture defined in a surface's own 2D metric coordinates (s, t in metres from one corner), so
// a 3D point looks the same from every view. Kept as a mip pyramid: distant surfaces are sampled
// from a coarser level instead of aliasing (which would make features flicker between frames).
class MipTexture {
 public:
  MipTexture(cv::Mat level0_bgr, float texels_per_metre);

  float texels_per_metre() const { return texels_per_metre_; }

  // Piecewise-linear log2 from the float's bits (error < 0.09): plenty to pick a mip level.
  static float approx_log2(float x) {
    x = std::max(x, 1e-20f);
    return static_cast<float>(std::bit_cast<uint32_t>(x)) * (1.0f / (1 << 23)) - 127.0f;
  }

  // Trilinear sample. `footprint_m` is the size of one image pixel on the surface in metres.
  cv::Vec3f sample(float s_m, float t_m, float footprint_m) const {
    return sample_lod(s_m, t_m, approx_log2(footprint_m * texels_per_metre_));
  }

  // Same with the level of detail (log2 of the footprint in level-0 texels) given.
  // Inline: called once per pixel of every frame.
  cv::Vec3f sample_lod(float s_m, float t_m, float lod) const {
    const int max_level = static_cast<int>(levels_.size()) - 1;
    if (lod <= 0.0f) return at_level(0, s_m, t_m);
    if (lod >= static_cast<float>(max_level)) return at_level(max_level, s_m, t_m);
    const int low = static_cast<int>(lod);
    // Blend two levels only in a band around the half-way point: half the cost of full
    // trilinear filtering and still no visible jump where a surface changes level.
    const float blend = std::clamp((lod - static_cast<float>(low) - 0.3f) * 2.5f, 0.0f, 1.0f);
    if (blend <= 0.0f) return at_level(low, s_m, t_m);
    if (blend >= 1.0f) return at_level(low + 1, s_m, t_m);
    return at_level(low, s_m, t_m) * (1.0f - blend) + at_level(low + 1, s_m, t_m) * blend;
  }

 private:
  cv::Vec3f at_level(int level, float s_m, float t_m) const {
    const float scale = texels_per_metre_ / static_cast<float>(1 << level);
    // pyrDown keeps texel centres at (2i + 0.5): coordinates scale with the level, minus 0.5.
    return bilinear(levels_[static_cast<size_t>(level)], s_m * scale - 0.5f, t_m * scale - 0.5f);
  }

  static cv::Vec3f bilinear(const cv::Mat& image, float x, float y) {
    x = std::clamp(x, 0.0f, static_cast<float>(image.cols - 1));
    y = std::clamp(y, 0.0f, static_cast<float>(image.rows - 1));
    const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
    const int x1 = std::min(x0 + 1, image.cols - 1), y1 = std::min(y0 + 1, image.rows - 1);
    const float fx = x - static_cast<float>(x0), fy = y - static_cast<float>(y0);
    const auto* row0 = image.ptr<cv::Vec3b>(y0);
    const auto* row1 = image.ptr<cv::Vec3b>(y1);
    cv::Vec3f out;
    for (int c = 0; c < 3; ++c) {
      const float top = row0[x0][c] + (row0[x1][c] - row0[x0][c]) * fx;
      const float bottom = row1[x0][c] + (row1[x1][c] - row1[x0][c]) * fx;
      out[c] = top + (bottom - top) * fy;
    }
    return out;
  }

  std::vector<cv::Mat> levels_;
  float texels_per_metre_;
};

// Draws the level-0 image (CV_8UC3) of a texture covering width_m x height_m metres at
// `texels_per_metre`, deterministic in `seed` (cv::RNG and OpenCV drawing are platform
// independent). Texel (i, j) covers surface coordinates [i, i+1) x [j, j+1) / texels_per_metre.
cv::Mat make_texture_image(const TextureRecipe& recipe, double width_m, double height_m,
                           float texels_per_metre, uint64_t seed);

// splitmix64: the one hash used for every derived seed and per-pixel random number, so results
// depend on (seed, what, where) only and never on thread scheduling.
inline uint64_t mix_hash(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
inline uint64_t mix_hash(uint64_t a, uint64_t b) { return mix_hash(a ^ mix_hash(b)); }
inline uint64_t mix_hash(uint64_t a, uint64_t b, uint64_t c) { return mix_hash(mix_hash(a, b), c); }

// Uniform in [0, 1) from a hash value.
inline double hash_to_unit(uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

}  // namespace pspslam::synth
