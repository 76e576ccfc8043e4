#pragma once

#include "pspslam/config/config.h"

namespace pspslam {

// ORB extractor parameters as ORB-SLAM2 defines them (YAML section `orb:`, all optional).
struct OrbConfig {
  int n_features = 1000;
  double scale_factor = 1.2;
  int n_levels = 8;
  int initial_fast_threshold = 20;
  int min_fast_threshold = 7;
  // When an extraction mask removes part of the image, keep the kept-keypoint count near
  // n_features: a pyramid level with fewer unmasked corners than its share is searched again at
  // min_fast_threshold, and what it still lacks goes to the levels that have corners to spare
  // (ORB-SLAM2 has neither, so a frame mostly covered by people keeps far fewer keypoints than
  // asked for). Frames without masked pixels are extracted exactly as with it off. YAML key
  // `mask_compensation`. Off by default: on real crowded sequences it keeps the count but makes
  // every mode less accurate, for reasons not established (docs/decisions/mask-compensation.md).
  bool mask_compensation = false;
};

// The `orb:` section of a config. Errors name the file, the line and the key: an unknown key,
// a value of the wrong type, n_features or n_levels not positive, scale_factor not above 1.
OrbConfig read_orb_config(const ConfigSection& section);

}  // namespace pspslam
