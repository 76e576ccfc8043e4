#pragma once

#include <string>

namespace pspslam {

// Which dynamic-feature detectors run (`pspslam run --dynamic`).
enum class DynamicMode {
  off,         // plain ORB-SLAM2: every feature is used
  semantic,    // a-priori dynamic classes of the segmentation (paper III.A) only
  geometry,    // compensated homography + multi-view test + region growing (III.B/C) only
  full,        // semantic + geometry with the reverse ant-colony search (the paper's system)
  exhaustive,  // semantic + geometry testing every keypoint (DynaSLAM-like baseline)
};

const char* to_string(DynamicMode mode);
// Throws pspslam::Error naming `flag` and the accepted values.
DynamicMode parse_dynamic_mode(const std::string& text, const std::string& flag);

inline bool uses_semantics(DynamicMode mode) {
  return mode == DynamicMode::semantic || mode == DynamicMode::full ||
         mode == DynamicMode::exhaustive;
}
inline bool uses_geometry(DynamicMode mode) {
  return mode == DynamicMode::geometry || mode == DynamicMode::full ||
         mode == DynamicMode::exhaustive;
}

}  // namespace pspslam
