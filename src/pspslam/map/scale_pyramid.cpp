#include "pspslam/map/scale_pyramid.h"

#include <algorithm>
#include <cmath>

namespace pspslam {

ScalePyramid ScalePyramid::from_config(const OrbConfig& orb) {
  ScalePyramid p;
  p.levels = orb.n_levels;
  p.scale_factor = orb.scale_factor;
  p.log_scale_factor = std::log(orb.scale_factor);
  p.scale.resize(p.levels);
  p.inv_scale.resize(p.levels);
  p.sigma2.resize(p.levels);
  p.inv_sigma2.resize(p.levels);
  double s = 1.0;
  for (int level = 0; level < p.levels; ++level) {
    p.scale[level] = s;
    p.inv_scale[level] = 1.0 / s;
    p.sigma2[level] = s * s;
    p.inv_sigma2[level] = 1.0 / (s * s);
    s *= orb.scale_factor;
  }
  return p;
}

int ScalePyramid::predict_level(double distance, double max_distance) const {
  const double ratio = max_distance / distance;
  const int level = static_cast<int>(std::ceil(std::log(ratio) / log_scale_factor));
  return std::clamp(level, 0, levels - 1);
}

}  // namespace pspslam
