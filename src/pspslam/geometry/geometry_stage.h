#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/geometry/ant_colony_search.h"
#include "pspslam/geometry/compensated_homography.h"
#include "pspslam/geometry/multiview_test.h"
#include "pspslam/geometry/reference_selection.h"
#include "pspslam/geometry/region_growing.h"

namespace pspslam {

class YamlSection;

// All parameters of the geometry thread (paper III.B/C). YAML section `geometry:` with the
// sub-sections homography, multiview, search, region; every key is optional.
struct GeometryParams {
  HomographyParams homography;
  MultiViewParams multiview;
  AntColonyParams search;
  RegionGrowParams region;
  // Choice of multiview.max_reference_views references when the input offers more (a keyframe
  // pool): greedy coverage, reference_selection.h. YAML section `references:`.
  struct ReferenceChoice {
    int wanted_coverage = 2;  // a candidate counts as covered once this many picks see it
    int point_stride = 8;     // coverage is estimated on every point_stride-th candidate
    double older_view_gain_share = 1.0;  // see ReferenceSelector::Params
    bool operator==(const ReferenceChoice&) const = default;
  } references;
  // Test the points inside the previous frame's dynamic mask (warped into this frame by the
  // compensated homography) before walking the path.
  bool previous_mask_prior = true;
  // Also return the previous mask warped into this frame (a full-image cv::warpPerspective, a
  // cost per frame). The prior itself needs no image: each keypoint is mapped back through H^-1.
  bool output_warped_previous_mask = false;

  static GeometryParams from_yaml(YamlSection& section);
  bool operator==(const GeometryParams&) const = default;
};

// One frame's input. Spans and cv::Mat headers refer to caller-owned data for the duration of
// GeometryStage::process() only.
struct GeometryFrameInput {
  cv::Mat depth;                               // current depth, CV_32FC1 metres
  Pose T_world_camera = Pose::Identity();      // current pose estimate
  std::span<const Eigen::Vector2d> keypoints;  // candidate pixels (undistorted)
  // Measured depth per keypoint (metres); empty = read from `depth` at the rounded pixel.
  std::span<const float> keypoint_depths;
  // Reference views (keyframes); when there are more than MultiViewParams::max_reference_views,
  // the stage picks that many by coverage of this frame's candidates (reference_selection.h).
  std::span<const DepthView> references;
  // Matches previous -> current for the compensated homography; fewer than 4 skips it.
  std::span<const Eigen::Vector2d> matched_previous;
  std::span<const Eigen::Vector2d> matched_current;
  // A compensated homography previous -> current computed by the caller (System does it in its
  // flow step): used instead of the matches, so the previous mask need not be warped beforehand
  // (each keypoint is mapped back through its inverse).
  std::optional<Eigen::Matrix3d> H_previous_to_current;
  cv::Mat previous_dynamic_mask;  // optional CV_8UC1 (non-zero = dynamic) of the previous frame
};

// Wall-clock and thread-CPU milliseconds of each part. CPU time is what the stage itself costs;
// on a loaded machine wall time also counts waiting for a core.
struct GeometryTiming {
  double homography_ms = 0.0;
  double selection_ms = 0.0;  // choice of the reference views from a larger pool
  double search_ms = 0.0;     // ant-colony (or exhaustive) search including the multi-view tests
  double region_ms = 0.0;
  double total_ms = 0.0;
  double homography_cpu_ms = 0.0;
  double selection_cpu_ms = 0.0;
  double search_cpu_ms = 0.0;
  double region_cpu_ms = 0.0;
  double total_cpu_ms = 0.0;
};

struct GeometryFrameResult {
  cv::Mat dynamic_mask;  // CV_8UC1, 255 = dynamic (grown regions, dilated)
  // Per keypoint: dynamic = found dynamic by the test or inside the grown mask.
  std::vector<std::uint8_t> keypoint_dynamic;
  std::vector<std::uint8_t> keypoint_tested;
  std::vector<std::uint8_t> keypoint_tested_dynamic;
  int tested_count = 0;
  int references_used = 0;
  int tested_dynamic_count = 0;
  int last_band_tests = 0;  // SearchResult::last_band_tests
  int dynamic_count = 0;
  CompensatedHomography homography;  // valid = false when no matches were given
  // Previous mask in the motion-compensated frame (only with output_warped_previous_mask).
  cv::Mat warped_previous_mask;
  GeometryTiming timing;
};

// The per-frame geometry stage: compensated homography (eq. 10-11) -> search (Fig. 6) with the
// multi-view test -> region growing. It owns reusable buffers and no globals: create one per
// worker thread and call process() from that thread only; results are returned by value so they
// can be handed to another thread.
class GeometryStage {
 public:
  GeometryStage(PinholeCamera camera, GeometryParams params);

  GeometryFrameResult process(const GeometryFrameInput& input);

  const GeometryParams& params() const { return params_; }
  // The ant colony's path of the last process() (DynamicPointSearch::last_path).
  std::span<const Eigen::Vector2f> last_search_path() const { return search_.last_path(); }

 private:
  // The homography previous -> current (the caller's, else estimated from the matches) and the
  // warped previous mask when asked for.
  std::optional<Eigen::Matrix3d> compensate_motion(const GeometryFrameInput& input,
                                                   GeometryFrameResult& result);
  static bool has_previous_mask(const GeometryFrameInput& input);
  // points_, candidates_ (depths not read yet) and the priority points inside the previous mask.
  void prepare_candidates(const GeometryFrameInput& input,
                          const std::optional<Eigen::Matrix3d>& previous_to_current);
  // Candidate i's depth, read on first use.
  double depth_of(const GeometryFrameInput& input, size_t i);
  std::span<const DepthView> select_references(const GeometryFrameInput& input);
  void grow_regions(const GeometryFrameInput& input, const SearchResult& search, cv::Mat& mask);
  void mark_dynamic_keypoints(const SearchResult& search, GeometryFrameResult& result) const;

  PinholeCamera camera_;
  GeometryParams params_;
  MultiViewTest test_;
  ReferenceSelector selector_;
  DynamicPointSearch search_;
  DynamicRegionGrower grower_;
  std::vector<Eigen::Vector2f> points_;
  std::vector<CandidatePoint> candidates_;
  std::vector<int> priority_;
  std::vector<int> selected_pool_indices_;
  std::vector<DepthView> selected_references_;  // oldest first
  std::vector<Eigen::Vector2f> seeds_;
  std::vector<float> seed_depths_;
  std::vector<Eigen::Vector2f> static_points_;
};

// Per-frame dynamic mask fusing the semantic thread's mask and the geometry mask: OR of both
// (non-zero = dynamic), dilated by `dilation_px` to cover object borders. Either may be empty.
cv::Mat fuse_dynamic_masks(const cv::Mat& semantic_mask, const cv::Mat& geometry_mask,
                           int dilation_px);

}  // namespace pspslam
