#pragma once

#include <string>
#include <vector>

#include "pspslam/core/yaml_section.h"
#include "pspslam/semantic/semantic_delay.h"

namespace pspslam {

// YAML section `semantic:` (all keys optional).
struct SemanticParams {
  bool enabled = true;
  // Segmenter metadata file; relative paths are relative to the source directory.
  std::string model = "models/pspnet/pspnet.yaml";
  // Names of dynamic classes; empty = the model's dynamic_classes.
  std::vector<std::string> dynamic_classes;
  int mask_dilation_px = 5;  // grow the dynamic mask by this margin (pixels)
  int queue_size = 1;        // pending frames kept; older ones are dropped when full
  int history = 64;          // published results kept for look-up by timestamp
  // Nice increment of the semantic thread (not a YAML key: real-time runs set it).
  int thread_nice = 0;
  // Extra wait after each segmentation (not a YAML key: `run --semantic-delay-ms`).
  SemanticDelay injected_delay;

  // Reads the keys of `section`, calls section.finish() (unknown keys are errors) and
  // validates the values (pspslam::Error naming the key).
  static SemanticParams from_yaml(YamlSection& section);
};

}  // namespace pspslam
