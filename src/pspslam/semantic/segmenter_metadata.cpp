#include "pspslam/semantic/segmenter_metadata.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <system_error>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/semantic/segmenter.h"

namespace pspslam {
namespace {

void read_triplet(YamlSection& section, const std::string& key, double out[3]) {
  const auto values = section.required<std::vector<double>>(key);
  if (values.size() != 3) {
    throw Error(section.file() + ": key '" + section.qualified(key) + "' must have 3 values, got " +
                std::to_string(values.size()));
  }
  std::copy(values.begin(), values.end(), out);
}

std::filesystem::path resolve_onnx(const std::filesystem::path& yaml, const std::string& value) {
  const std::string shared_prefix = "${shared}/";
  if (value.rfind(shared_prefix, 0) == 0) {
    return shared_dir() / value.substr(shared_prefix.size());
  }
  const std::filesystem::path path(value);
  return path.is_absolute() ? path : yaml.parent_path() / path;
}

}  // namespace

SegmenterMetadata load_segmenter_metadata(const std::filesystem::path& file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::BadFile&) {
    throw Error("cannot open segmenter metadata '" + file.string() + "'");
  } catch (const YAML::Exception& e) {
    throw Error(file.string() + ":" + std::to_string(e.mark.line + 1) +
                ": not valid YAML: " + e.msg);
  }
  SegmenterMetadata meta;
  meta.file = file;
  YamlSection top(root, file.string(), "");
  meta.name = top.optional<std::string>("name", file.stem().string());
  const std::string onnx = top.required<std::string>("onnx");

  YamlSection input = top.section("input");
  meta.input_width = input.required<int>("width");
  meta.input_height = input.required<int>("height");
  const std::string order = input.required<std::string>("channel_order");
  const std::string layout = input.required<std::string>("layout");
  read_triplet(input, "mean", meta.mean);
  read_triplet(input, "std", meta.std);
  input.finish();

  YamlSection output = top.section("output");
  meta.output_stride = output.required<int>("stride");
  output.finish();

  meta.classes = top.required<std::vector<std::string>>("classes");
  meta.dynamic_classes = top.required<std::vector<std::string>>("dynamic_classes");
  top.finish();

  const std::string where = file.string() + ": ";
  if (meta.input_width <= 0 || meta.input_height <= 0) {
    throw Error(where + "input.width and input.height must be positive");
  }
  if (order != "RGB" && order != "BGR") {
    throw Error(where + "input.channel_order must be RGB or BGR, got '" + order + "'");
  }
  meta.rgb = order == "RGB";
  if (layout != "NCHW") throw Error(where + "input.layout must be NCHW, got '" + layout + "'");
  for (double s : meta.std) {
    if (s == 0.0) throw Error(where + "input.std must not contain 0");
  }
  if (meta.output_stride <= 0 || meta.input_width % meta.output_stride != 0 ||
      meta.input_height % meta.output_stride != 0) {
    throw Error(where + "output.stride must be positive and divide the input size");
  }
  if (meta.classes.empty() || meta.classes.size() > 255) {
    throw Error(where + "classes must list 1 to 255 names");
  }
  class_ids(meta.classes, meta.dynamic_classes, file.string() + ": dynamic_classes");

  meta.onnx = resolve_onnx(file, onnx);
  std::error_code ec;  // a name the file system cannot look up (too long) does not exist either
  if (!std::filesystem::is_regular_file(meta.onnx, ec)) {
    throw Error(where + "onnx file '" + meta.onnx.string() + "' (key 'onnx') does not exist");
  }
  return meta;
}

}  // namespace pspslam
