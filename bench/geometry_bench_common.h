#pragma once
// Shared by the geometry benches (bench_geometry_synth, bench_geometry_test_scene).
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "pspslam/geometry/geometry_stage.h"

namespace pspslam::bench {

// Sets the GeometryParams field named `key` (sweeps and command-line overrides of the benches).
inline void apply_geometry_override(GeometryParams& p, const std::string& key, double value) {
  if (key == "depth_threshold_abs_m")
    p.multiview.depth_threshold_abs_m = value;
  else if (key == "depth_threshold_relative")
    p.multiview.depth_threshold_relative = value;
  else if (key == "either_sign")
    p.multiview.disagreement =
        value > 0 ? DepthDisagreement::either_sign : DepthDisagreement::farther_only;
  else if (key == "max_parallax_deg")
    p.multiview.max_parallax_deg = value;
  else if (key == "reference_patch_radius")
    p.multiview.reference_patch_radius = int(value);
  else if (key == "min_dynamic_vote_fraction")
    p.multiview.min_dynamic_vote_fraction = value;
  else if (key == "max_reference_views")
    p.multiview.max_reference_views = int(value);
  else if (key == "search_radius_px")
    p.search.search_radius_px = float(value);
  else if (key == "band_width_px")
    p.search.band_width_px = float(value);
  else if (key == "node_spacing_px")
    p.search.node_spacing_px = float(value);
  else if (key == "lane_spacing_px")
    p.search.lane_spacing_px = float(value);
  else if (key == "alternate_lanes")
    p.search.alternate_lanes = value > 0;
  else if (key == "exhaustive")
    p.search.strategy = value > 0 ? SearchStrategy::exhaustive : SearchStrategy::ant_colony;
  else if (key == "region")
    p.region.enabled = value > 0;
  else if (key == "stride")
    p.region.stride = int(value);
  else if (key == "max_step_abs_m")
    p.region.max_step_abs_m = value;
  else if (key == "max_step_relative")
    p.region.max_step_relative = value;
  else if (key == "max_depth_from_seed_m")
    p.region.max_depth_from_seed_m = value;
  else if (key == "static_barrier_radius_px")
    p.region.static_barrier_radius_px = float(value);
  else if (key == "max_grow_radius_px")
    p.region.max_grow_radius_px = float(value);
  else if (key == "max_grow_radius_m")
    p.region.max_grow_radius_m = float(value);
  else if (key == "min_seeds_per_region")
    p.region.min_seeds_per_region = int(value);
  else if (key == "wanted_coverage")
    p.references.wanted_coverage = int(value);
  else if (key == "older_view_gain_share")
    p.references.older_view_gain_share = value;
  else if (key == "point_stride")
    p.references.point_stride = int(value);
  else if (key == "dilation_px")
    p.region.dilation_px = int(value);
  else {
    std::fprintf(stderr, "unknown key --%s\n", key.c_str());
    std::exit(2);
  }
}

// T composed with a random rotation of `deg` and translation of `mm` (mimics tracking error).
inline Pose perturbed(const Pose& T, double mm, double deg, std::mt19937_64& rng) {
  if (mm <= 0.0 && deg <= 0.0) return T;
  std::normal_distribution<double> n(0.0, 1.0);
  Pose d = Pose::Identity();
  d.translation() = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized() * mm * 1e-3;
  d.linear() =
      Eigen::AngleAxisd(deg * M_PI / 180.0, Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized())
          .toRotationMatrix();
  return T * d;
}

}  // namespace pspslam::bench
