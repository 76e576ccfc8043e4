#include <gtest/gtest.h>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/geometry/geometry_stage.h"
#include "support/geometry_test_scene.h"

namespace pspslam {
namespace {

struct Rendered {
  cv::Mat depth, labels;
};

TEST(GeometryStage, DetectsPeopleAndCarriedBoxInGeometryTestScene) {
  GeometryTestSceneParams scene_params;
  scene_params.seed = 3;
  const GeometryTestScene scene(scene_params);
  const int current = 40;
  std::vector<DepthView> references;
  std::vector<Rendered> keep;
  for (int frame = current - 10; frame >= current - 30; frame -= 10) {
    Rendered r;
    scene.render(frame, r.depth, r.labels);
    references.push_back({scene.camera_pose(frame), r.depth});
    keep.push_back(r);
  }
  Rendered now;
  scene.render(current, now.depth, now.labels);
  const std::vector<Eigen::Vector2d> keypoints = sample_candidate_pixels(now.depth, 1000, 11);

  GeometryStage stage(scene_params.camera, GeometryParams{});
  GeometryFrameInput input;
  input.depth = now.depth;
  input.T_world_camera = scene.camera_pose(current);
  input.keypoints = keypoints;
  input.references = references;
  const GeometryFrameResult result = stage.process(input);

  int true_positive = 0, false_positive = 0, false_negative = 0, carried = 0, carried_found = 0;
  for (size_t i = 0; i < keypoints.size(); ++i) {
    const int label = now.labels.at<std::uint8_t>(static_cast<int>(keypoints[i].y()),
                                                  static_cast<int>(keypoints[i].x()));
    const bool dynamic = label != 0;
    if (label == 100) {
      ++carried;
      carried_found += result.keypoint_dynamic[i];
    }
    if (dynamic && result.keypoint_dynamic[i]) ++true_positive;
    if (!dynamic && result.keypoint_dynamic[i]) ++false_positive;
    if (dynamic && !result.keypoint_dynamic[i]) ++false_negative;
  }
  ASSERT_GT(true_positive + false_negative, 20);
  const double recall = static_cast<double>(true_positive) / (true_positive + false_negative);
  const double precision = static_cast<double>(true_positive) / (true_positive + false_positive);
  EXPECT_GE(recall, 0.9);
  EXPECT_GE(precision, 0.9);
  if (carried > 0) {
    EXPECT_GE(carried_found, carried * 0.8);
  }
  EXPECT_LT(result.tested_count, static_cast<int>(keypoints.size()));
  EXPECT_EQ(result.dynamic_mask.type(), CV_8UC1);
  EXPECT_EQ(result.dynamic_mask.size(), now.depth.size());
  EXPECT_GT(result.timing.total_ms, 0.0);
}

// System computes the compensated homography in its flow step and passes it with the unwarped
// previous mask: the stage must use that H (not estimate one from matches) to map the mask.
TEST(GeometryStage, UsesTheGivenHomographyForThePreviousMask) {
  const PinholeCamera camera;  // 640x480, f = 525 px
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(3.0f));
  cv::Mat previous_mask = cv::Mat::zeros(480, 640, CV_8UC1);
  previous_mask(cv::Rect(100, 150, 80, 200)).setTo(255);
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  H(0, 2) = 25.0;  // the scene moved 25 px to the right
  H(1, 2) = -10.0;
  // Matches of a different motion: they must be ignored when H is given.
  const std::vector<Eigen::Vector2d> previous{
      {10, 10}, {600, 20}, {30, 450}, {620, 460}, {300, 200}};
  std::vector<Eigen::Vector2d> current;
  for (const Eigen::Vector2d& p : previous) current.push_back(p + Eigen::Vector2d(-40.0, 0.0));
  const std::vector<Eigen::Vector2d> keypoints{{140.0, 250.0}, {165.0, 240.0}, {400.0, 300.0}};

  GeometryParams params;
  params.output_warped_previous_mask = true;
  GeometryStage stage(camera, params);
  GeometryFrameInput input;
  input.depth = depth;
  input.keypoints = keypoints;
  input.matched_previous = previous;
  input.matched_current = current;
  input.H_previous_to_current = H;
  input.previous_dynamic_mask = previous_mask;
  const GeometryFrameResult result = stage.process(input);

  EXPECT_FALSE(result.homography.valid);  // nothing estimated
  const cv::Mat expected = warp_to_current(previous_mask, H, depth.size(), true);
  EXPECT_EQ(cv::countNonZero(result.warped_previous_mask != expected), 0);
  EXPECT_EQ(cv::countNonZero(result.warped_previous_mask), 80 * 200);
  // (140, 250) maps back to (115, 260), inside the previous mask: a priority point, tested first.
  // (165, 240) maps to (140, 250), also inside; (400, 300) is tested only if the path passes it.
  EXPECT_EQ(result.keypoint_tested[0], 1);
  EXPECT_EQ(result.keypoint_tested[1], 1);
}

TEST(GeometryStage, FuseMasksIsDilatedOr) {
  cv::Mat semantic = cv::Mat::zeros(100, 100, CV_8UC1), geometry = semantic.clone();
  semantic.at<std::uint8_t>(10, 10) = 15;  // label values count as dynamic
  geometry.at<std::uint8_t>(80, 80) = 255;
  const cv::Mat fused = fuse_dynamic_masks(semantic, geometry, 2);
  EXPECT_EQ(fused.at<std::uint8_t>(10, 10), 255);
  EXPECT_EQ(fused.at<std::uint8_t>(12, 10), 255);
  EXPECT_EQ(fused.at<std::uint8_t>(80, 82), 255);
  EXPECT_EQ(fused.at<std::uint8_t>(50, 50), 0);
  EXPECT_EQ(fused.at<std::uint8_t>(10, 13), 0);
  EXPECT_EQ(cv::countNonZero(fuse_dynamic_masks(cv::Mat(), geometry, 0)), 1);
  try {
    fuse_dynamic_masks(semantic, cv::Mat::zeros(50, 50, CV_8UC1), 0);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(
        e.what(),
        "fuse_dynamic_masks: semantic mask 100x100 and geometry mask 50x50 differ in size");
  }
}

TEST(GeometryStage, ParamsFromYamlReadsSubsections) {
  const YAML::Node node = YAML::Load(
      "homography: {inlier_threshold_px: 3}\nsearch: {strategy: exhaustive}\n"
      "region: {stride: 4}\nprevious_mask_prior: false\n");
  YamlSection section(node, "s.yaml", "geometry");
  const GeometryParams p = GeometryParams::from_yaml(section);
  EXPECT_DOUBLE_EQ(p.homography.inlier_threshold_px, 3.0);
  EXPECT_EQ(p.search.strategy, SearchStrategy::exhaustive);
  EXPECT_EQ(p.region.stride, 4);
  EXPECT_FALSE(p.previous_mask_prior);
  const YAML::Node bad = YAML::Load("region: {strid: 4}\n");
  YamlSection bad_section(bad, "s.yaml", "geometry");
  try {
    GeometryParams::from_yaml(bad_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(
        e.what(),
        "s.yaml:1: unknown key 'geometry.region.strid' (did you mean 'geometry.region.stride'?)");
  }
}

}  // namespace
}  // namespace pspslam
