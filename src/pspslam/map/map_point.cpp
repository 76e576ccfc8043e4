#include "pspslam/map/map_point.h"

#include <algorithm>
#include <limits>

#include "pspslam/map/keyframe.h"
#include "pspslam/map/scale_pyramid.h"

namespace pspslam {

MapPoint::MapPoint(std::uint64_t id, const Eigen::Vector3d& position_world,
                   const std::shared_ptr<KeyFrame>& reference_keyframe)
    : id_(id),
      position_(position_world),
      reference_keyframe_(reference_keyframe),
      first_frame_id_(reference_keyframe ? reference_keyframe->frame_id() : 0) {
  if (reference_keyframe) first_keyframe_id = reference_keyframe->id();
}

Eigen::Vector3d MapPoint::position() const {
  std::lock_guard lock(position_mutex_);
  return position_;
}

void MapPoint::set_position(const Eigen::Vector3d& position_world) {
  std::lock_guard lock(position_mutex_);
  position_ = position_world;
}

Eigen::Vector3d MapPoint::normal() const {
  std::lock_guard lock(position_mutex_);
  return normal_;
}

OrbDescriptor MapPoint::descriptor() const {
  std::lock_guard lock(observation_mutex_);
  return descriptor_;
}

// The 0.8 / 1.2 margins are ORB-SLAM2's tolerance on scale prediction.
double MapPoint::min_distance() const {
  std::lock_guard lock(position_mutex_);
  return 0.8 * min_distance_;
}

double MapPoint::max_distance() const {
  std::lock_guard lock(position_mutex_);
  return 1.2 * max_distance_;
}

std::shared_ptr<KeyFrame> MapPoint::reference_keyframe() const {
  std::lock_guard lock(observation_mutex_);
  return reference_keyframe_.lock();
}

void MapPoint::add_observation(const std::shared_ptr<KeyFrame>& keyframe, int keypoint_index) {
  std::lock_guard lock(observation_mutex_);
  if (observations_.contains(keyframe->id())) return;
  observations_[keyframe->id()] = {keyframe, keypoint_index};
  num_observations_ += keyframe->has_depth(keypoint_index) ? 2 : 1;
}

bool MapPoint::erase_observation(std::uint64_t keyframe_id) {
  bool now_bad = false;
  {
    std::lock_guard lock(observation_mutex_);
    auto it = observations_.find(keyframe_id);
    if (it == observations_.end()) return false;
    if (auto kf = it->second.keyframe.lock()) {
      num_observations_ -= kf->has_depth(it->second.keypoint_index) ? 2 : 1;
    } else {
      num_observations_ -= 1;
    }
    observations_.erase(it);
    auto reference = reference_keyframe_.lock();
    if ((!reference || reference->id() == keyframe_id) && !observations_.empty()) {
      reference_keyframe_ = observations_.begin()->second.keyframe;
    }
    // A point seen by fewer than two keyframes carries no constraint any more.
    now_bad = num_observations_ <= 2 && !bad_;
  }
  if (now_bad) set_bad();
  return now_bad;
}

std::map<std::uint64_t, MapPoint::Observation> MapPoint::observations() const {
  std::lock_guard lock(observation_mutex_);
  return observations_;
}

int MapPoint::num_observations() const {
  std::lock_guard lock(observation_mutex_);
  return num_observations_;
}

int MapPoint::keypoint_index_in(std::uint64_t keyframe_id) const {
  std::lock_guard lock(observation_mutex_);
  auto it = observations_.find(keyframe_id);
  return it == observations_.end() ? -1 : it->second.keypoint_index;
}

bool MapPoint::is_observed_by(std::uint64_t keyframe_id) const {
  std::lock_guard lock(observation_mutex_);
  return observations_.contains(keyframe_id);
}

void MapPoint::compute_distinctive_descriptor() {
  std::vector<OrbDescriptor> descriptors;
  for (const auto& [id, obs] : observations()) {
    if (auto kf = obs.keyframe.lock(); kf && !kf->is_bad()) {
      descriptors.push_back(descriptor_from_row(kf->descriptors(), obs.keypoint_index));
    }
  }
  if (descriptors.empty()) return;
  const size_t n = descriptors.size();
  std::vector<int> distances(n * n, 0);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const int d = descriptor_distance(descriptors[i].data(), descriptors[j].data());
      distances[i * n + j] = d;
      distances[j * n + i] = d;
    }
  }
  int best_median = std::numeric_limits<int>::max();
  size_t best = 0;
  std::vector<int> row(n);
  for (size_t i = 0; i < n; ++i) {
    std::copy(distances.begin() + i * n, distances.begin() + (i + 1) * n, row.begin());
    std::nth_element(row.begin(), row.begin() + (n - 1) / 2, row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  std::lock_guard lock(observation_mutex_);
  descriptor_ = descriptors[best];
}

void MapPoint::update_normal_and_depth(const ScalePyramid& pyramid) {
  std::map<std::uint64_t, Observation> observations;
  std::shared_ptr<KeyFrame> reference;
  {
    std::lock_guard lock(observation_mutex_);
    if (bad_) return;
    observations = observations_;
    reference = reference_keyframe_.lock();
  }
  if (observations.empty() || !reference) return;
  const Eigen::Vector3d position = this->position();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& [id, obs] : observations) {
    auto kf = obs.keyframe.lock();
    if (!kf) continue;
    normal += (position - kf->camera_center()).normalized();
    ++n;
  }
  const int ref_index = keypoint_index_in(reference->id());
  if (n == 0 || ref_index < 0) return;
  const double distance = (position - reference->camera_center()).norm();
  const int level = reference->keypoints()[ref_index].octave;
  std::lock_guard lock(position_mutex_);
  max_distance_ = distance * pyramid.scale[level];
  min_distance_ = max_distance_ / pyramid.scale[pyramid.levels - 1];
  normal_ = normal / n;
}

int MapPoint::predict_level(double distance, const ScalePyramid& pyramid) const {
  double max_distance;
  {
    std::lock_guard lock(position_mutex_);
    max_distance = max_distance_;
  }
  return pyramid.predict_level(distance, max_distance);
}

void MapPoint::increase_visible(int n) {
  std::lock_guard lock(observation_mutex_);
  visible_ += n;
}

void MapPoint::increase_found(int n) {
  std::lock_guard lock(observation_mutex_);
  found_ += n;
}

double MapPoint::found_ratio() const {
  std::lock_guard lock(observation_mutex_);
  return static_cast<double>(found_) / visible_;
}

void MapPoint::set_bad() {
  std::map<std::uint64_t, Observation> observations;
  {
    std::lock_guard lock(observation_mutex_);
    bad_ = true;
    observations.swap(observations_);
    num_observations_ = 0;
  }
  for (const auto& [id, obs] : observations) {
    if (auto kf = obs.keyframe.lock()) kf->erase_map_point(obs.keypoint_index);
  }
}

bool MapPoint::is_bad() const { return bad_; }

bool MapPoint::replace_with(const std::shared_ptr<MapPoint>& other) {
  if (other.get() == this) return false;
  std::map<std::uint64_t, Observation> observations;
  int visible;
  int found;
  {
    std::lock_guard lock(observation_mutex_);
    if (bad_) return false;
    bad_ = true;
    observations.swap(observations_);
    num_observations_ = 0;
    visible = visible_;
    found = found_;
    replaced_by_ = other;
  }
  for (const auto& [id, obs] : observations) {
    auto kf = obs.keyframe.lock();
    if (!kf) continue;
    if (!other->is_observed_by(id)) {
      kf->replace_map_point(obs.keypoint_index, other);
      other->add_observation(kf, obs.keypoint_index);
    } else {
      kf->erase_map_point(obs.keypoint_index);
    }
  }
  other->increase_found(found);
  other->increase_visible(visible);
  other->compute_distinctive_descriptor();
  return true;
}

std::shared_ptr<MapPoint> MapPoint::replaced_by() const {
  std::lock_guard lock(observation_mutex_);
  return replaced_by_.lock();
}

}  // namespace pspslam
