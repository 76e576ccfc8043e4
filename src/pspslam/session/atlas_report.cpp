#include "pspslam/session/atlas_report.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <string>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

// The map a map merged into, after every merge (the merges are in order).
std::uint32_t final_map_of(std::uint32_t map_id, std::span<const MapMerge> merges) {
  for (const MapMerge& merge : merges) {
    if (merge.from == map_id) map_id = merge.into;
  }
  return map_id;
}

}  // namespace

std::vector<MapTrajectory> split_by_map(const Trajectory& poses,
                                        std::span<const std::uint32_t> map_of) {
  if (map_of.size() != poses.size()) {
    throw Error("split_by_map: " + std::to_string(poses.size()) + " poses but " +
                std::to_string(map_of.size()) + " map ids");
  }
  std::map<std::uint32_t, Trajectory> by_map;
  for (size_t i = 0; i < poses.size(); ++i) by_map[map_of[i]].push_back(poses[i]);
  std::vector<MapTrajectory> maps;
  for (auto& [id, trajectory] : by_map) maps.push_back({id, std::move(trajectory)});
  std::stable_sort(maps.begin(), maps.end(), [](const MapTrajectory& a, const MapTrajectory& b) {
    return a.poses.size() > b.poses.size();
  });
  if (maps.empty()) maps.push_back({});
  return maps;
}

std::filesystem::path other_map_file(const std::filesystem::path& folder, const char* stem,
                                     std::uint32_t map_id) {
  return folder / (std::string(stem) + "_map" + std::to_string(map_id) + ".txt");
}

void print_atlas(const AtlasSummary& atlas, std::ostream& out) {
  if (atlas.maps.size() <= 1) return;
  out << "atlas:        " << atlas.maps.size() << " maps, " << atlas.merges.size()
      << " merge(s); the final files are in map " << atlas.final_maps.front().map_id << "\n";
  for (const auto& [id, frames] : atlas.maps) {
    const std::uint32_t now = final_map_of(id, atlas.merges);
    out << "              map " << id << ": " << frames.frames << " frames tracked ("
        << frames.first_frame << "-" << frames.last_frame << ")";
    if (now != id) out << ", merged into map " << now;
    if (now != atlas.final_maps.front().map_id)
      out << ", never merged with the main map: trajectory_refined_map" << now << ".txt";
    out << "\n";
  }
}

nlohmann::ordered_json atlas_json(const AtlasSummary& atlas) {
  nlohmann::ordered_json maps = nlohmann::ordered_json::array();
  for (const auto& [id, frames] : atlas.maps) {
    const std::uint32_t now = final_map_of(id, atlas.merges);
    maps.push_back({{"id", id},
                    {"frames_tracked", frames.frames},
                    {"first_frame", frames.first_frame},
                    {"last_frame", frames.last_frame},
                    {"final_map", now}});
  }
  nlohmann::ordered_json merges = nlohmann::ordered_json::array();
  for (const MapMerge& merge : atlas.merges) {
    merges.push_back({{"from", merge.from},
                      {"into", merge.into},
                      {"current_keyframe", merge.current_keyframe},
                      {"matched_keyframe", merge.matched_keyframe}});
  }
  nlohmann::ordered_json final_maps = nlohmann::ordered_json::array();
  for (const MapTrajectory& map : atlas.final_maps)
    final_maps.push_back({{"id", map.map_id}, {"poses", map.poses.size()}});
  size_t other_poses = 0;
  for (size_t m = 1; m < atlas.final_maps.size(); ++m)
    other_poses += atlas.final_maps[m].poses.size();
  return {{"new_map_after_s", atlas.new_map_after_seconds},
          // Counts first, for tables: maps tracked in, merges, and the final poses in the main
          // map (trajectory_refined.txt) and in maps that never merged with it.
          {"maps_tracked_in", atlas.maps.size()},
          {"merge_count", atlas.merges.size()},
          {"main_map_poses", atlas.final_maps.empty() ? 0 : atlas.final_maps.front().poses.size()},
          {"other_map_poses", other_poses},
          {"maps", maps},
          {"merges", merges},
          {"maps_at_end", atlas.maps_at_end},
          // First: the main map, whose poses are trajectory_refined.txt.
          {"final_trajectories", final_maps}};
}

}  // namespace pspslam
