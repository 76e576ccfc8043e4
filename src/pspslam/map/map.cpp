#include "pspslam/map/map.h"

#include "pspslam/map/keyframe.h"
#include "pspslam/map/map_point.h"

namespace pspslam {

void Map::add_keyframe(const std::shared_ptr<KeyFrame>& keyframe) {
  std::lock_guard lock(mutex_);
  // Adding a keyframe again (local mapping does, after tracking) counts it once.
  if (!keyframes_.insert_or_assign(keyframe->id(), keyframe).second) return;
  max_keyframe_id_ = std::max(max_keyframe_id_, keyframe->id());
  const std::uint32_t map_id = keyframe->map_id();
  size_t& in_map = keyframes_per_map_[map_id];
  if (in_map++ == 0) keyframe->set_map(map_id, /*anchor=*/true);
  next_map_id_ = std::max(next_map_id_, map_id + 1);
}

void Map::add_map_point(const std::shared_ptr<MapPoint>& point) {
  std::lock_guard lock(mutex_);
  map_points_[point->id()] = point;
}

void Map::erase_keyframe(const std::shared_ptr<KeyFrame>& keyframe) {
  keyframe->set_bad();
  if (!keyframe->is_bad()) return;  // the anchor keyframe refuses
  std::lock_guard lock(mutex_);
  if (keyframes_.erase(keyframe->id()) > 0) --keyframes_per_map_[keyframe->map_id()];
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

std::uint32_t Map::open_new_map() {
  std::lock_guard lock(mutex_);
  active_map_ = next_map_id_;
  return next_map_id_;
}

size_t Map::num_keyframes_in(std::uint32_t map_id) const {
  std::lock_guard lock(mutex_);
  const auto it = keyframes_per_map_.find(map_id);
  return it == keyframes_per_map_.end() ? 0 : it->second;
}

std::vector<std::uint32_t> Map::map_ids() const {
  std::lock_guard lock(mutex_);
  std::vector<std::uint32_t> ids;
  for (const auto& [id, count] : keyframes_per_map_) {
    if (count > 0) ids.push_back(id);
  }
  return ids;
}

void Map::merge_map(const MapMerge& merge) {
  std::lock_guard lock(mutex_);
  for (const auto& [id, keyframe] : keyframes_) {
    if (keyframe->map_id() == merge.from) keyframe->set_map(merge.into, /*anchor=*/false);
  }
  keyframes_per_map_[merge.into] += keyframes_per_map_[merge.from];
  keyframes_per_map_.erase(merge.from);
  merges_.push_back(merge);
  if (active_map_ == merge.from) active_map_ = merge.into;
}

std::vector<MapMerge> Map::merges() const {
  std::lock_guard lock(mutex_);
  return merges_;
}

std::uint32_t Map::current_map_of(std::uint32_t map_id) const {
  std::lock_guard lock(mutex_);
  for (const MapMerge& merge : merges_) {  // in merge order, so a chain resolves in one pass
    if (merge.from == map_id) map_id = merge.into;
  }
  return map_id;
}

void Map::erase_map(std::uint32_t map_id) {
  std::vector<std::shared_ptr<KeyFrame>> doomed;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, keyframe] : keyframes_) {
      if (keyframe->map_id() == map_id) doomed.push_back(keyframe);
    }
  }
  for (const auto& keyframe : doomed) {
    for (const auto& point : keyframe->map_points()) {
      if (point) erase_map_point(point);
    }
    keyframe->set_map(map_id, /*anchor=*/false);  // so that set_bad detaches it
    erase_keyframe(keyframe);
  }
  std::lock_guard lock(mutex_);
  keyframes_per_map_.erase(map_id);
  if (map_id + 1 == next_map_id_) next_map_id_ = map_id;
}

void Map::clear() {
  std::lock_guard lock(mutex_);
  keyframes_.clear();
  keyframes_per_map_.clear();
  next_map_id_ = 0;
  merges_.clear();
  active_map_ = 0;
  map_points_.clear();
  reference_map_points_.clear();
  max_keyframe_id_ = 0;
  // A new map starts from keyframe 0 again: bundle adjustment holds keyframe 0 fixed.
  next_keyframe_id_ = 0;
  next_map_point_id_ = 0;
}

}  // namespace pspslam
