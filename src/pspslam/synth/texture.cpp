#include "pspslam/synth/texture.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

namespace pspslam::synth {
namespace {

cv::Scalar random_colour(cv::RNG& rng, double saturation) {
  // Mix a random colour with its own grey so `saturation` controls how colourful accents are.
  const double r = rng.uniform(0.0, 255.0), g = rng.uniform(0.0, 255.0),
               b = rng.uniform(0.0, 255.0);
  const double grey = (r + g + b) / 3.0;
  return cv::Scalar(grey + (b - grey) * saturation, grey + (g - grey) * saturation,
                    grey + (r - grey) * saturation);
}

// Multi-scale value noise in [0, 1]: random grids at several cell sizes, upsampled smoothly and
// summed, so the surface has structure from centimetres to half a metre.
cv::Mat value_noise(int width, int height, float texels_per_metre, cv::RNG& rng) {
  const double cell_sizes_m[] = {0.6, 0.2, 0.07, 0.025};
  const double weights[] = {0.35, 0.3, 0.2, 0.15};
  cv::Mat sum(height, width, CV_32F, cv::Scalar(0));
  for (size_t octave = 0; octave < std::size(cell_sizes_m); ++octave) {
    const double cell_texels = std::max(2.0, cell_sizes_m[octave] * texels_per_metre);
    const int grid_w = static_cast<int>(std::ceil(width / cell_texels)) + 2;
    const int grid_h = static_cast<int>(std::ceil(height / cell_texels)) + 2;
    cv::Mat grid(grid_h, grid_w, CV_32F);
    rng.fill(grid, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::Mat up;
    cv::resize(
        grid, up,
        cv::Size(static_cast<int>(grid_w * cell_texels), static_cast<int>(grid_h * cell_texels)), 0,
        0, cv::INTER_CUBIC);
    sum += up(cv::Rect(0, 0, width, height)) * weights[octave];
  }
  double lo = 0, hi = 1;
  cv::minMaxLoc(sum, &lo, &hi);
  sum = (sum - lo) / std::max(1e-6, hi - lo);
  return sum;
}

}  // namespace

TextureRecipe static_surface_recipe(uint64_t seed) {
  cv::RNG rng(mix_hash(seed, 0x7e57u));
  TextureRecipe recipe;
  // Two base colours far apart in brightness: high contrast at every scale.
  const cv::Scalar dark = random_colour(rng, 0.8) * 0.35;
  const cv::Scalar light = random_colour(rng, 0.6) * 0.45 + cv::Scalar(130, 130, 130);
  for (int c = 0; c < 3; ++c) {
    recipe.colour_a[c] = cv::saturate_cast<uchar>(dark[c]);
    recipe.colour_b[c] = cv::saturate_cast<uchar>(light[c]);
  }
  recipe.noise_contrast = rng.uniform(0.7, 1.0);
  recipe.blobs_per_m2 = rng.uniform(15.0, 40.0);
  recipe.lines_per_m2 = rng.uniform(8.0, 25.0);
  recipe.rects_per_m2 = rng.uniform(2.0, 8.0);
  recipe.glyphs_per_m2 = rng.uniform(3.0, 10.0);
  recipe.saturation = rng.uniform(0.4, 1.0);
  return recipe;
}

cv::Mat make_texture_image(const TextureRecipe& recipe, double width_m, double height_m,
                           float texels_per_metre, uint64_t seed) {
  cv::RNG rng(mix_hash(seed));
  const int width = std::max(4, static_cast<int>(std::ceil(width_m * texels_per_metre)));
  const int height = std::max(4, static_cast<int>(std::ceil(height_m * texels_per_metre)));
  const cv::Mat noise = value_noise(width, height, texels_per_metre, rng);

  cv::Mat image(height, width, CV_8UC3);
  for (int y = 0; y < height; ++y) {
    const float* n = noise.ptr<float>(y);
    auto* out = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < width; ++x) {
      const double w = std::clamp(0.5 + (n[x] - 0.5) * 1.6 * recipe.noise_contrast, 0.0, 1.0);
      for (int c = 0; c < 3; ++c) {
        out[x][c] =
            cv::saturate_cast<uchar>(recipe.colour_a[c] * (1.0 - w) + recipe.colour_b[c] * w);
      }
    }
  }

  const double area = width_m * height_m;
  const auto count = [&](double per_m2) {
    const double expected = per_m2 * area;
    // At least one feature of each kind when the rate is not zero, so tiny faces still have detail.
    return per_m2 > 0 ? std::max(1, static_cast<int>(std::lround(expected))) : 0;
  };
  const auto point = [&] { return cv::Point(rng.uniform(0, width), rng.uniform(0, height)); };
  const auto metres = [&](double lo, double hi) {
    return std::max(1, static_cast<int>(rng.uniform(lo, hi) * texels_per_metre));
  };

  for (int i = 0, n = count(recipe.rects_per_m2); i < n; ++i) {
    const cv::Point corner = point();
    const cv::Rect rect(corner.x, corner.y, metres(0.04, 0.35), metres(0.04, 0.35));
    cv::rectangle(image, rect, random_colour(rng, recipe.saturation), cv::FILLED, cv::LINE_8);
    if (rng.uniform(0, 2) == 0) {
      cv::rectangle(image, rect, random_colour(rng, recipe.saturation) * 0.3,
                    std::max(1, metres(0.004, 0.012)), cv::LINE_8);
    }
  }
  for (int i = 0, n = count(recipe.blobs_per_m2); i < n; ++i) {
    const cv::Size axes(metres(0.008, 0.08), metres(0.008, 0.08));
    const int thickness = rng.uniform(0, 3) == 0 ? std::max(1, metres(0.003, 0.01)) : cv::FILLED;
    cv::ellipse(image, point(), axes, rng.uniform(0.0, 180.0), 0, 360,
                random_colour(rng, recipe.saturation), thickness, cv::LINE_AA);
  }
  for (int i = 0, n = count(recipe.lines_per_m2); i < n; ++i) {
    const cv::Point a = point();
    const double angle = rng.uniform(0.0, CV_PI);
    const double length = metres(0.05, 0.5);
    const cv::Point b(a.x + static_cast<int>(length * std::cos(angle)),
                      a.y + static_cast<int>(length * std::sin(angle)));
    const cv::Scalar colour =
        rng.uniform(0, 2) ? cv::Scalar(20, 20, 20) : cv::Scalar(235, 235, 235);
    cv::line(image, a, b, colour, std::max(1, metres(0.003, 0.012)), cv::LINE_AA);
  }
  static constexpr char kGlyphs[] = "ABCDEFGHKLMNPRSTUVWXYZ0123456789#%&";
  for (int i = 0, n = count(recipe.glyphs_per_m2); i < n; ++i) {
    std::string text;
    for (int k = rng.uniform(2, 6); k > 0; --k) text += kGlyphs[rng.uniform(0, 35)];
    const double glyph_height = metres(0.025, 0.09);
    const double scale = glyph_height / 22.0;  // FONT_HERSHEY_SIMPLEX is ~22 px tall at scale 1
    const cv::Scalar colour =
        rng.uniform(0, 2) ? cv::Scalar(15, 15, 15) : cv::Scalar(245, 245, 245);
    cv::putText(image, text, point(), cv::FONT_HERSHEY_SIMPLEX, scale, colour,
                std::max(1, static_cast<int>(glyph_height / 10)), cv::LINE_AA);
  }
  return image;
}

MipTexture::MipTexture(cv::Mat level0_bgr, float texels_per_metre)
    : texels_per_metre_(texels_per_metre) {
  levels_.push_back(std::move(level0_bgr));
  while (levels_.size() < 7 && std::min(levels_.back().cols, levels_.back().rows) >= 8) {
    cv::Mat down;
    cv::pyrDown(levels_.back(), down);
    levels_.push_back(std::move(down));
  }
}

}  // namespace pspslam::synth
