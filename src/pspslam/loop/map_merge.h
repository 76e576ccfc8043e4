#pragma once

// Merging two maps of the atlas (ORB-SLAM3's map merging, built on our loop correction). A
// keyframe of one map that recognises a place in another is found exactly as a loop is
// (LoopDetector: BoW, covisibility consistency, 3D-3D RANSAC, guided matching, projection); the
// verified transform is a Sim(3) for monocular maps and an SE(3) where depth fixes the scale.
// Its whole map is then moved into the other's frame and relabelled (this file). What remains is
// a loop, and correct_loop() treats it as one: it fuses the duplicated points along the seam,
// links the two sides in the essential graph and spreads the residual over both; the global BA
// that follows, on the merged map only, welds the seam.

namespace pspslam {

class Map;
struct DetectedLoop;

// Moves `loop.current`'s map into `loop.matched`'s frame (keyframe poses and the points they
// see: x_matched_world = S · x_current_world, S from the verified loop), relabels its keyframes
// (Map::merge_map) and returns the loop as it stands afterwards: the current keyframe is where
// the loop puts it, so the correction only fuses and optimises. Call with Map::update_mutex()
// held and local mapping stopped.
DetectedLoop bring_into_matched_map(Map& map, const DetectedLoop& loop);

}  // namespace pspslam
