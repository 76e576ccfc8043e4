#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <ostream>
#include <span>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/map/map.h"

namespace pspslam {

// The frames one map of the atlas held while they were tracked (sequence indices).
struct MapFrames {
  size_t frames = 0;
  size_t first_frame = 0;
  size_t last_frame = 0;
};

// The final poses of one map of the atlas (after the merges), in its world frame.
struct MapTrajectory {
  std::uint32_t map_id = 0;
  Trajectory poses;
};

// The final trajectory split by the map each pose ends in (`map_of`: one id per pose). The main
// map, the one with the most poses (the lowest id among equals), comes first: it is the run's
// trajectory_refined.txt; the others are maps that never merged with it, each in a world frame
// (and, monocular, a scale) of its own.
std::vector<MapTrajectory> split_by_map(const Trajectory& poses,
                                        std::span<const std::uint32_t> map_of);

// What the run's summary and stats.json say of the atlas.
struct AtlasSummary {
  double new_map_after_seconds = 0.0;       // 0: no new maps (TrackerOptions)
  std::map<std::uint32_t, MapFrames> maps;  // as tracked: the map each frame was tracked in
  std::vector<MapMerge> merges;
  std::vector<std::uint32_t> maps_at_end;     // maps holding keyframes at the end
  std::span<const MapTrajectory> final_maps;  // split_by_map of the final trajectory
};

// The file of a map other than the main one: trajectory_refined_map<ID>.txt, keyframes_map<ID>.txt.
std::filesystem::path other_map_file(const std::filesystem::path& folder, const char* stem,
                                     std::uint32_t map_id);

// One summary line per map beyond the first (nothing when the run used one map).
void print_atlas(const AtlasSummary& atlas, std::ostream& out);
nlohmann::ordered_json atlas_json(const AtlasSummary& atlas);

}  // namespace pspslam
