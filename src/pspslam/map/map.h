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

// A merge of the atlas: map `from` was brought into map `into`'s frame and relabelled.
struct MapMerge {
  std::uint32_t from = 0;
  std::uint32_t into = 0;
  std::uint64_t current_keyframe = 0;  // the keyframe that recognised the place (`from`'s side)
  std::uint64_t matched_keyframe = 0;  // the keyframe it recognised (`into`'s side)
};

// Owner of all keyframes and map points (the only shared_ptr owner; everything else refers to
// them by weak_ptr or id). Thread-safe. update_mutex() serialises "the map changes under you"
// sections: tracking holds it for one frame, local mapping while it writes optimised values.
//
// The container is an atlas: every keyframe belongs to one map (KeyFrame::map_id), each with its
// own world frame (and, monocular, scale). Maps share no points and no covisibility, so local
// mapping, local BA and tracking's local map stay inside one without knowing of the others. The
// keyframe database covers them all: relocalisation lands in any, loop closing merges two when
// a keyframe of one recognises a place in the other (loop/map_merge.h). Tracking makes keyframes
// in the active map.
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

  // --- the atlas
  std::uint32_t active_map() const { return active_map_.load(std::memory_order_acquire); }
  void set_active_map(std::uint32_t map_id) {
    active_map_.store(map_id, std::memory_order_release);
  }
  // Makes a new, empty map active and returns its id (the same id again until a keyframe of it
  // is added, so a start that fails leaves no gap).
  std::uint32_t open_new_map();
  size_t num_keyframes_in(std::uint32_t map_id) const;
  // Ids of the maps that hold keyframes now, ascending.
  std::vector<std::uint32_t> map_ids() const;
  // The keyframes of `from` join `into` (their poses and points were moved into its frame first);
  // `from`'s anchor stops anchoring and `into` becomes active if `from` was.
  void merge_map(const MapMerge& merge);
  std::vector<MapMerge> merges() const;
  // The map a keyframe made in `map_id` belongs to now, after the merges since.
  std::uint32_t current_map_of(std::uint32_t map_id) const;
  // Removes `map_id`'s keyframes and the points they observe from the atlas (a start that
  // failed); its anchor included.
  void erase_map(std::uint32_t map_id);

  // Empties the atlas (a monocular restart without the atlas); ids start from 0 again.
  void clear();

 private:
  mutable std::mutex mutex_;
  std::map<std::uint64_t, std::shared_ptr<KeyFrame>> keyframes_;
  std::map<std::uint64_t, std::shared_ptr<MapPoint>> map_points_;
  std::vector<std::shared_ptr<MapPoint>> reference_map_points_;
  std::uint64_t max_keyframe_id_ = 0;
  std::map<std::uint32_t, size_t> keyframes_per_map_;
  std::uint32_t next_map_id_ = 0;  // above every map id with keyframes so far
  std::vector<MapMerge> merges_;
  std::atomic<std::uint32_t> active_map_{0};
  std::atomic<std::uint64_t> next_keyframe_id_{0};
  std::atomic<std::uint64_t> next_map_point_id_{0};
  std::mutex update_mutex_;
};

}  // namespace pspslam
