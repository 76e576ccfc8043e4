#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/semantic/semantic_params.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

const char* kValid = R"(name: tiny
onnx: model.onnx
input:
  width: 64
  height: 48
  channel_order: BGR
  layout: NCHW
  mean: [1, 2, 3]
  std: [4, 5, 6]
output:
  stride: 8
classes: [background, person, dog]
dynamic_classes: [person]
)";

std::filesystem::path write_yaml(const std::filesystem::path& dir, const std::string& text,
                                 bool with_onnx = true) {
  if (with_onnx) std::ofstream(dir / "model.onnx") << "not really onnx";
  const auto file = dir / "meta.yaml";
  std::ofstream(file) << text;
  return file;
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

std::string error_of(const std::filesystem::path& file) {
  try {
    load_segmenter_metadata(file);
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(SegmenterMetadata, ReadsAllKeys) {
  const auto dir = testing::make_temp_dir("semantic");
  const auto meta = load_segmenter_metadata(write_yaml(dir, kValid));
  EXPECT_EQ(meta.name, "tiny");
  EXPECT_EQ(meta.onnx, dir / "model.onnx");
  EXPECT_EQ(meta.input_width, 64);
  EXPECT_EQ(meta.input_height, 48);
  EXPECT_FALSE(meta.rgb);
  EXPECT_DOUBLE_EQ(meta.mean[2], 3.0);
  EXPECT_DOUBLE_EQ(meta.std[0], 4.0);
  EXPECT_EQ(meta.output_stride, 8);
  EXPECT_EQ(meta.classes, (std::vector<std::string>{"background", "person", "dog"}));
  EXPECT_EQ(meta.dynamic_classes, (std::vector<std::string>{"person"}));
}

TEST(SegmenterMetadata, MissingKeyIsNamed) {
  const auto dir = testing::make_temp_dir("semantic");
  const auto file = write_yaml(dir, replace(kValid, "  height: 48\n", ""));
  EXPECT_EQ(error_of(file), file.string() + ": missing key 'input.height'");
  const auto file2 = write_yaml(dir, replace(kValid, "dynamic_classes: [person]\n", ""));
  EXPECT_EQ(error_of(file2), file2.string() + ": missing key 'dynamic_classes'");
}

TEST(SegmenterMetadata, UnknownKeyIsNamedWithItsLine) {
  const auto dir = testing::make_temp_dir("semantic");
  const auto file =
      write_yaml(dir, replace(kValid, "  layout: NCHW\n", "  layout: NCHW\n  scale: 2\n"));
  EXPECT_EQ(error_of(file), file.string() + ":8: unknown key 'input.scale'");
  const auto file2 = write_yaml(dir, std::string(kValid) + "licence: MIT\n");
  EXPECT_EQ(error_of(file2), file2.string() + ":14: unknown key 'licence'");
}

TEST(SegmenterMetadata, MissingOnnxFileIsNamed) {
  const auto dir = testing::make_temp_dir("semantic");
  const auto file = write_yaml(dir, kValid, false);
  EXPECT_EQ(error_of(file), file.string() + ": onnx file '" + (dir / "model.onnx").string() +
                                "' (key 'onnx') does not exist");
}

TEST(SegmenterMetadata, BadValuesAreNamed) {
  const auto dir = testing::make_temp_dir("semantic");
  auto file = write_yaml(dir, replace(kValid, "channel_order: BGR", "channel_order: RBG"));
  EXPECT_EQ(error_of(file), file.string() + ": input.channel_order must be RGB or BGR, got 'RBG'");
  file = write_yaml(dir, replace(kValid, "mean: [1, 2, 3]", "mean: [1, 2]"));
  EXPECT_EQ(error_of(file), file.string() + ": key 'input.mean' must have 3 values, got 2");
  file = write_yaml(dir, replace(kValid, "width: 64", "width: wide"));
  EXPECT_EQ(error_of(file), file.string() + ":4: key 'input.width' has an invalid value");
  file = write_yaml(dir, replace(kValid, "dynamic_classes: [person]", "dynamic_classes: [cat]"));
  EXPECT_EQ(error_of(file), file.string() +
                                ": dynamic_classes: unknown class 'cat' (classes: background, "
                                "person, dog)");
  EXPECT_EQ(error_of(dir / "absent.yaml"),
            "cannot open segmenter metadata '" + (dir / "absent.yaml").string() + "'");
}

TEST(SegmenterMetadata, SharedPrefixResolvesToTheSharedFolder) {
  const auto dir = testing::make_temp_dir("semantic");
  std::filesystem::create_directories(dir / "models");
  std::ofstream(dir / "models" / "teacher.onnx") << "x";
  const char* old = std::getenv("PSPSLAM_SHARED");
  const std::string saved = old ? old : "";
  setenv("PSPSLAM_SHARED", dir.c_str(), 1);
  const auto file =
      write_yaml(dir, replace(kValid, "onnx: model.onnx", "onnx: ${shared}/models/teacher.onnx"));
  const auto meta = load_segmenter_metadata(file);
  if (old) {
    setenv("PSPSLAM_SHARED", saved.c_str(), 1);
  } else {
    unsetenv("PSPSLAM_SHARED");
  }
  EXPECT_EQ(meta.onnx, dir / "models" / "teacher.onnx");
}

TEST(SegmenterMetadata, ShippedModelMetadataIsValid) {
  const auto meta = load_segmenter_metadata(source_dir() / "models" / "pspnet" / "pspnet.yaml");
  EXPECT_EQ(meta.classes.size(), 21u);
  EXPECT_EQ(meta.classes[15], "person");
  EXPECT_EQ(meta.dynamic_classes.size(), 14u);
  EXPECT_TRUE(meta.rgb);
  EXPECT_EQ(meta.output_stride, 1);
  EXPECT_LE(std::filesystem::file_size(meta.onnx), 16u * 1024 * 1024);
}

TEST(SemanticParams, DefaultsOverridesAndUnknownKeys) {
  const YAML::Node empty = YAML::Load("{}");
  YamlSection s0(empty, "c.yaml", "semantic");
  const SemanticParams d = SemanticParams::from_yaml(s0);
  EXPECT_TRUE(d.enabled);
  EXPECT_EQ(d.model, "models/pspnet/pspnet.yaml");
  EXPECT_TRUE(d.dynamic_classes.empty());
  EXPECT_EQ(d.queue_size, 1);

  const YAML::Node node =
      YAML::Load("enabled: false\ndynamic_classes: [person, dog]\nmask_dilation_px: 3\n");
  YamlSection s1(node, "c.yaml", "semantic");
  const SemanticParams p = SemanticParams::from_yaml(s1);
  EXPECT_FALSE(p.enabled);
  EXPECT_EQ(p.dynamic_classes, (std::vector<std::string>{"person", "dog"}));
  EXPECT_EQ(p.mask_dilation_px, 3);

  const YAML::Node bad = YAML::Load("queue_size: 1\nqueue: 2\n");
  YamlSection s2(bad, "c.yaml", "semantic");
  try {
    SemanticParams::from_yaml(s2);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "c.yaml:2: unknown key 'semantic.queue'");
  }
  const YAML::Node negative = YAML::Load("queue_size: 0\n");
  YamlSection s3(negative, "c.yaml", "semantic");
  try {
    SemanticParams::from_yaml(s3);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "c.yaml: key 'semantic.queue_size' must be >= 1");
  }
}

}  // namespace
}  // namespace pspslam
