#include "pspslam/system/tracking_module.h"

#include <algorithm>
#include <chrono>
#include <mutex>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/clock.h"
#include "pspslam/core/thread_cpu_time.h"
#include "pspslam/feature/orb_config.h"
#include "pspslam/geometry/geometry_config.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/semantic/segmenter_metadata.h"
#include "pspslam/system/frame_builder.h"

namespace pspslam {
namespace {

// The tracker's settings that follow from the camera: ORB-SLAM2 wants a keyframe at least once
// per second of video, and pose optimisation weighs depth as bundle adjustment does.
TrackerOptions tracker_options(const SystemConfig& config, const SystemOptions& options) {
  TrackerOptions tracker = options.tracker;
  tracker.keyframes.max_frames_between = static_cast<int>(config.camera.fps);
  if (config.camera.depth_noise == CameraConfig::DepthNoise::kinect_v1)
    tracker.pose_optimizer.depth_noise = {.enabled = true,
                                          .scale = config.camera.depth_noise_scale};
  return tracker;
}

std::unique_ptr<DynamicPipeline> make_dynamic_pipeline(const SystemConfig& config,
                                                       const SystemOptions& options, Map& map) {
  if (options.dynamic.mode == DynamicMode::off) return nullptr;
  DynamicOptions dynamic = options.dynamic;
  dynamic.semantic.thread_nice = options.background_thread_nice;
  dynamic.geometry = read_geometry_config(config.geometry);
  return std::make_unique<DynamicPipeline>(dynamic, config.camera.pinhole, map);
}

// People are tracked where each frame's persons are labelled (the network, or mask files) and
// the sensor gives depth.
std::unique_ptr<PeopleTracking> make_people_tracking(const SystemConfig& config,
                                                     const SystemOptions& options) {
  const DynamicOptions& dynamic = options.dynamic;
  if (!uses_semantics(dynamic.mode) || config.camera.type == SensorType::monocular) return nullptr;
  // Masks read from files are taken as label maps with PASCAL VOC's person id, as the masks of
  // `pspslam synth` are (kSynthLabelPerson).
  constexpr int kVocPerson = 15;
  if (!dynamic.semantic_masks.empty())
    return std::make_unique<PeopleTracking>(config.camera.pinhole, kVocPerson);
  const std::vector<std::string> classes = load_segmenter_metadata(dynamic.model).classes;
  const auto person = std::find(classes.begin(), classes.end(), "person");
  if (person == classes.end()) return nullptr;
  return std::make_unique<PeopleTracking>(config.camera.pinhole,
                                          static_cast<int>(person - classes.begin()));
}

cv::Mat grey_image(const InputFrame& frame) {
  if (!frame.gray.empty()) return frame.gray;
  cv::Mat gray;
  cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

}  // namespace

TrackingModule::TrackingModule(const SystemConfig& config, const SystemOptions& options,
                               std::unique_ptr<FrameBuilder> frame_builder, Map& map,
                               KeyFrameSink* keyframe_sink, std::shared_ptr<PlaceRecognition> place,
                               BackEndHooks back_end)
    : map_(map),
      place_(std::move(place)),
      back_end_(std::move(back_end)),
      frame_builder_(std::move(frame_builder)),
      tracker_(map, keyframe_sink, tracker_options(config, options),
               options.place.relocalization ? place_ : nullptr,
               frame_builder_->make_map_initializer(tracker_options(config, options))),
      extractor_(std::make_unique<OrbExtractor>(read_orb_config(config.orb))),
      record_keypoint_fates_(options.record_keypoint_fates),
      dynamic_(make_dynamic_pipeline(config, options, map)),
      people_(make_people_tracking(config, options)) {}

TrackingModule::~TrackingModule() = default;

void TrackingModule::announce(const InputFrame& frame) {
  frame_builder_->prepare(frame);
  if (dynamic_) dynamic_->announce(frame);
}

// The paper's pipeline, in order. Without a dynamic pipeline (DynamicMode::off) steps 1, 2, 4
// and 6 are skipped and the frame is ORB-SLAM2's.
FrameReport TrackingModule::process(const InputFrame& frame) {
  FrameReport report;
  const double cpu_start = thread_cpu_ms();
  const cv::Mat gray = grey_image(frame);
  // 1. Flow and compensated homography to the previous frame (eq. 10-11), then
  // 2. the semantic mask: this frame's own (deterministic) or the newest one brought into it
  // (live). docs/architecture.md numbers the steps as here.
  const cv::Mat semantic_mask =
      dynamic_ ? dynamic_->begin_frame(frame, gray, report.dynamic) : cv::Mat();

  // 3. ORB features, none on the semantic mask.
  const auto extraction_start = std::chrono::steady_clock::now();
  OrbFeatures features;
  frame_builder_->extract(frame, gray, semantic_mask, features);
  const cv::Mat depth = dynamic_ ? frame_builder_->depth_image(frame) : cv::Mat();
  report.extraction_ms = milliseconds_since(extraction_start);

  // 4. The multi-view geometry test drops dynamic keypoints before the Frame exists, so they
  // are neither tracked nor mapped.
  std::vector<KeypointRecord>* fates = record_keypoint_fates_ ? &report.keypoints : nullptr;
  if (dynamic_) {
    reanchor_dynamic_pipeline();
    if (fates && record_masked_fates_) record_fates_before_removal(gray, semantic_mask, *fates);
    dynamic_->remove_dynamic(depth, frame_builder_->keypoint_depths(), semantic_mask, features,
                             report.dynamic, fates);
  }
  const auto build_start = std::chrono::steady_clock::now();
  Frame tracked_frame = frame_builder_->build(next_frame_id_++, frame, std::move(features), depth,
                                              tracker_.angular_velocity());
  report.extraction_ms += milliseconds_since(build_start);
  report.extraction_cpu_ms = thread_cpu_ms() - cpu_start;  // includes flow and geometry

  // 5. Tracking, against a map the back end has caught up with (deterministic runs).
  back_end_.wait_for_back_end();
  const double cpu_tracking_start = thread_cpu_ms();
  const auto tracking_start = std::chrono::steady_clock::now();
  const std::optional<std::uint64_t> judged = judged_through_frame(tracked_frame.id(), report);
  report.tracking = tracker_.track(std::move(tracked_frame), judged);
  if (report.tracking.restart_due) restart_map();
  report.tracking_ms = milliseconds_since(tracking_start);
  report.tracking_cpu_ms = thread_cpu_ms() - cpu_tracking_start;

  // 6. Map points judged dynamic are culled (--cull-evidence: none by default, the same in
  // deterministic and live runs; docs/decisions/map-hygiene.md). The culler and the next frame's
  // geometry stage read points and keyframe poses the back end refines: a deterministic run lets
  // it finish this frame's keyframe first (docs/decisions/back-end-wait.md).
  if (dynamic_) {
    back_end_.wait_for_back_end();
    dynamic_->end_frame(report.tracking, depth, semantic_mask, report.dynamic);
  }
  if (fates) record_fates_of_tracked_frame(*fates);
  // 7. People: this frame's own person labels (a stale mask's are of another frame), its depth
  // and pose give each person's centre; tracks link them over frames.
  if (people_) {
    if (report.tracking.restart_due) people_->reset();
    const bool own_labels = report.dynamic.mask_age_frames == 0;
    report.people =
        people_->process(frame.timestamp, own_labels ? dynamic_->semantic_labels() : cv::Mat(),
                         depth, report.tracking.T_world_camera);
  }
  return report;
}

// The newest frame whose map points an exact semantic mask has judged, while a live run's mask is
// stale (Tracker::track).
std::optional<std::uint64_t> TrackingModule::judged_through_frame(std::uint64_t frame_id,
                                                                  const FrameReport& report) const {
  if (!dynamic_) return std::nullopt;
  const std::optional<int> back = dynamic_->frames_since_judged(report.dynamic);
  if (!back || static_cast<std::uint64_t>(*back) > frame_id) return std::nullopt;
  return frame_id - static_cast<std::uint64_t>(*back);
}

void TrackingModule::reanchor_dynamic_pipeline() {
  std::lock_guard lock(map_.update_mutex());
  if (map_corrections_ == map_corrections_seen_) return;
  map_corrections_seen_ = map_corrections_;
  dynamic_->reanchor_last_pose(tracker_.last_tracked_world_pose());
}

void TrackingModule::on_map_corrected() {
  tracker_.on_map_corrected();
  ++map_corrections_;
}

void TrackingModule::start_in_loaded_map(bool localization_only) {
  tracker_.start_in_loaded_map();
  if (dynamic_ && localization_only) dynamic_->use_loaded_map_only();
}

void TrackingModule::restart_map() {
  // Local mapping may still hold keyframes of the map about to go: let it finish them first.
  back_end_.wait_for_local_mapping();
  std::lock_guard lock(map_.update_mutex());
  if (place_) {
    for (const auto& keyframe : map_.keyframes()) place_->database().erase(keyframe->id());
  }
  map_.clear();
  tracker_.restart();
}

// The semantic mask is the extraction mask, so the features it removes never exist as keypoints.
// To show them, the frame is extracted once more without the mask (into a buffer of its own, so
// the tracked features are untouched) and the keypoints on the mask are recorded.
void TrackingModule::record_fates_before_removal(const cv::Mat& gray, const cv::Mat& semantic_mask,
                                                 std::vector<KeypointRecord>& records) {
  if (semantic_mask.empty()) return;
  extractor_->extract(gray, cv::Mat(), unmasked_features_);
  for (const cv::KeyPoint& keypoint : unmasked_features_.keypoints) {
    const int u = std::clamp(cvRound(keypoint.pt.x), 0, semantic_mask.cols - 1);
    const int v = std::clamp(cvRound(keypoint.pt.y), 0, semantic_mask.rows - 1);
    if (semantic_mask.at<std::uint8_t>(v, u) != 0)
      records.push_back({keypoint.pt, KeypointFate::semantic});
  }
}

// The keypoints that reached tracking: matched to a map point after pose optimisation or not
// (the tracker has already cleared the matches of pose outliers).
void TrackingModule::record_fates_of_tracked_frame(std::vector<KeypointRecord>& records) const {
  const Frame* tracked = tracker_.last_frame();
  if (tracked == nullptr) return;
  const std::vector<cv::KeyPoint>& keypoints = tracked->keypoints();
  for (size_t i = 0; i < keypoints.size(); ++i) {
    records.push_back({keypoints[i].pt,
                       tracked->map_points[i] ? KeypointFate::tracked : KeypointFate::unmatched});
  }
}

}  // namespace pspslam
