#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace pspslam {

class KeyFrame;
class MapPoint;

// Owner of all keyframes and map points (the only shared_ptr owner; everything else refers to
// them by weak_ptr or id). Thread-safe. update_mutex() serialises "the map changes under you"
// sections: tracking holds it for one frame, local mapping while it writes optimised values.
class Map {
 public:
  Map() = default;
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  std::uint64_t next_keyframe_id() { return next_keyframe_id_++; }
  std::uint64_t next_map_point_id() { return next_map_point_id_++; }
  // After a map is loaded with the ids it was saved with: ids handed out from now on are larger
  // than the loaded ones.
  void continue_ids_after(std::uint64_t keyframe_id, std::uint64_t map_point_id) {
    next_keyframe_id_ = std::max<std::uint64_t>(next_keyframe_id_, keyframe_id + 1);
    next_map_point_id_ = std::max<std::uint64_t>(next_map_point_id_, map_point_id + 1);
  }

  void add_keyframe(const std::shared_ptr<KeyFrame>& keyframe);
  void add_map_point(const std::shared_ptr<MapPoint>& point);
  // Marks bad (detaching from the graph) and drops the map's ownership.
  void erase_keyframe(const std::shared_ptr<KeyFrame>& keyframe);
  void erase_map_point(const std::shared_ptr<MapPoint>& point);
  // Drops the map's ownership of every point that became bad without passing through
  // erase_map_point (MapPoint::erase_observation or replace_with can make a point bad from
  // anywhere). Returns how many were dropped. O(points); local mapping runs it per keyframe.
  size_t erase_bad_map_points();

  std::shared_ptr<KeyFrame> keyframe(std::uint64_t id) const;  // nullptr if erased
  std::vector<std::shared_ptr<KeyFrame>> keyframes() const;    // ordered by id
  std::vector<std::shared_ptr<MapPoint>> map_points() const;   // ordered by id
  size_t num_keyframes() const;
  size_t num_map_points() const;
  std::uint64_t max_keyframe_id() const;

  // The local map tracking currently uses (for viewers / diagnostics).
  void set_reference_map_points(std::vector<std::shared_ptr<MapPoint>> points);
  std::vector<std::shared_ptr<MapPoint>> reference_map_points() const;

  std::mutex& update_mutex() { return update_mutex_; }

  // Empties the map (a monocular restart); ids start from 0 again.
  void clear();

 private:
  mutable std::mutex mutex_;
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> keyframes_;
  std::map<std::uint64_t, std::shared_ptr<MapPoint>> map_points_;
  std::vector<std::shared_ptr<MapPoint>> reference_map_points_;
  std::uint64_t max_keyframe_id_ = 0;
  std::atomic<std::uint64_t> next_keyframe_id_{0};
  std::atomic<std::uint64_t> next_map_point_id_{0};
  std::mutex update_mutex_;
};

}  // namespace pspslam
