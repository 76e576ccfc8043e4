#include "pspslam/people/person_detector.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pspslam {
namespace {

// The value at fraction `q` of `values` once sorted (reorders them).
float quantile(std::vector<float>& values, double q) {
  const auto at = values.begin() + static_cast<std::ptrdiff_t>(q * (values.size() - 1) + 0.5);
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace

void PersonDetector::sample(const cv::Mat& labels, int person_label, const cv::Mat& depth) {
  const int step = std::max(1, params_.grid_step);
  grid_w_ = depth.cols / step;
  grid_h_ = depth.rows / step;
  grid_depth_.assign(static_cast<size_t>(grid_w_) * static_cast<size_t>(grid_h_), 0.0f);
  all_depth_.assign(grid_depth_.size(), 0.0f);
  const double label_x = static_cast<double>(labels.cols) / depth.cols;
  const double label_y = static_cast<double>(labels.rows) / depth.rows;
  for (int gy = 0; gy < grid_h_; ++gy) {
    const int y = gy * step + step / 2;
    const float* depth_row = depth.ptr<float>(y);
    const std::uint8_t* label_row = labels.ptr<std::uint8_t>(static_cast<int>(y * label_y));
    for (int gx = 0; gx < grid_w_; ++gx) {
      const int x = gx * step + step / 2;
      const int label = label_row[static_cast<int>(x * label_x)];
      const bool person = person_label < 0 ? label != 0 : label == person_label;
      const float z = depth_row[x];
      if (!(z > 0.0f && z < params_.max_depth_m)) continue;
      all_depth_[static_cast<size_t>(gy * grid_w_ + gx)] = z;
      if (person) grid_depth_[static_cast<size_t>(gy * grid_w_ + gx)] = z;
    }
  }
}

// Connected regions of person samples whose depths join without a jump.
void PersonDetector::label_components() {
  grid_id_.assign(grid_depth_.size(), -1);
  for (Instance& instance : instances_) {
    instance.u.clear();
    instance.v.clear();
    instance.depth.clear();
  }
  size_t count = 0;
  const int step = std::max(1, params_.grid_step);
  const auto joined = [&](float a, float b) {
    return b > 0.0f &&
           std::abs(a - b) <= params_.depth_jump_abs_m + params_.depth_jump_rel * std::min(a, b);
  };
  for (int seed = 0; seed < static_cast<int>(grid_depth_.size()); ++seed) {
    if (grid_depth_[static_cast<size_t>(seed)] <= 0.0f || grid_id_[static_cast<size_t>(seed)] >= 0)
      continue;
    if (instances_.size() <= count) instances_.emplace_back();
    Instance& instance = instances_[count];
    const auto id = static_cast<std::int32_t>(count++);
    instance.min_x = instance.min_y = 1 << 30;
    instance.max_x = instance.max_y = -1;
    queue_.assign(1, seed);
    grid_id_[static_cast<size_t>(seed)] = id;
    for (size_t head = 0; head < queue_.size(); ++head) {
      const int at = queue_[head];
      const int gx = at % grid_w_, gy = at / grid_w_;
      const float z = grid_depth_[static_cast<size_t>(at)];
      const int x = gx * step + step / 2, y = gy * step + step / 2;
      instance.u.push_back(static_cast<float>(x));
      instance.v.push_back(static_cast<float>(y));
      instance.depth.push_back(z);
      instance.min_x = std::min(instance.min_x, x);
      instance.max_x = std::max(instance.max_x, x);
      instance.min_y = std::min(instance.min_y, y);
      instance.max_y = std::max(instance.max_y, y);
      const int neighbours[4] = {gx > 0 ? at - 1 : -1, gx + 1 < grid_w_ ? at + 1 : -1,
                                 gy > 0 ? at - grid_w_ : -1, gy + 1 < grid_h_ ? at + grid_w_ : -1};
      for (const int next : neighbours) {
        if (next < 0 || grid_id_[static_cast<size_t>(next)] >= 0) continue;
        if (!joined(z, grid_depth_[static_cast<size_t>(next)])) continue;
        grid_id_[static_cast<size_t>(next)] = id;
        queue_.push_back(next);
      }
    }
  }
  instances_.resize(count);
}

double PersonDetector::standout(const Instance& instance, std::int32_t id) const {
  const int step = std::max(1, params_.grid_step);
  const int x0 = instance.min_x / step, x1 = instance.max_x / step;
  const int y0 = instance.min_y / step, y1 = instance.max_y / step;
  const int grow_x = static_cast<int>((x1 - x0 + 1) * params_.standout_window) + 1;
  const int grow_y = static_cast<int>((y1 - y0 + 1) * params_.standout_window) + 1;
  std::vector<float> depths = instance.depth;
  const float z = quantile(depths, 0.5);
  const float behind_from = z + params_.depth_jump_abs_m + params_.depth_jump_rel * z;
  int around = 0, behind = 0;
  for (int gy = std::max(0, y0 - grow_y); gy < std::min(grid_h_, y1 + grow_y + 1); ++gy) {
    for (int gx = std::max(0, x0 - grow_x); gx < std::min(grid_w_, x1 + grow_x + 1); ++gx) {
      const size_t at = static_cast<size_t>(gy * grid_w_ + gx);
      if (grid_id_[at] == id || all_depth_[at] <= 0.0f) continue;
      ++around;
      behind += all_depth_[at] > behind_from;
    }
  }
  return around > 0 ? static_cast<double>(behind) / around : 1.0;
}

PersonObservation PersonDetector::observe(Instance& instance, const PinholeCamera& camera) const {
  const int step = std::max(1, params_.grid_step);
  PersonObservation person;
  person.visible_pixels = static_cast<int>(instance.u.size()) * step * step;
  const float u_low = quantile(instance.u, 0.1), u_high = quantile(instance.u, 0.9);
  const float v_low = quantile(instance.v, 0.1), v_high = quantile(instance.v, 0.9);
  std::vector<cv::Point2f> centre = {{quantile(instance.u, 0.5), quantile(instance.v, 0.5)}};
  const double z = quantile(instance.depth, 0.5);
  camera.undistort_points(centre);
  const Eigen::Vector3d ray =
      camera.unproject(Eigen::Vector2d(centre[0].x, centre[0].y), 1.0).normalized();
  // The median depth is the front surface on the median pixel's ray; the centre lies behind it.
  person.position_camera = ray * (z / ray.z() + params_.body_radius_m);
  person.extent_m =
      std::max((u_high - u_low + step) * z / camera.fx, (v_high - v_low + step) * z / camera.fy);
  person.box =
      cv::Rect(instance.min_x - step / 2, instance.min_y - step / 2,
               instance.max_x - instance.min_x + step, instance.max_y - instance.min_y + step);
  return person;
}

std::vector<PersonObservation> PersonDetector::detect(const cv::Mat& labels, int person_label,
                                                      const cv::Mat& depth,
                                                      const PinholeCamera& camera,
                                                      const Pose& T_world_camera) {
  std::vector<PersonObservation> people;
  if (labels.empty() || depth.empty() || labels.type() != CV_8UC1 || depth.type() != CV_32FC1)
    return people;
  sample(labels, person_label, depth);
  label_components();
  const int step = std::max(1, params_.grid_step);
  const size_t min_samples = static_cast<size_t>(std::max(1, params_.min_pixels / (step * step)));
  for (size_t i = 0; i < instances_.size(); ++i) {
    Instance& instance = instances_[i];
    if (instance.u.size() < min_samples) continue;
    if (standout(instance, static_cast<std::int32_t>(i)) < params_.min_standout) continue;
    people.push_back(observe(instance, camera));
  }
  // Fragments of one person (an arm cut off by its depth jump) join the larger part: pixel-
  // weighted centre, united box.
  std::sort(people.begin(), people.end(),
            [](const auto& a, const auto& b) { return a.visible_pixels > b.visible_pixels; });
  std::vector<PersonObservation> merged;
  for (const PersonObservation& part : people) {
    auto into = std::find_if(merged.begin(), merged.end(), [&](const PersonObservation& whole) {
      const Eigen::Vector3d apart = (whole.position_camera - part.position_camera).cwiseAbs();
      return apart.x() < params_.merge_side_m && apart.y() < params_.merge_height_m &&
             apart.z() < params_.merge_depth_m;
    });
    if (into == merged.end()) {
      merged.push_back(part);
      continue;
    }
    const double w = static_cast<double>(part.visible_pixels) /
                     static_cast<double>(into->visible_pixels + part.visible_pixels);
    into->position_camera = (1.0 - w) * into->position_camera + w * part.position_camera;
    into->visible_pixels += part.visible_pixels;
    into->box |= part.box;
    const double z = into->position_camera.z();
    into->extent_m = std::max(
        {into->extent_m, into->box.width * z / camera.fx, into->box.height * z / camera.fy});
  }
  for (PersonObservation& person : merged)
    person.position_world = T_world_camera * person.position_camera;
  return merged;
}

}  // namespace pspslam
