#pragma once

#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

class MapPoint;

// What counts as one frame's evidence that a map point is on something that moves
// (docs/decisions/map-hygiene.md).
enum class CullingEvidence : std::uint8_t {
  // Nothing: no map point leaves the map for being dynamic. Features on dynamic pixels never
  // make points, and a point that stops being matched leaves by local mapping's own culling.
  none,
  // The point projects onto the frame's dynamic mask and the measured depth there agrees with
  // its own: it lies on the detected mover. A mask that spills over the background (its margin,
  // or a network's imprecision) makes static points behind a person count too.
  dynamic_pixels,
  // The point itself has moved: the frame sees through the place the map has it (the measured
  // depth at its pixel and around it lies well behind it), so that space is empty now. A static
  // point is never seen through, whatever mask covers it; a point made on a person is, once she
  // moves on. No mask is needed, so live and deterministic runs cull alike.
  seen_through,
};

// "off", "mask" or "seen-through"; throws pspslam::Error naming `setting` and the accepted values.
CullingEvidence parse_culling_evidence(const std::string& text, const std::string& setting);

// Where a point of the camera frame appears in the image as recorded (the distorted pixel, where
// the camera's own depth image holds it); PinholeCamera::project gives the ideal pinhole's.
Eigen::Vector2d project_distorted(const PinholeCamera& camera, const Eigen::Vector3d& point);

struct DynamicCullingParams {
  CullingEvidence evidence = CullingEvidence::none;
  // A map point is culled once this many frames gave evidence against it (seen_through: net of
  // the frames that measured it where the map has it).
  int min_dynamic_hits = 3;
  // Depth agreement: |measured - predicted| <= abs + relative * measured.
  double depth_tolerance_abs_m = 0.05;
  double depth_tolerance_relative = 0.03;
  // seen_through: the measured depth must lie behind the point by more than abs + relative *
  // measured, at its pixel and at the four pixels this far from it. A point on a depth edge is
  // then not seen through for a small reprojection error, nor for depth taken a few
  // milliseconds off colour while the camera turns (a Kinect's depth and colour are not
  // synchronised): both shift the background under it by pixels, not by the radius.
  double seen_through_margin_abs_m = 0.10;
  double seen_through_margin_relative = 0.05;
  int seen_through_radius_px = 4;
  // seen_through: a frame that sees through more than this share of the points it measures
  // (at least min_points_measured of them) most likely has a wrong pose, not a moved scene: it
  // counts nothing.
  double max_seen_through_share = 0.25;
  int min_points_measured = 20;
};

// Counts, per map point, the frames that gave evidence it is on something that moves, and
// reports the points that reached the threshold (points created on a person before she was
// detected -- e.g. she stood still, or the mask missed her edge -- must leave the map once she
// moves). Not thread-safe: used by the tracking thread only. Buffers are reused.
class DynamicPointCuller {
 public:
  explicit DynamicPointCuller(DynamicCullingParams params = {}) : params_(params) {}

  // `points`: map points to check (e.g. the tracker's local map); `dynamic_mask` CV_8UC1 (only
  // read by dynamic_pixels) and `depth` CV_32FC1 metres of the current frame with pose
  // `T_world_camera`. Returns the points that reached the threshold (they are forgotten here;
  // the caller erases them from the Map).
  const std::vector<std::shared_ptr<MapPoint>>& observe(
      std::span<const std::shared_ptr<MapPoint>> points, const Pose& T_world_camera,
      const cv::Mat& dynamic_mask, const cv::Mat& depth, const PinholeCamera& camera);

  const DynamicCullingParams& params() const { return params_; }

 private:
  enum class Verdict : std::uint8_t { none, against, confirmed };
  struct Projection {
    int u = 0, v = 0;
    double z = 0.0;
  };

  std::optional<Projection> project(const MapPoint& point, const Pose& T_camera_world,
                                    const PinholeCamera& camera, const cv::Mat& image) const;
  Verdict on_dynamic_pixels(const Projection& p, const cv::Mat& mask, const cv::Mat& depth) const;
  Verdict seen_through(const Projection& p, const cv::Mat& depth) const;
  void count_against(const std::shared_ptr<MapPoint>& point);

  DynamicCullingParams params_;
  std::unordered_map<std::uint64_t, int> hits_;
  std::vector<std::pair<std::shared_ptr<MapPoint>, Verdict>> verdicts_;
  std::vector<std::shared_ptr<MapPoint>> to_cull_;
};

}  // namespace pspslam
