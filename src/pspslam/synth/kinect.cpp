#include "pspslam/synth/kinect.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"
#include "pspslam/synth/sensor.h"
#include "pspslam/synth/texture.h"

namespace pspslam::synth {

const std::vector<std::string>& KinectFaults::names() {
  static const std::vector<std::string> kNames = {
      "depth-noise", "holes",      "sync-offset",     "rolling-shutter", "motion-blur",
      "exposure",    "distortion", "handheld-motion", "marker"};
  return kNames;
}

namespace {

// The switches in the order of KinectFaults::names().
constexpr bool KinectFaults::*kFields[] = {
    &KinectFaults::depth_noise,     &KinectFaults::holes,           &KinectFaults::sync_offset,
    &KinectFaults::rolling_shutter, &KinectFaults::motion_blur,     &KinectFaults::exposure,
    &KinectFaults::distortion,      &KinectFaults::handheld_motion, &KinectFaults::marker};

bool KinectFaults::*fault_field(const std::string& name) {
  const std::vector<std::string>& all = KinectFaults::names();
  for (size_t i = 0; i < all.size(); ++i) {
    if (all[i] == name) return kFields[i];
  }
  throw Error("synth: flag --no-fault: unknown fault '" + name + "'");
}

}  // namespace

void KinectFaults::set(const std::string& name, bool on) { this->*fault_field(name) = on; }

bool KinectFaults::is_on(const std::string& name) const { return this->*fault_field(name); }

std::string KinectFaults::describe() const {
  std::string text;
  for (const std::string& name : names()) {
    if (!is_on(name)) continue;
    if (!text.empty()) text += ",";
    text += name;
  }
  return text.empty() ? "none" : text;
}

KinectDepthModel::KinectDepthModel(uint64_t seed, double focal_px)
    : seed_(mix_hash(seed, 0x41EC7u)), focal_px_(focal_px), normals_(make_normal_table(seed_)) {}

double KinectDepthModel::shadow_width_px(double z_near, double z_far) const {
  return focal_px_ * kKinectBaseline_m * (1.0 / z_near - 1.0 / z_far);
}

double KinectDepthModel::quantise(double z) const {
  const double bf = kKinectBaseline_m * focal_px_;
  const double steps = std::round(bf / z / kKinectDisparityStep_px);
  return steps > 0.0 ? bf / (steps * kKinectDisparityStep_px) : 0.0;
}

void KinectDepthModel::apply(const cv::Mat& exact, const cv::Mat& incidence_cos, const cv::Mat& bgr,
                             uint64_t frame_index, const Switches& switches, cv::Mat& out) const {
  CV_Assert(exact.type() == CV_32F && incidence_cos.type() == CV_32F && bgr.type() == CV_8UC3);
  out.create(exact.size(), CV_32F);
  const int width = exact.cols, height = exact.rows;
  const uint64_t frame_seed = mix_hash(seed_, frame_index);
  const double bf = kKinectBaseline_m * focal_px_;
  const double steps_per_px = 1.0 / kKinectDisparityStep_px;

  for (int y = 0; y < height; ++y) {
    const float* z_row = exact.ptr<float>(y);
    const float* cos_row = incidence_cos.ptr<float>(y);
    const auto* colour_row = bgr.ptr<cv::Vec3b>(y);
    float* out_row = out.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      float z = z_row[x];
      if (switches.holes) {
        const cv::Vec3b c = colour_row[x];
        const int grey = (c[0] + c[1] + c[2]) / 3;
        if (z < kMinRange_m || z > kMaxRange_m || cos_row[x] < kMinIncidenceCos ||
            grey < kDarkGrey) {
          out_row[x] = 0.0f;
          continue;
        }
      }
      if (switches.noise) {
        const uint64_t h = mix_hash(frame_seed, static_cast<uint64_t>(y) * width + x);
        z += kinect_sigma(z) * normals_[h & (kNormalTableSize - 1)];
      }
      if (switches.quantisation && z > 0.0f) {
        // The sensor reports disparity in 1/8 px; depth is b f / d.
        const double steps = std::floor(bf / z * steps_per_px + 0.5);
        z = steps > 0.0 ? static_cast<float>(bf * steps_per_px / steps) : 0.0f;
      }
      out_row[x] = z;
    }
  }
  if (!switches.holes) return;

  // Mixed pixels and the projector shadow (its full geometric width, at most 64 px, the mixed
  // pixel included) at depth jumps.
  clear_depth_discontinuities(
      exact,
      [this](float z_near, float z_far) {
        return std::min(64, static_cast<int>(std::lround(shadow_width_px(z_near, z_far)))) - 1;
      },
      out);
}

double kinect_sync_offset(uint64_t seed, size_t index) {
  const double u = hash_to_unit(mix_hash(seed, 0x5C0FFu, static_cast<uint64_t>(index)));
  return (2.0 * u - 1.0) * kKinectSyncOffsetMax_s;
}

double kinect_exposure_gain(uint64_t seed, double t) {
  const uint64_t exposure_seed = mix_hash(seed, 0xE7B05u);
  const double phase = 2.0 * M_PI * hash_to_unit(mix_hash(exposure_seed, 0));
  const double drift = 1.0 + 0.08 * std::sin(2.0 * M_PI * t / 9.0 + phase);
  // Each 2 s segment keeps the previous level or (one time in three) jumps to a new one within
  // +-12 %; walking back to the last change keeps the gain a pure function of t.
  int64_t segment = static_cast<int64_t>(std::floor(t / 2.0));
  while (segment > 0 &&
         hash_to_unit(mix_hash(exposure_seed, 1, static_cast<uint64_t>(segment))) >= 1.0 / 3.0) {
    --segment;
  }
  const double step =
      segment <= 0
          ? 1.0
          : 1.0 + 0.24 * (hash_to_unit(mix_hash(exposure_seed, 2, static_cast<uint64_t>(segment))) -
                          0.5);
  return drift * step;
}

void kinect_motion_blur(cv::Mat& bgr, const Eigen::Vector3d& omega_camera, double focal_px,
                        double exposure_s) {
  // Flow at the principal point of a rotation: (f w_y, -f w_x) px/s.
  const double dx = focal_px * omega_camera.y() * exposure_s;
  const double dy = -focal_px * omega_camera.x() * exposure_s;
  const double length = std::hypot(dx, dy);
  if (length < 0.5) return;  // less than half a pixel of smear: nothing visible
  const int taps = std::min(31, 1 + 2 * static_cast<int>(std::ceil(length / 2.0)));
  const int size = taps;
  cv::Mat kernel = cv::Mat::zeros(size, size, CV_32F);
  const double centre = (size - 1) / 2.0;
  // Sample the segment densely and splat bilinearly: a smooth kernel for any direction.
  constexpr int kSamples = 64;
  for (int i = 0; i < kSamples; ++i) {
    const double s = (i + 0.5) / kSamples - 0.5;
    const double px = centre + s * dx, py = centre + s * dy;
    const int x0 = static_cast<int>(std::floor(px)), y0 = static_cast<int>(std::floor(py));
    const float fx = static_cast<float>(px - x0), fy = static_cast<float>(py - y0);
    const auto add = [&](int x, int y, float w) {
      if (x >= 0 && y >= 0 && x < size && y < size) kernel.at<float>(y, x) += w;
    };
    add(x0, y0, (1 - fx) * (1 - fy));
    add(x0 + 1, y0, fx * (1 - fy));
    add(x0, y0 + 1, (1 - fx) * fy);
    add(x0 + 1, y0 + 1, fx * fy);
  }
  kernel /= cv::sum(kernel)[0];
  cv::filter2D(bgr, bgr, -1, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
}

DistortionMaps::DistortionMaps(int width, int height, double fx, double fy, double cx, double cy,
                               const std::array<double, 5>& k) {
  map_x.create(height, width, CV_32F);
  map_y.create(height, width, CV_32F);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      // Invert x_d = distort(x) by fixed-point iteration (converges in a few steps for
      // distortions of a few per cent).
      const double xd = (u - cx) / fx, yd = (v - cy) / fy;
      double x = xd, y = yd;
      for (int it = 0; it < 20; ++it) {
        const double r2 = x * x + y * y;
        const double radial = 1.0 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
        const double tx = 2.0 * k[2] * x * y + k[3] * (r2 + 2.0 * x * x);
        const double ty = k[2] * (r2 + 2.0 * y * y) + 2.0 * k[3] * x * y;
        x = (xd - tx) / radial;
        y = (yd - ty) / radial;
      }
      map_x.at<float>(v, u) = static_cast<float>(fx * x + cx);
      map_y.at<float>(v, u) = static_cast<float>(fy * y + cy);
    }
  }
}

}  // namespace pspslam::synth
