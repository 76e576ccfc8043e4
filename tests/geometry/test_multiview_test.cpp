#include <gtest/gtest.h>

#include <random>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/geometry/multiview_test.h"

namespace pspslam {
namespace {

PinholeCamera camera() {
  PinholeCamera c;
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 525.0;
  c.cx = 319.5;
  c.cy = 239.5;
  return c;
}

Pose translated(double x) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  return T;
}

// Two-view scene: a wall 3 m in front of both cameras; the reference is 10 cm to the left.
struct TwoViewScene {
  std::vector<DepthView> references{
      {translated(-0.1), cv::Mat(480, 640, CV_32FC1, cv::Scalar(3.0f))}};
  Pose T_world_current = Pose::Identity();
};

TEST(MultiViewTest, FlagsMovedPointNotStaticOne) {
  const TwoViewScene scene;
  MultiViewTest test(camera(), MultiViewParams{});
  test.set_frame(scene.T_world_current, scene.references);

  // On the wall in both views: consistent.
  const MultiViewVerdict wall = test.evaluate({{320.0, 240.0}, 3.0});
  EXPECT_EQ(wall.valid_references, 1);
  EXPECT_EQ(wall.dynamic_votes, 0);
  EXPECT_FALSE(wall.dynamic);

  // A person now 2 m away where the reference saw the wall: the reference sees through it.
  const MultiViewVerdict moved = test.evaluate({{320.0, 240.0}, 2.0});
  EXPECT_EQ(moved.valid_references, 1);
  EXPECT_EQ(moved.dynamic_votes, 1);
  EXPECT_TRUE(moved.dynamic);

  // Small depth noise (1 cm at 3 m) stays static.
  EXPECT_FALSE(test.is_dynamic({{100.0, 50.0}, 3.01}));
}

TEST(MultiViewTest, OcclusionInReferenceOnlyCountsWithEitherSign) {
  // In the reference an object stood 1.5 m away in front of the wall; now it is gone and the
  // candidate is the (static) wall behind it.
  TwoViewScene scene;
  scene.references[0].depth(cv::Rect(250, 180, 150, 120)).setTo(1.5f);
  MultiViewTest farther(camera(), MultiViewParams{});
  farther.set_frame(scene.T_world_current, scene.references);
  EXPECT_FALSE(farther.is_dynamic({{320.0, 240.0}, 3.0}));
  MultiViewParams symmetric;
  symmetric.disagreement = DepthDisagreement::either_sign;
  MultiViewTest either(camera(), symmetric);
  either.set_frame(scene.T_world_current, scene.references);
  EXPECT_TRUE(either.is_dynamic({{320.0, 240.0}, 3.0}));
}

TEST(MultiViewTest, WideParallaxAndMissingDepthAreNotEvidence) {
  TwoViewScene scene;
  // 3 m baseline at 2 m depth: ~56 degrees of parallax, above the 30 degree limit.
  scene.references.push_back({translated(-3.0), cv::Mat(480, 640, CV_32FC1, cv::Scalar(9.0f))});
  scene.references[0].depth.setTo(0.0f);  // first reference has no depth readings at all
  MultiViewTest test(camera(), MultiViewParams{});
  test.set_frame(scene.T_world_current, scene.references);
  const MultiViewVerdict verdict = test.evaluate({{320.0, 240.0}, 2.0});
  EXPECT_EQ(verdict.valid_references, 0);
  EXPECT_FALSE(verdict.dynamic);
  // Out-of-range candidate depth is never tested.
  EXPECT_EQ(test.evaluate({{320.0, 240.0}, 0.0}).valid_references, 0);
}

TEST(MultiViewTest, VoteFraction) {
  TwoViewScene scene;
  // Second reference: the moving object was already there (consistent), third: wall again.
  cv::Mat with_person(480, 640, CV_32FC1, cv::Scalar(3.0f));
  with_person(cv::Rect(200, 150, 250, 200)).setTo(2.0f);
  scene.references.push_back({translated(0.05), with_person});
  scene.references.push_back({translated(0.1), cv::Mat(480, 640, CV_32FC1, cv::Scalar(3.0f))});
  MultiViewParams majority;
  majority.min_dynamic_vote_fraction = 0.5;
  MultiViewTest test(camera(), majority);
  test.set_frame(scene.T_world_current, scene.references);
  const MultiViewVerdict v = test.evaluate({{320.0, 240.0}, 2.0});
  EXPECT_EQ(v.valid_references, 3);
  EXPECT_EQ(v.dynamic_votes, 2);
  EXPECT_TRUE(v.dynamic);  // 2 of 3 >= 0.5
  MultiViewParams unanimous;
  unanimous.min_dynamic_vote_fraction = 1.0;
  MultiViewTest strict(camera(), unanimous);
  strict.set_frame(scene.T_world_current, scene.references);
  EXPECT_FALSE(strict.is_dynamic({{320.0, 240.0}, 2.0}));
  // The default (0.2, "any one of up to 5") stops at the first dynamic vote.
  MultiViewTest any(camera(), MultiViewParams{});
  any.set_frame(scene.T_world_current, scene.references);
  const MultiViewVerdict first = any.evaluate({{320.0, 240.0}, 2.0});
  EXPECT_TRUE(first.dynamic);
  EXPECT_EQ(first.dynamic_votes, 1);
  EXPECT_EQ(first.valid_references, 1);
}

// The patch rule written out pixel by pixel in double precision: a reference votes dynamic when
// the patch has a valid pixel and every valid pixel disagrees.
bool patch_votes_dynamic(const cv::Mat& depth, int u, int v, int r, double projected,
                         const MultiViewParams& p) {
  const double threshold = p.depth_threshold_abs_m + p.depth_threshold_relative * projected;
  bool valid = false, agrees = false;
  for (int y = v - r; y <= v + r; ++y) {
    for (int x = u - r; x <= u + r; ++x) {
      const double measured = depth.at<float>(y, x);
      if (!(measured > 0.0)) continue;
      valid = true;
      const double difference = measured - projected;
      agrees |= p.disagreement == DepthDisagreement::farther_only
                    ? difference <= threshold
                    : std::abs(difference) <= threshold;
    }
  }
  return valid && !agrees;
}

// The centre shortcut and the branch-free patch scan must give the verdict of the plain rule on
// every point: a depth image of random boxes (edges everywhere) with 10 % holes, points near the
// measured depths, both disagreement rules.
TEST(MultiViewTest, PatchScanMatchesThePlainPatchRule) {
  std::mt19937 rng(11);
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(3.5f));
  std::uniform_int_distribution<int> x_of(0, 639), y_of(0, 479), size_of(4, 60);
  std::uniform_real_distribution<float> depth_of(0.8f, 4.0f), unit(0.0f, 1.0f);
  for (int box = 0; box < 400; ++box) {
    const int x = x_of(rng), y = y_of(rng);
    const cv::Rect rect = cv::Rect(x, y, size_of(rng), size_of(rng)) & cv::Rect(0, 0, 640, 480);
    depth(rect).setTo(depth_of(rng));
  }
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      if (unit(rng) < 0.1f) depth.at<float>(y, x) = 0.0f;
  const std::vector<DepthView> references{{Pose::Identity(), depth}};
  std::uniform_real_distribution<double> offset(-0.4, 0.4);
  for (const DepthDisagreement rule :
       {DepthDisagreement::farther_only, DepthDisagreement::either_sign}) {
    MultiViewParams params;
    params.disagreement = rule;
    params.max_parallax_deg = 180.0;
    MultiViewTest test(camera(), params);
    int dynamic = 0, agreeing = 0, mismatches = 0;
    for (int frame = 0; frame < 2; ++frame) {
      test.set_frame(Pose::Identity(), references);  // same view: the pixel maps to itself
      for (int i = 0; i < 20000; ++i) {
        const int u = std::uniform_int_distribution<int>(4, 635)(rng);
        const int v = std::uniform_int_distribution<int>(4, 475)(rng);
        const double measured = depth.at<float>(v, u);
        const double point_depth = (measured > 0.0 ? measured : 2.0) + offset(rng);
        const MultiViewVerdict verdict = test.evaluate({{double(u), double(v)}, point_depth});
        const bool expected = patch_votes_dynamic(depth, u, v, 4, point_depth, params);
        mismatches += verdict.dynamic != expected;
        dynamic += expected;
        agreeing += !expected && verdict.valid_references == 1;
      }
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(dynamic, 5000);  // both outcomes are exercised
    EXPECT_GT(agreeing, 5000);
  }
}

TEST(MultiViewTest, ParamsFromYamlNameTheKey) {
  const YAML::Node node = YAML::Load(
      "depth_threshold_relative: 0.05\ndisagreement: either_sign\nmax_parallax_deg: 25\n");
  YamlSection section(node, "g.yaml", "geometry.multiview");
  const MultiViewParams p = MultiViewParams::from_yaml(section);
  EXPECT_DOUBLE_EQ(p.depth_threshold_relative, 0.05);
  EXPECT_EQ(p.disagreement, DepthDisagreement::either_sign);
  EXPECT_DOUBLE_EQ(p.max_parallax_deg, 25.0);

  const YAML::Node bad = YAML::Load("min_dynamic_vote_fraction: 0\n");
  YamlSection bad_section(bad, "g.yaml", "geometry.multiview");
  try {
    MultiViewParams::from_yaml(bad_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "g.yaml:1: key 'geometry.multiview.min_dynamic_vote_fraction' must be in (0, 1]");
  }
  const YAML::Node wrong_type = YAML::Load("max_parallax_deg: wide\n");
  YamlSection type_section(wrong_type, "g.yaml", "geometry.multiview");
  try {
    MultiViewParams::from_yaml(type_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "g.yaml:1: key 'geometry.multiview.max_parallax_deg' has an invalid value");
  }
}

}  // namespace
}  // namespace pspslam
