#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>

namespace pspslam {

class Map;
struct CameraModel;
struct ScalePyramid;

struct MapFileSummary {
  std::size_t keyframes = 0;
  std::size_t map_points = 0;
  std::size_t observations = 0;
  std::size_t bytes = 0;  // file size
};

// Binary map file ("PSPSLMAP", format in map_file.cpp): keyframes (pose, undistorted
// keypoints, descriptors, depth per keypoint, map point per keypoint, spanning-tree parent) and
// map points (position, reference keyframe). The rest is derived on load exactly as the live
// system derives it: observations from the keyframes' associations, representative
// descriptors, normals and distance ranges, covisibility; BoW vectors are recomputed by whoever
// indexes the keyframes (System). Versioned and checksummed (FNV-1a 64 of the payload).
//
// Saving needs a quiet map: call it after System::shutdown() (it takes Map::update_mutex()).
// Throws pspslam::Error naming the file when it cannot be written.
MapFileSummary save_map(Map& map, const CameraModel& camera, const ScalePyramid& pyramid,
                        const std::filesystem::path& file);

// Loads a map file into `map`, which must be empty. Keyframe and map point ids are renumbered
// from the map's counters (in saved id order, so the first keyframe stays the anchor). The
// camera and pyramid must be the ones the map was made with (compared with the file's).
// Throws pspslam::Error naming the file and what is wrong: missing, bad magic, unsupported
// version, truncated, checksum mismatch, different camera, inconsistent content. On error the
// map is left untouched (the whole file is checked before anything is created).
MapFileSummary load_map(const std::filesystem::path& file, Map& map,
                        std::shared_ptr<const CameraModel> camera,
                        std::shared_ptr<const ScalePyramid> pyramid);

}  // namespace pspslam
