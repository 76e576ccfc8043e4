#pragma once

#include <Eigen/Core>
#include <memory>
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

// Parameters of the multi-view dynamic test (paper III.C, after DynaSLAM). Defaults: measured,
// docs/geometry.md.
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
// allocation-free. It fills a per-reference cache lazily (block depth bounds, see below), so it
// is not const: use one MultiViewTest per worker thread.
class MultiViewTest {
 public:
  MultiViewTest(PinholeCamera camera, MultiViewParams params);

  // References beyond params.max_reference_views are ignored (the first ones are kept). The
  // depth images are referenced, not copied: they must outlive the calls to evaluate(), and must
  // not be written to while a reference with the same buffer is in use (block bounds are cached
  // by buffer address across frames, as keyframes stay references for many frames).
  void set_frame(const Pose& T_world_current, std::span<const DepthView> references);

  // References are tried in the order given; with a vote fraction one vote reaches, the first
  // dynamic vote ends the test (the verdict does not depend on the order).
  MultiViewVerdict evaluate(const CandidatePoint& point);
  bool is_dynamic(const CandidatePoint& point) { return evaluate(point).dynamic; }

  const MultiViewParams& params() const { return params_; }

 private:
  // Depth bounds over the valid pixels of one kBlock x kBlock block of a reference depth image
  // (min > max: no valid pixel; NaN min: not computed yet).
  struct BlockBounds {
    float min;
    float max;
  };
  // Per reference depth image, computed block by block when a test first needs a block: when
  // every valid pixel of the blocks around a projection lies outside the agreement interval, so
  // does every valid pixel of the patch, and a dynamic vote costs a few reads of this small table
  // instead of the (2r+1)^2 patch pixels spread over 2r+1 cache lines of the depth image.
  struct CachedBounds {
    cv::Mat depth;  // shallow: keeps the buffer (whose address is the key) alive
    int block_cols = 0;
    std::vector<BlockBounds> blocks;
    bool used = false;
  };
  struct Reference {
    Eigen::Matrix3d R_ref_current;
    Eigen::Vector3d t_ref_current;
    Eigen::Vector3d center_in_current;  // reference camera centre in current-camera coordinates
    cv::Mat depth;                      // shallow header
    CachedBounds* bounds = nullptr;     // entry of bounds_cache_, stable until the next frame
  };
  CachedBounds& bounds_for(const cv::Mat& depth);
  const BlockBounds& block(CachedBounds& bounds, int block_x, int block_y);

  PinholeCamera camera_;
  MultiViewParams params_;
  double cos_max_parallax_ = 0.0;
  std::vector<Reference> references_;
  std::vector<std::unique_ptr<CachedBounds>> bounds_cache_;
};

}  // namespace pspslam
