#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/dynamic/dynamic_mode.h"
#include "pspslam/dynamic/dynamic_point_culler.h"
#include "pspslam/dynamic/frame_flow.h"
#include "pspslam/dynamic/late_mask_frames.h"
#include "pspslam/dynamic/map_reference_views.h"
#include "pspslam/dynamic/mask_propagator.h"
#include "pspslam/dynamic/mask_warper.h"
#include "pspslam/feature/orb_extractor.h"
#include "pspslam/geometry/geometry_stage.h"
#include "pspslam/semantic/semantic_params.h"
#include "pspslam/tracking/tracker.h"

namespace pspslam {

class KeyFrame;
class Map;
class SemanticThread;
struct SemanticResult;
struct InputFrame;

// How a live run brings an older mask into the current frame.
enum class StaleMaskPolicy : std::uint8_t {
  homography,  // with the camera's frame-to-frame homographies only
  flow,        // with the people's own flow, grown with the mask's age (MaskPropagator)
};

// How dynamic content is detected and removed (`pspslam run --dynamic`).
struct DynamicOptions {
  DynamicMode mode = DynamicMode::off;
  // Segmenter metadata YAML (semantic, full, exhaustive); must exist for those modes.
  std::filesystem::path model;
  // Non-empty: the semantic masks are read from this folder instead of running the network
  // (`run --semantic-masks`): per frame the 8-bit PNG named per_frame_png_name (io/), non-zero =
  // dynamic, grown by semantic.mask_dilation_px. Masks made elsewhere (a larger segmenter run
  // offline, a sequence's ground truth, an earlier run's --save-masks) then stand in for step 2.
  std::filesystem::path semantic_masks;
  // true: never wait for segmentation, use the newest mask warped into the frame (live camera).
  // false: wait for each frame's own mask (reproducible accuracy runs).
  bool realtime = false;
  // mask_dilation_px is the semantic margin; queue_size is set by the pipeline from `realtime`.
  SemanticParams semantic;
  // The config's `geometry:` section (System copies it here); search.strategy is set from the
  // mode (full: ant colony, exhaustive: every point).
  GeometryParams geometry;
  DynamicCullingParams culling;
  // Segment every n-th frame (1: all); the others use the newest mask warped by the frames'
  // homographies. Frees the network's core for local mapping in real-time runs.
  int segment_every = 1;
  // Deterministic mode gives up on a frame's mask after this long (then runs without it).
  std::chrono::milliseconds semantic_timeout{30000};

  // Live runs only (realtime); a deterministic run never changes its network, stride or masks.
  // The semantic thread keeps pace (SemanticPace): it steps down to `smaller_model` (when
  // given), then to every 2nd .. pace_max_stride-th frame, and back up when there is room.
  // Off by default: not yet shown to keep more frames posed than one network on every frame.
  bool keep_pace = false;
  std::filesystem::path smaller_model;
  int pace_max_stride = 3;
  double frame_period_ms = 1000.0 / 30.0;  // the camera's (the runner sets it from the config)
  // Homography by default: masks grown for their age can leave a crowd too few static
  // keypoints to track.
  StaleMaskPolicy stale_masks = StaleMaskPolicy::homography;
  MaskPropagationParams propagation;
  // A mask more than this many frames old is stale: the geometry stage then tests every
  // keypoint near it (MaskPropagationParams::watch_band_px), and the summary counts the frame.
  int stale_mask_frames = 2;
  // While the mask is stale, the geometry stage's prior is the band around the moved mask
  // instead of the previous frame's fused mask. Not the fused mask as well: it holds last
  // frame's grown mask and regions, and a prior that includes its own growth widens each frame.
  bool tighten_geometry = true;
  // A live run's mask arrives frames after the frame it was made for, and is exact for that
  // frame alone. Culling (DynamicPointCuller) then trusts exact masks only: the late mask judges
  // its own frame, at that frame's pose and depth, so points a stale mask let onto the people
  // leave the map; a stale mask, which lies where the people were, culls nothing (it would cull
  // the static points they uncovered since), and the frame's geometry verdicts still count.
  bool cull_with_late_masks = true;
};

// What became of one extracted keypoint (pictures of a run: `pspslam run --save-overlays`).
enum class KeypointFate : std::uint8_t {
  tracked,    // kept and matched to a map point after pose optimisation
  unmatched,  // kept, but no map point matched it (or its match was a pose outlier)
  semantic,   // on the semantic mask: the extractor never returns it (see DynamicPipeline)
  geometry,   // dropped by the geometry stage (multi-view test or grown region)
};
const char* to_string(KeypointFate fate);

struct KeypointRecord {
  cv::Point2f position;  // distorted image coordinates, as extracted
  KeypointFate fate = KeypointFate::unmatched;
};

// What the geometry stage looked at in one frame, for pictures (the live viewer); filled only
// when keypoint fates are recorded. Positions are distorted image pixels.
struct GeometryPicture {
  struct TestedPoint {
    cv::Point2f position;
    bool dynamic = false;  // the multi-view test said dynamic
  };
  cv::Mat regions;  // grown dynamic regions (CV_8UC1, 255 = dynamic); empty: stage did not run
  std::vector<TestedPoint> tested;
  std::vector<cv::Point2f> path;  // the ant colony's path, in walking order (empty: exhaustive)
};

// What the dynamic-scene stages did for one frame (all zero / -1 with DynamicMode::off).
struct DynamicReport {
  double flow_ms = 0.0;              // LK matches + compensated homography (eq. 10-11)
  double semantic_wait_ms = 0.0;     // time tracking blocked waiting for the mask
  double semantic_inference_ms = 0;  // inference time of the mask used (0: none used)
  double geometry_ms = 0.0;          // multi-view test + search + region growing
  double geometry_search_ms = 0.0;   // of which: the (ant-colony or exhaustive) search
  int mask_age_frames = -1;          // current frame - the mask's frame; -1: no mask
  double mask_latency_ms = 0.0;      // from submitting the mask's frame until its use here
  bool mask_warped = false;
  bool geometry_ran = false;  // false without a pose prior or reference keyframes
  int tested_points = 0;      // multi-view tests run
  int dynamic_points = 0;     // keypoints geometry flagged (tested or in grown regions)
  int masked_keypoints = 0;   // extracted keypoints dropped as dynamic before tracking
  int culled_map_points = 0;  // map points erased for lying on dynamic pixels
  // Live runs: an earlier frame judged by its own mask, which arrived now (cull_with_late_masks),
  // and the map points that culled (a part of culled_map_points).
  bool late_frame_judged = false;
  int culled_by_late_mask = 0;
  // Live runs with a pace: the level the mask used was made at, and the thread's level now
  // (-1: no pace or no mask).
  int semantic_level = -1;
  int semantic_pace_level = -1;
  bool mask_moved_by_flow = false;  // at least one part of the mask moved by its own flow
  int mask_growth_px = 0;           // growth of the moved mask for its age
  bool geometry_tightened = false;  // every keypoint near a stale mask got the multi-view test
};

// The dynamic-scene stages around tracking (paper Fig. 1) and their state between frames:
// steps 1, 2, 4 and 6 of the thread layout in system/system.cpp. Owns the semantic thread;
// everything else runs on the caller's thread. System drives it per frame:
//   begin_frame -> (ORB extraction with the returned mask) -> remove_dynamic -> (tracking)
//   -> end_frame.
class DynamicPipeline {
 public:
  // `map` must outlive the pipeline. Loads the segmentation model for the semantic modes
  // (throws pspslam::Error naming the file when it cannot).
  DynamicPipeline(const DynamicOptions& options, const PinholeCamera& camera, Map& map);
  ~DynamicPipeline();
  DynamicPipeline(const DynamicPipeline&) = delete;
  DynamicPipeline& operator=(const DynamicPipeline&) = delete;

  // Hands a frame to the semantic thread ahead of begin_frame (see System::announce).
  void announce(const InputFrame& frame);

  // Steps 1-2: homography to the previous frame, then the semantic mask of this frame (empty
  // when none is usable). With DynamicOptions::semantic_masks, the mask is read from there;
  // throws pspslam::Error naming the file when it is missing or not the frame's size.
  cv::Mat begin_frame(const InputFrame& frame, const cv::Mat& gray, DynamicReport& report);

  // Live runs culling with late masks, on a stale mask: how many frames back the newest frame an
  // exact mask has judged is (its map points and older ones were culled where it saw people,
  // newer ones not yet). Nothing when the mask is fresh or absent.
  std::optional<int> frames_since_judged(const DynamicReport& report) const;

  // Step 4: geometry verdicts fused with the semantic mask; dynamic keypoints are removed.
  // `keypoint_depths`: each keypoint's own depth measurement (FrameBuilder::keypoint_depths;
  // empty: the geometry stage reads `depth` at the keypoint's pixel). `dropped` (null unless
  // pictures are asked for) receives each removed keypoint with the verdict that removed it.
  void remove_dynamic(const cv::Mat& depth, std::span<const float> keypoint_depths,
                      const cv::Mat& semantic_mask, OrbFeatures& features, DynamicReport& report,
                      std::vector<KeypointRecord>* dropped = nullptr);

  // Localisation: the loaded map must stay as it was saved, so no map point is
  // culled, and the geometry stage takes its reference views from the map's keyframes since
  // the run inserts none. Call after the map is loaded.
  void use_loaded_map_only();

  // The map was corrected under the last tracked pose (loop closing): take the corrected one.
  void reanchor_last_pose(const std::optional<Pose>& T_world_camera);

  // The fused semantic + geometry mask of the frame end_frame() finished last.
  const cv::Mat& fused_mask() const { return previous_mask_; }
  // Class labels (CV_8UC1) of the segmentation whose mask the last begin_frame() used (with
  // DynamicOptions::semantic_masks: the mask file as read); empty without one. In --realtime runs
  // they may be of an earlier frame (the mask was warped, the labels are not). Shared with the
  // semantic thread's result, not copied.
  const cv::Mat& semantic_labels() const { return labels_; }

  // The geometry stage's tested points, path and grown regions of the last remove_dynamic()
  // that was given `dropped`; empty otherwise.
  const GeometryPicture& geometry_picture() const { return picture_; }

  // Step 6 and the state for the next frame.
  void end_frame(const TrackResult& result, const cv::Mat& depth, const cv::Mat& semantic_mask,
                 DynamicReport& report);

 private:
  struct Reference {
    std::weak_ptr<KeyFrame> keyframe;  // its pose is read at use: local BA keeps refining it
    cv::Mat depth;
  };
  struct Submitted {
    std::int64_t id = 0;
    Timestamp timestamp = 0.0;
    std::chrono::steady_clock::time_point time;
  };

  cv::Mat mask_from_file(const InputFrame& frame, DynamicReport& report);
  cv::Mat semantic_mask(DynamicReport& report);
  // A live run's older mask moved into the current frame (StaleMaskPolicy::flow).
  cv::Mat propagate_mask(const SemanticResult& result, DynamicReport& report);
  // Culls the map points a late mask's own frame saw on its people (cull_with_late_masks).
  void judge_late_frame(const SemanticResult& result, DynamicReport& report);
  void remember_segmented_frame(const TrackResult& result, const cv::Mat& depth,
                                const DynamicReport& report);
  bool judged_by_late_masks_only(const DynamicReport& report) const;
  cv::Mat culling_mask(const DynamicReport& report) const;
  int cull_frame(const Pose& T_world_camera, const cv::Mat& depth, const DynamicReport& report);
  int cull(const Pose& T_world_camera, const cv::Mat& mask, const cv::Mat& depth);
  void collect_reference_views();
  std::optional<Pose> prior_pose() const;

  // Reference pool = this many times the multi-view test's views (12-15 keyframe depths, ~1 MB
  // each; docs/geometry.md measured the recall gain with a pool of 20 frames).
  static constexpr size_t kReferencePoolFactor = 3;

  DynamicOptions options_;
  PinholeCamera camera_;
  Map& map_;
  std::unique_ptr<SemanticThread> semantic_;
  std::optional<MaskPropagator> propagator_;  // live runs with StaleMaskPolicy::flow
  std::unique_ptr<GeometryStage> geometry_;
  FrameFlow flow_;
  HomographyChain chain_;
  DynamicPointCuller culler_;

  std::int64_t next_id_ = 0;          // processed frames
  std::int64_t next_announced_ = 0;   // frames handed to the semantic thread
  std::int64_t last_segmented_ = -1;  // the last frame handed to it to segment
  std::int64_t current_id_ = 0;
  std::deque<Submitted> submitted_;
  LateMaskFrames late_mask_frames_;   // live runs: segmented frames awaiting their masks
  std::deque<Reference> references_;  // newest keyframe first
  std::optional<MapReferenceViews> map_references_;  // localisation only
  bool protect_map_ = false;                         // localisation: never erase map points
  std::optional<Eigen::Matrix3d> H_previous_to_current_;
  cv::Mat previous_gray_;
  cv::Mat previous_mask_;  // fused semantic + geometry mask of the previous frame
  cv::Mat geometry_mask_;
  cv::Mat watch_mask_;  // around a stale mask, for the geometry stage; empty otherwise
  cv::Mat cull_mask_;   // a moved mask before its growth; empty: cull on the fused mask
  cv::Mat labels_;      // of the mask used for the current frame
  GeometryPicture picture_;
  std::optional<Pose> last_pose_;
  std::optional<Pose> velocity_;
  std::int64_t last_pose_id_ = -1;

  // Per-frame buffers, reused.
  std::vector<cv::Point2f> previous_points_;
  std::vector<Eigen::Vector2d> pixels_;
  std::vector<DepthView> views_;
  std::vector<std::uint8_t> geometry_flags_;
  std::vector<std::uint8_t> dynamic_flags_;
};

}  // namespace pspslam
