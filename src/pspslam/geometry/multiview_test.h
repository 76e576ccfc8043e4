#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"

namespace pspslam {

class YamlSection;

// Which depth disagreement counts as evidence of motion (see docs/geometry.md for the sweep).
enum class DepthDisagreement {
  // The reference sees *farther* than where the point is now: the point was not there when the
  // reference was taken. A static point occluded in the reference by something in front never
  // triggers this, which is why it is the default.
  farther_only,
  // |measured - projected| in either direction (DynaSLAM's symmetric form).
  either_sign,
};

// Parameters of the multi-view dynamic test (paper III.C, after DynaSLAM). Defaults: chosen by
// experiment (docs/decisions/geometry-parameters.md).
struct MultiViewParams {
  // A reference votes "dynamic" when the disagreement exceeds abs + relative * projected depth.
  double depth_threshold_abs_m = 0.04;
  double depth_threshold_relative = 0.04;
  DepthDisagreement disagreement = DepthDisagreement::farther_only;
  // References whose viewing ray differs from the current one by more than this are skipped:
  // at wide parallax occlusions make depth comparisons meaningless.
  double max_parallax_deg = 30.0;
  // Half-size of the reference depth patch: the reference votes dynamic only if *every* valid
  // pixel of the (2r+1)^2 patch disagrees, which absorbs depth edges and small pose errors.
  int reference_patch_radius = 4;
  // Fraction of the valid references that must vote dynamic; 0.2 = "any one" for up to 5
  // references (a person that stood still in some references is still caught).
  double min_dynamic_vote_fraction = 0.2;
  int max_reference_views = 5;
  double min_depth_m = 0.1;
  double max_depth_m = 8.0;

  static MultiViewParams from_yaml(YamlSection& section);
  bool operator==(const MultiViewParams&) const = default;
};

// A reference view: keyframe pose and its depth image (CV_32FC1 metres, 0 = no reading).
struct DepthView {
  Pose T_world_camera = Pose::Identity();
  cv::Mat depth;
};

// A candidate point of the current frame with its measured depth (metres).
struct CandidatePoint {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double depth = 0.0;
};

struct MultiViewVerdict {
  int valid_references = 0;  // references where the point projected, in range, small parallax
  int dynamic_votes = 0;
  bool dynamic = false;
};

// The test itself. set_frame() precomputes the relative poses once per frame; evaluate() is then
// allocation-free and const, so one worker thread can call it for thousands of points.
class MultiViewTest {
 public:
  MultiViewTest(PinholeCamera camera, MultiViewParams params);

  // References beyond params.max_reference_views are ignored (the first ones are kept). The
  // depth images are referenced, not copied: they must outlive the calls to evaluate().
  void set_frame(const Pose& T_world_current, std::span<const DepthView> references);

  // References are tried in the order given; with a vote fraction one vote reaches, the first
  // dynamic vote ends the test (the verdict does not depend on the order).
  MultiViewVerdict evaluate(const CandidatePoint& point) const;
  bool is_dynamic(const CandidatePoint& point) const { return evaluate(point).dynamic; }

  const MultiViewParams& params() const { return params_; }

 private:
  struct Reference {
    Eigen::Matrix3d R_ref_current;
    Eigen::Vector3d t_ref_current;
    Eigen::Vector3d center_in_current;  // reference camera centre in current-camera coordinates
    cv::Mat depth;                      // shallow header
  };

  PinholeCamera camera_;
  MultiViewParams params_;
  double cos_max_parallax_ = 0.0;
  std::vector<Reference> references_;
};

}  // namespace pspslam
