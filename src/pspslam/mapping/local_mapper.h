#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "pspslam/mapping/local_mapping_options.h"

namespace pspslam {

class KeyFrame;
class Map;
class MapPoint;
class PlaceRecognition;

// Counters for monitoring and tests (cumulative since construction).
struct LocalMappingStats {
  std::uint64_t keyframes_processed = 0;
  std::uint64_t points_from_depth = 0;
  std::uint64_t points_triangulated = 0;
  std::uint64_t points_culled = 0;
  std::uint64_t bad_points_swept = 0;  // bad points found still in the Map (erase_bad_map_points)
  std::uint64_t points_fused = 0;
  std::uint64_t keyframes_culled = 0;
  std::uint64_t bundle_adjustments = 0;
  std::uint64_t bundle_adjustments_interrupted = 0;
  std::uint64_t ba_outliers_removed = 0;
  double last_bundle_adjustment_seconds = 0.0;
  double last_bundle_adjustment_cpu_ms = 0.0;
  double last_keyframe_seconds = 0.0;
};

// The local mapping work for one keyframe, synchronously (LocalMapping runs it on its thread;
// tests call it directly). ORB-SLAM2 order:
//   1. insert: register the keyframe's observations, update point normals/descriptors,
//      covisibility, add it to the map; create points from its close depth readings
//   2. cull recent map points that tracking does not find / few keyframes observe
//   3. triangulate new points with the covisible keyframes
//   4. fuse duplicates with first and second neighbours        (skipped if a keyframe waits)
//   5. local bundle adjustment, 6. redundant keyframe culling  (skipped if a keyframe waits)
// With `place` (may be null) each keyframe gets its bag of words in step 1 and enters the
// keyframe database; culled keyframes leave it.
class LocalMapper {
 public:
  LocalMapper(std::shared_ptr<Map> map, LocalMappingOptions options,
              std::shared_ptr<PlaceRecognition> place = nullptr);

  // has_new_keyframe is polled between steps and inside bundle adjustment; when it returns
  // true the optional steps are skipped / the BA stops early, so tracking never waits long.
  void process(const std::shared_ptr<KeyFrame>& keyframe,
               const std::function<bool()>& has_new_keyframe = {});

  const LocalMappingStats& stats() const { return stats_; }

 private:
  void insert_keyframe_into_map(const std::shared_ptr<KeyFrame>& keyframe);
  void cull_recent_points(const KeyFrame& keyframe);
  void fuse_with_neighbours(const std::shared_ptr<KeyFrame>& keyframe);
  void add_recent(const std::vector<std::shared_ptr<MapPoint>>& points);

  std::shared_ptr<Map> map_;
  LocalMappingOptions options_;
  std::shared_ptr<PlaceRecognition> place_;
  // Weak: the Map stays the only owner; a point erased elsewhere just drops out of probation.
  std::vector<std::weak_ptr<MapPoint>> recent_points_;
  LocalMappingStats stats_;
};

}  // namespace pspslam
