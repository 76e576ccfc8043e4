#pragma once

#include <cmath>

namespace pspslam {

// How an RGB-D observation's depth is weighed in pose optimisation and bundle adjustment.
//
// ORB-SLAM2 turns depth z into a virtual right coordinate u_r = u − bf/z and weighs it like a
// pixel. But u_r carries the keypoint's own pixel error, so that row says the depth is known to
// about z²/bf (bf ≈ 42 px: 24 mm at 1 m, 38 cm at 4 m) while an RGB-D sensor measures it ~15×
// better. On the synthetic static sequence that under-weighting lets every keyframe pose drift
// in rotation; the sensor model below removes most of that drift.
//
// When enabled, the third row of an RGB-D observation is the disparity bf/z, whitened by
// σ_d = scale · bf · σ_z(z) / z² with the axial noise σ_z(z) = constant + quadratic (z − offset)²
// of structured-light sensors (Kinect v1 / Xtion, Nguyen, Izadi, Lovell 2012); z is the measured
// depth, so the weight is fixed for an observation. Disabled, the ORB-SLAM2 u_r row is used.
//
// Off by default, switched on per sensor by the camera config (`depth_noise: kinect_v1`, with
// `depth_noise_scale` as `scale` for both pose-only optimisation and BA). On the synthetic
// static sequences (depth registered and synchronised with colour) scale 2 is far more accurate
// than the u_r row. Real depth needs a looser model: on the Bonn recordings, with the depth
// registration shift and the rolling-shutter correction, scale 16 beats the u_r row while scale 2
// is worse than it (config/bonn.yaml; docs/decisions/depth-weighting.md). The TUM presets keep
// the u_r row: no experiment has compared the two there.
struct DepthNoiseModel {
  bool enabled = false;
  double constant = 0.0012;   // metres
  double quadratic = 0.0019;  // metres per square metre
  double offset = 0.4;        // metres
  // Multiplies σ_d: margin for depth/colour registration and depth sampled at the rounded pixel.
  double scale = 1.0;

  // 1 / σ_d for a measured disparity (pixels; > 0).
  double sqrt_information(double bf, double disparity) const {
    const double z = bf / disparity;
    const double d = z - offset;
    return z * z / (scale * bf * (constant + quadratic * d * d));
  }
};

}  // namespace pspslam
