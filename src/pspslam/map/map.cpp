#include "pspslam/map/map.h"

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

void Map::add_keyframe(const std::shared_ptr<KeyFrame>& keyframe) {
  std::lock_guard lock(mutex_);
  keyframes_[keyframe->id()] = keyframe;
  max_keyframe_id_ = std::max(max_keyframe_id_, keyframe->id());
}

void Map::add_map_point(const std::shared_ptr<MapPoint>& point) {
  std::lock_guard lock(mutex_);
  map_points_[point->id()] = point;
}

void Map::erase_keyframe(const std::shared_ptr<KeyFrame>& keyframe) {
  keyframe->set_bad();
  if (!keyframe->is_bad()) return;  // the anchor keyframe refuses
  std::lock_guard lock(mutex_);
  keyframes_.erase(keyframe->id());
}

void Map::erase_map_point(const std::shared_ptr<MapPoint>& point) {
  point->set_bad();
  std::lock_guard lock(mutex_);
  map_points_.erase(point->id());
}

size_t Map::erase_bad_map_points() {
  std::lock_guard lock(mutex_);
  return std::erase_if(map_points_, [](const auto& entry) { return entry.second->is_bad(); });
}

std::shared_ptr<KeyFrame> Map::keyframe(std::uint64_t id) const {
  std::lock_guard lock(mutex_);
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : it->second;
}

std::vector<std::shared_ptr<KeyFrame>> Map::keyframes() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<KeyFrame>> out;
  out.reserve(keyframes_.size());
  for (const auto& [id, kf] : keyframes_) out.push_back(kf);
  return out;
}

std::vector<std::shared_ptr<MapPoint>> Map::map_points() const {
  std::lock_guard lock(mutex_);
  std::vector<std::shared_ptr<MapPoint>> out;
  out.reserve(map_points_.size());
  for (const auto& [id, point] : map_points_) out.push_back(point);
  return out;
}

size_t Map::num_keyframes() const {
  std::lock_guard lock(mutex_);
  return keyframes_.size();
}

size_t Map::num_map_points() const {
  std::lock_guard lock(mutex_);
  return map_points_.size();
}

std::uint64_t Map::max_keyframe_id() const {
  std::lock_guard lock(mutex_);
  return max_keyframe_id_;
}

void Map::set_reference_map_points(std::vector<std::shared_ptr<MapPoint>> points) {
  std::lock_guard lock(mutex_);
  reference_map_points_ = std::move(points);
}

std::vector<std::shared_ptr<MapPoint>> Map::reference_map_points() const {
  std::lock_guard lock(mutex_);
  return reference_map_points_;
}

void Map::clear() {
  std::lock_guard lock(mutex_);
  keyframes_.clear();
  map_points_.clear();
  reference_map_points_.clear();
  max_keyframe_id_ = 0;
  // A new map starts from keyframe 0 again: bundle adjustment holds keyframe 0 fixed.
  next_keyframe_id_ = 0;
  next_map_point_id_ = 0;
}

}  // namespace pspslam
