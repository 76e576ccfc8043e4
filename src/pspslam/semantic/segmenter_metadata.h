#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pspslam {

// Everything OnnxSegmenter needs to run a network, read from a YAML file (see
// models/pspnet/pspnet.yaml). Keys (all required unless marked):
//   name: text                       (optional)
//   onnx: file                       relative to the YAML's folder, or "${shared}/..." for a
//                                    file in the read-only shared folder (pspslam::shared_dir())
//   input: {width, height, channel_order: RGB|BGR, layout: NCHW, mean: [3], std: [3]}
//          mean/std in pixel units (0..255), in the network's channel order:
//          blob = (pixel - mean) / std
//   output: {stride}                 logits are 1 x classes x (height/stride) x (width/stride)
//   classes: [names]                 label id = index
//   dynamic_classes: [names]         default set of dynamic classes (subset of classes)
struct SegmenterMetadata {
  std::filesystem::path file;  // the YAML it was read from
  std::string name;
  std::filesystem::path onnx;  // resolved, exists
  int input_width = 0;
  int input_height = 0;
  bool rgb = true;  // channel order of the network input
  double mean[3] = {0.0, 0.0, 0.0};
  double std[3] = {1.0, 1.0, 1.0};
  int output_stride = 1;
  std::vector<std::string> classes;
  std::vector<std::string> dynamic_classes;
};

// Reads and validates a metadata file. Missing/unknown keys, bad values, unknown class names and
// a missing ONNX file raise pspslam::Error naming the file and the key.
SegmenterMetadata load_segmenter_metadata(const std::filesystem::path& file);

}  // namespace pspslam
