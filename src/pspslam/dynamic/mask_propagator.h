#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "pspslam/dynamic/mask_warper.h"

namespace pspslam {

struct MaskPropagationParams {
  // How fast the parts of a person may move beyond what the flow measured (limbs, turns, a
  // change of pace), m/s: the mask grows by this speed times its age, seen at the person's depth.
  double residual_speed_mps = 0.5;
  // Growing a crowd's masks much further leaves too few static keypoints to track.
  int max_growth_px = 12;
  // Around the grown mask, keypoints this many pixels further out are all given the multi-view
  // test while the mask is stale (DynamicOptions::stale_mask_frames).
  int watch_band_px = 24;
  int corners_per_component = 40;
  // Corners are taken this far inside the mask: the semantic margin lies on the background.
  int corner_inset_px = 5;
  int min_tracked_corners = 4;  // fewer: the component moves with the camera homography
  int min_component_area_px = 64;
  size_t frames_kept = 48;  // recent frames' images: the oldest mask that can still be moved
};

struct PropagatedMask {
  cv::Mat mask;   // CV_8UC1 in the current frame, 255 = dynamic; empty when none was given
  cv::Mat watch;  // the mask grown by watch_band_px more (only when asked for and it was moved)
  cv::Mat moved;  // the mask moved but not grown (only when it was moved)
  int age_frames = 0;
  int components = 0;     // connected parts of the mask
  int moved_by_flow = 0;  // of which moved by their own flow (the rest: the homography)
  int growth_px = 0;      // the largest growth radius applied
};

// Brings the newest semantic mask, made for an older frame, into the current frame by the
// people's own motion, as NGD-SLAM keeps tracking the dynamic objects between masks: per
// connected component, corners inside it are followed with pyramidal Lucas-Kanade from the
// mask's frame to the current one and the component moves by their median displacement (camera
// and person motion together). A component without enough tracked corners moves with the
// camera's compensated homography (paper eq. 10-11). Each component then grows by how far a
// person can move, beyond what was measured, in the mask's age. Corners are found once per mask
// and followed frame to frame after that.
class MaskPropagator {
 public:
  // `fx`: focal length in pixels; `frame_period_s`: the camera's frame period.
  MaskPropagator(double fx, double frame_period_s, MaskPropagationParams params = {});

  // Every frame, ids increasing by one: its gray image and depth (CV_32FC1 metres, may be
  // empty). The Mats are shared, not copied: the caller must not write to them afterwards.
  void add_frame(std::int64_t id, const cv::Mat& gray, const cv::Mat& depth);

  // `mask` (CV_8UC1, non-zero = dynamic) of frame `mask_id` in frame `current_id` (both added);
  // `with_watch`: also make PropagatedMask::watch.
  PropagatedMask propagate(const cv::Mat& mask, std::int64_t mask_id, std::int64_t current_id,
                           const HomographyChain& chain, bool with_watch);

 private:
  struct Images {
    std::int64_t id = 0;
    cv::Mat gray;
    cv::Mat depth;
  };
  struct Component {
    cv::Rect box;
    cv::Mat shape;  // CV_8UC1 of box's size, 255 inside the component
    cv::Point2d centroid;
    double depth_m = 0.0;             // median depth inside it; 0: unknown
    std::vector<cv::Point2f> origin;  // corners in the mask's frame
    std::vector<cv::Point2f> now;     // the same corners in frame tracked_to_
    std::vector<std::uint8_t> alive;
  };

  const Images* images(std::int64_t id) const;
  void start(const cv::Mat& mask, std::int64_t mask_id);
  void add_component(const cv::Mat& labels, const cv::Mat& stats, const cv::Mat& centroids,
                     int label, const Images& frame);
  void advance(std::int64_t current_id);
  cv::Point2d displacement(const Component& component, const std::optional<Eigen::Matrix3d>& H,
                           bool& by_flow) const;
  int growth_px(const Component& component, int age_frames) const;
  static void paint_grown(const Component& component, cv::Point offset, int radius, cv::Mat& out);

  double fx_;
  double frame_period_s_;
  MaskPropagationParams params_;
  std::deque<Images> frames_;
  std::vector<Component> components_;
  std::int64_t mask_id_ = -1;     // the mask the components were made of
  std::int64_t tracked_to_ = -1;  // frame the corners' `now` positions are in

  // Reused buffers.
  std::vector<cv::Point2f> from_;
  std::vector<cv::Point2f> to_;
  std::vector<unsigned char> status_;
  std::vector<float> error_;
};

}  // namespace pspslam
