// The dynamic pipeline on synthetic frames with walking people, driven through the frame path
// that runs it (TrackingModule::process) with no System and no background threads: the
// keypoints it drops are compared with the renderer's own labels.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <memory>
#include <string>

#include "pspslam/eval/ate.h"
#include "pspslam/map/camera_model.h"
#include "pspslam/map/map.h"
#include "pspslam/map/scale_pyramid.h"
#include "pspslam/synth/scene.h"
#include "pspslam/system/frame_builder.h"
#include "pspslam/system/tracking_module.h"
#include "support/input_frames.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

// Keypoint fates of a run, counted against where the people really are.
struct FateCounts {
  int dropped_on_people = 0;  // geometry fate on a person (within a few pixels of one)
  int dropped_elsewhere = 0;
  int kept_on_people = 0;  // reached tracking although on a person
  int semantic_off_mask = 0;
  int semantic = 0;
  int all = 0;        // every keypoint recorded
  int on_people = 0;  // of which on a person
};

bool on(const cv::Mat& mask, const cv::Point2f& position) {
  const int u = std::clamp(cvRound(position.x), 0, mask.cols - 1);
  const int v = std::clamp(cvRound(position.y), 0, mask.rows - 1);
  return mask.at<std::uint8_t>(v, u) != 0;
}

class DynamicPipelineRun {
 public:
  DynamicPipelineRun(const SyntheticScene& scene, const DynamicOptions& dynamic)
      : scene_(scene), config_(synthetic_system_config()) {
    SystemOptions options;
    options.dynamic = dynamic;
    options.place.relocalization = false;
    options.record_keypoint_fates = true;
    const auto camera =
        std::make_shared<const CameraModel>(CameraModel::from_config(config_.camera, 0.08));
    const auto pyramid = std::make_shared<const ScalePyramid>(
        ScalePyramid::from_config(read_orb_config(config_.orb)));
    tracking_ = std::make_unique<TrackingModule>(config_, options,
                                                 make_frame_builder(config_, camera, pyramid, true),
                                                 map_, nullptr, nullptr, BackEndHooks{});
  }

  // Every frame through the path; returns the fates counted from frame `count_from` on.
  FateCounts run(size_t count_from) {
    FateCounts counts;
    SynthFrame rendered;
    for (size_t i = 0; i < scene_.frame_count(); ++i) {
      scene_.render(i, rendered, 1);
      InputFrame input = grey_depth_frame(scene_.timestamp(i), {}, rendered.depth_sensor);
      input.bgr = rendered.bgr;
      input.name = "rgb/" + std::to_string(i) + ".png";
      const FrameReport report = tracking_->process(input);
      if (!report.tracking.T_world_camera) continue;
      estimate_.push_back({scene_.timestamp(i), *report.tracking.T_world_camera});
      if (i >= count_from) count(report, rendered.labels, counts);
    }
    return counts;
  }

  const Trajectory& estimate() const { return estimate_; }
  const TrackingModule& tracking() const { return *tracking_; }

 private:
  static void count(const FrameReport& report, const cv::Mat& labels, FateCounts& counts) {
    const cv::Mat people = labels != kSynthLabelStatic;
    cv::Mat near_people;
    cv::dilate(people, near_people, cv::Mat(), {-1, -1}, 4);
    for (const KeypointRecord& record : report.keypoints) {
      ++counts.all;
      if (on(people, record.position)) ++counts.on_people;
      switch (record.fate) {
        case KeypointFate::geometry:
          ++(on(near_people, record.position) ? counts.dropped_on_people
                                              : counts.dropped_elsewhere);
          break;
        case KeypointFate::semantic:
          ++counts.semantic;
          if (!on(people, record.position)) ++counts.semantic_off_mask;
          break;
        case KeypointFate::tracked:
        case KeypointFate::unmatched:
          if (on(people, record.position)) ++counts.kept_on_people;
          break;
      }
    }
  }

  const SyntheticScene& scene_;
  SystemConfig config_;
  Map map_;
  std::unique_ptr<TrackingModule> tracking_;
  Trajectory estimate_;
};

DynamicOptions dynamic_mode(DynamicMode mode, std::filesystem::path semantic_masks = {}) {
  DynamicOptions options;
  options.mode = mode;
  options.semantic_masks = std::move(semantic_masks);
  return options;
}

SynthOptions people_room(size_t frames) {
  SynthOptions options;
  options.frames = frames;
  options.bodies = 3;
  options.seed = 1;
  options.threads = 1;
  return options;
}

// Geometry alone (no network): the multi-view test against the keyframes' depth finds the
// people once there are keyframes to compare with. Without the network it is not precise (its
// regions grow over static surfaces near a find, and noisy depth flags some static points), so
// the bounds say what it does: its drops fall on people far more often than keypoints do, it
// catches a good share of theirs, and it leaves most static keypoints alone.
TEST(DynamicPipeline, GeometryFindsThePeopleWithoutANetwork) {
  const SyntheticScene scene(people_room(60));
  DynamicPipelineRun run(scene, dynamic_mode(DynamicMode::geometry));
  const FateCounts counts = run.run(15);
  EXPECT_EQ(run.estimate().size(), scene.frame_count());
  const int dropped = counts.dropped_on_people + counts.dropped_elsewhere;
  ASSERT_GT(dropped, 0);
  const double people_share = static_cast<double>(counts.on_people) / counts.all;
  const double drops_on_people = static_cast<double>(counts.dropped_on_people) / dropped;
  const std::string seen = std::to_string(counts.dropped_on_people) + " of " +
                           std::to_string(dropped) + " drops on people; " +
                           std::to_string(counts.on_people) + " of " + std::to_string(counts.all) +
                           " keypoints on people, " + std::to_string(counts.kept_on_people) +
                           " of them tracked";
  EXPECT_GT(drops_on_people, 2.0 * people_share) << seen;
  EXPECT_GT(static_cast<double>(counts.dropped_on_people) /
                (counts.dropped_on_people + counts.kept_on_people),
            0.4)
      << seen;
  EXPECT_LT(static_cast<double>(counts.dropped_elsewhere) / (counts.all - counts.on_people), 0.25)
      << seen;
  EXPECT_EQ(counts.semantic, 0);
  EXPECT_LT(compute_ate(scene.ground_truth(), run.estimate()).error.rmse, 0.015);
}

// Masks from files (`run --semantic-masks`) stand in for the network: the people's own masks
// keep every keypoint on them from being extracted, and the fused mask covers them.
TEST(DynamicPipeline, SemanticMasksKeepEveryKeypointOnThePeopleFromTracking) {
  const SyntheticScene scene(people_room(30));
  const std::filesystem::path masks = testing::make_temp_dir("semantic_masks");
  SynthFrame rendered;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    scene.render(i, rendered, 1);
    cv::imwrite((masks / (std::to_string(i) + ".png")).string(),
                cv::Mat(rendered.labels != kSynthLabelStatic));
  }
  DynamicPipelineRun run(scene, dynamic_mode(DynamicMode::semantic, masks));
  const FateCounts counts = run.run(0);
  EXPECT_EQ(run.estimate().size(), scene.frame_count());
  EXPECT_EQ(counts.kept_on_people, 0);
  EXPECT_GT(counts.semantic, 100);
  // Only the mask's dilation margin lies off the people.
  EXPECT_LT(counts.semantic_off_mask, counts.semantic / 2);
  EXPECT_EQ(counts.dropped_on_people + counts.dropped_elsewhere, 0);  // no geometry stage
  scene.render(scene.frame_count() - 1, rendered, 1);
  const cv::Mat fused = run.tracking().last_dynamic_mask();
  ASSERT_FALSE(fused.empty());
  EXPECT_EQ(cv::countNonZero((rendered.labels != kSynthLabelStatic) & (fused == 0)), 0);
  EXPECT_LT(compute_ate(scene.ground_truth(), run.estimate()).error.rmse, 0.015);
}

}  // namespace
}  // namespace pspslam
