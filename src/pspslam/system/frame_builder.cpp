#include "pspslam/system/frame_builder.h"

#include <algorithm>
#include <array>
#include <future>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"
#include "pspslam/match/stereo_matcher.h"

namespace pspslam {
namespace {

bool same_keypoint(const cv::KeyPoint& a, const cv::KeyPoint& b) {
  return a.pt == b.pt && a.octave == b.octave && a.angle == b.angle;
}

class RgbdFrameBuilder final : public FrameBuilder {
 public:
  RgbdFrameBuilder(const OrbConfig& orb, std::shared_ptr<const CameraModel> camera,
                   std::shared_ptr<const ScalePyramid> pyramid)
      : extractor_(orb), camera_(std::move(camera)), pyramid_(std::move(pyramid)) {}

  void extract(const InputFrame&, const cv::Mat& gray, const cv::Mat& mask,
               OrbFeatures& features) override {
    extractor_.extract(gray, mask, features);
  }

  cv::Mat depth_image(const InputFrame& frame) override { return frame.depth; }

  Frame build(std::uint64_t id, const InputFrame& frame, OrbFeatures&& features, const cv::Mat&,
              const Eigen::Vector3d& angular_velocity) override {
    return Frame(id, frame.timestamp, std::move(features.keypoints),
                 std::move(features.descriptors), frame.depth, camera_, pyramid_, angular_velocity);
  }

 private:
  OrbExtractor extractor_;
  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
};

// A rectified pair: both images are extracted at once (two threads), and each left keypoint's
// depth comes from its partner on the same rows of the right image (match/stereo_matcher.h).
//
// The semantic mask is computed once per pair, on the left image, and masks the left extraction
// only. The right image is not masked: its keypoints serve only as partners of left keypoints,
// which the mask has already filtered, so a person in the right image can only be picked for a
// static left keypoint it hides, and such a pair fails the descriptor threshold, the row band,
// the SAD test or its median check (different surfaces). Segmenting the right image too would
// double the PSPNet's cost, and warping the left mask needs the disparity of the masked pixels,
// which exists only after matching; an unmasked right extraction also needs no mask to start.
//
// The dynamic pipeline needs a dense depth image (see depth_image()); sparse keypoint depths do
// not serve it, since the geometry stage reads depth patches around *projected* pixels of its
// reference views and the culler reads depth where map points project. It is computed by block
// matching (cv::StereoBM) only when a dynamic pipeline asks for it; tracking uses the sparse,
// sub-pixel keypoint depths, which are more accurate than a dense matcher's 1/16 px steps
// averaged over a block. So does the geometry stage for its candidates (keypoint_depths()):
// keypoints are corners, often on a depth edge, where block matching lends the nearer surface's
// disparity to the farther one's pixels; a background keypoint read from the dense image then
// lies in front of what its reference keyframes saw there, which the multi-view test takes for
// motion. Read from the dense image, such depths fill the geometry mask with static pixels;
// the keypoints' own depths keep it on what moves.
class StereoFrameBuilder final : public FrameBuilder {
 public:
  // Twice the left image's features on the right: the quadtree keeps a different subset of
  // corners in each image, so a left keypoint's partner is often not among the right image's
  // best n; doubling raises the matched share of a rendered pair (tests/match,
  // RenderedPairDisparityWithinAQuarterPixel), and the right image runs on the second thread.
  static OrbConfig right_config(OrbConfig orb) {
    orb.n_features *= 2;
    return orb;
  }

  StereoFrameBuilder(const OrbConfig& orb, std::shared_ptr<const CameraModel> camera,
                     std::shared_ptr<const ScalePyramid> pyramid, bool dense_depth)
      : left_extractor_(orb),
        camera_(std::move(camera)),
        pyramid_(std::move(pyramid)),
        dense_depth_(dense_depth) {
    // Block matching at half resolution: the cost grows with width x height x disparities, and
    // the dynamic pipeline's depth tests tolerate 4 cm + 4 % (geometry/). Semi-global matching
    // (cv::StereoSGBM, 3-way, 5x5 blocks) costs several times as much a pair, and with the
    // candidates on their own depths it is also the less accurate of the two on synthetic
    // stereo sequences (lower ATE with StereoBM on most seeds). Disparities up to the nearest
    // depth matched sparsely, rounded up to a multiple of 16, capped at 96 (nearer pixels get no
    // depth); 11x11 blocks.
    const double max_disparity = 0.5 * camera_->bf / matching_.min_depth_m;
    const int disparities =
        std::clamp(static_cast<int>(std::ceil(max_disparity / 16.0)) * 16, 16, 96);
    for (auto& work : images_) work = std::make_unique<ImageWork>(right_config(orb), disparities);
    block_matcher_for_calls_ = cv::StereoBM::create(disparities, 11);
  }

  // The right image's features and the dense depth need only the frame's two images, not the
  // mask or the map: a deterministic run starts them when the frame is announced, one frame
  // ahead, so they run while the frame before is tracked and its keyframe refined (time in
  // which the caller thread only waits) instead of on the frame's own path.
  void prepare(const InputFrame& frame) override {
    if (frame.right.empty() || frame.right.size() != left_size(frame)) return;  // extract() says
    ImageWork& work = *images_[next_work_];
    next_work_ = 1 - next_work_;
    start(work, frame);
  }

  void extract(const InputFrame& frame, const cv::Mat& gray, const cv::Mat& mask,
               OrbFeatures& features) override {
    check_pair(frame);
    current_ = find(frame);
    if (current_ == nullptr) {  // not announced (live runs): start it now, beside the left image
      current_ = images_[next_work_].get();
      next_work_ = 1 - next_work_;
      start(*current_, frame, gray);
    }
    left_extractor_.extract(gray, mask, features);
    current_->right_done.get();
    // Matched once, before dynamic removal, so the geometry stage can use the depths too.
    match_stereo(features.keypoints, features.descriptors, current_->right.keypoints,
                 current_->right.descriptors, gray, frame.right, *pyramid_, camera_->bf, matching_,
                 depths_);
    extracted_ = features.keypoints;
  }

  cv::Mat depth_image(const InputFrame& frame) override {
    if (current_ != nullptr && current_->dense_done.valid() && current_->index == frame.index)
      return current_->dense_done.get();
    cv::Mat gray = frame.gray;
    if (gray.empty()) cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    return dense_depth(block_matcher_for_calls_, gray, frame.right);
  }

  std::span<const float> keypoint_depths() const override { return depths_.depth; }

  Frame build(std::uint64_t id, const InputFrame& frame, OrbFeatures&& features, const cv::Mat&,
              const Eigen::Vector3d& angular_velocity) override {
    // The kept keypoints are an order-preserving subset of the extracted ones (dynamic removal
    // compacts in place): walk both lists to carry each kept keypoint's match over.
    std::vector<float> depth(features.keypoints.size());
    std::vector<float> right_u(features.keypoints.size());
    size_t source = 0;
    for (size_t i = 0; i < features.keypoints.size(); ++i) {
      const cv::KeyPoint& kept = features.keypoints[i];
      while (source < extracted_.size() && !same_keypoint(extracted_[source], kept)) ++source;
      if (source == extracted_.size()) {
        throw Error("stereo camera: frame " + frame.name +
                    " was built from keypoints that were not extracted from it");
      }
      depth[i] = depths_.depth[source];
      right_u[i] = depths_.right_u[source];
      ++source;
    }
    return Frame(id, frame.timestamp, std::move(features.keypoints),
                 std::move(features.descriptors), std::move(depth), std::move(right_u), camera_,
                 pyramid_, angular_velocity);
  }

 private:
  // One frame's image-only work (see prepare()). Two, used in turn: the next frame's runs while
  // the current frame's results are read. Each has its own extractor and block matcher, which
  // keep scratch buffers and so serve one thread at a time.
  struct ImageWork {
    ImageWork(const OrbConfig& orb, int disparities)
        : extractor(orb), block_matcher(cv::StereoBM::create(disparities, 11)) {}
    size_t index = 0;
    Timestamp timestamp = 0.0;
    OrbExtractor extractor;
    cv::Ptr<cv::StereoBM> block_matcher;
    OrbFeatures right;
    std::future<void> right_done;
    std::future<cv::Mat> dense_done;  // invalid when no dense depth is wanted
  };

  static cv::Size left_size(const InputFrame& frame) {
    return frame.gray.empty() ? frame.bgr.size() : frame.gray.size();
  }

  static void check_pair(const InputFrame& frame) {
    if (frame.right.empty()) {
      throw Error("stereo camera: frame " + frame.name + " has no right image");
    }
    const cv::Size left = left_size(frame);
    if (frame.right.size() != left) {
      throw Error("stereo camera: the right image of " + frame.name + " is " +
                  std::to_string(frame.right.cols) + "x" + std::to_string(frame.right.rows) +
                  " but the left is " + std::to_string(left.width) + "x" +
                  std::to_string(left.height));
    }
  }

  // `gray`: the left image in grey when the caller has it; otherwise the task converts it.
  void start(ImageWork& work, const InputFrame& frame, cv::Mat gray = cv::Mat()) {
    if (gray.empty()) gray = frame.gray;
    // The slot's previous frame may have been announced and never processed (end of the run).
    if (work.right_done.valid()) work.right_done.wait();
    if (work.dense_done.valid()) work.dense_done.wait();
    work.index = frame.index;
    work.timestamp = frame.timestamp;
    work.right_done = std::async(std::launch::async, [&work, right = frame.right] {
      work.extractor.extract(right, cv::Mat(), work.right);
    });
    if (dense_depth_) {
      work.dense_done =
          std::async(std::launch::async, [this, &work, gray, bgr = frame.bgr, right = frame.right] {
            cv::Mat left = gray;
            if (left.empty()) cv::cvtColor(bgr, left, cv::COLOR_BGR2GRAY);
            return dense_depth(work.block_matcher, left, right);
          });
    }
  }

  ImageWork* find(const InputFrame& frame) {
    for (const auto& work : images_) {
      if (work->right_done.valid() && work->index == frame.index &&
          work->timestamp == frame.timestamp)
        return work.get();
    }
    return nullptr;
  }

  OrbExtractor left_extractor_;
  StereoDepths depths_;                  // per extracted left keypoint
  std::vector<cv::KeyPoint> extracted_;  // the left keypoints depths_ belongs to
  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
  // CV_32F metres at full resolution from block matching at half resolution (nearest-neighbour
  // upsampling: interpolating across a depth edge would invent depths between the two surfaces).
  cv::Mat dense_depth(const cv::Ptr<cv::StereoBM>& block_matcher, const cv::Mat& left,
                      const cv::Mat& right) const {
    cv::Mat left_half, right_half, disparity;
    cv::resize(left, left_half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    cv::resize(right, right_half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    // CV_16S, 16 x half-resolution disparity; no match: negative.
    block_matcher->compute(left_half, right_half, disparity);
    cv::Mat depth_half(disparity.size(), CV_32F);
    // z = bf / d_full = bf / (2 d_half) = bf * 16 / (2 * value).
    const float bf8 = static_cast<float>(camera_->bf * 8.0);
    for (int y = 0; y < disparity.rows; ++y) {
      const std::int16_t* d = disparity.ptr<std::int16_t>(y);
      float* z = depth_half.ptr<float>(y);
      for (int x = 0; x < disparity.cols; ++x) z[x] = d[x] > 0 ? bf8 / d[x] : 0.0f;
    }
    cv::Mat depth;
    cv::resize(depth_half, depth, left.size(), 0.0, 0.0, cv::INTER_NEAREST);
    return depth;
  }

  StereoMatchOptions matching_;
  bool dense_depth_ = false;
  std::array<std::unique_ptr<ImageWork>, 2> images_;
  int next_work_ = 0;
  ImageWork* current_ = nullptr;  // the work of the frame being built
  // For a depth image asked for without extract(): its own matcher, no thread shares it.
  cv::Ptr<cv::StereoBM> block_matcher_for_calls_;
};

// One colour image: the RGB-D extraction without a depth image. No keypoint has a depth, so the
// map starts from two views with parallax (tracking/map_initializer.h) and local mapping makes
// points by triangulation only. depth_image() is empty: the geometry stage needs a dense depth
// image of the frame and of its reference keyframes, which a single camera does not have
// (apply_sensor_limits runs the modes with geometry without it); the culler does nothing
// without one. The semantic mask masks the one image's extraction, as for RGB-D.
class MonocularFrameBuilder final : public FrameBuilder {
 public:
  MonocularFrameBuilder(const OrbConfig& orb, std::shared_ptr<const CameraModel> camera,
                        std::shared_ptr<const ScalePyramid> pyramid)
      : extractor_(orb), camera_(std::move(camera)), pyramid_(std::move(pyramid)) {}

  void extract(const InputFrame&, const cv::Mat& gray, const cv::Mat& mask,
               OrbFeatures& features) override {
    extractor_.extract(gray, mask, features);
  }

  cv::Mat depth_image(const InputFrame&) override { return {}; }

  Frame build(std::uint64_t id, const InputFrame& frame, OrbFeatures&& features, const cv::Mat&,
              const Eigen::Vector3d& angular_velocity) override {
    return Frame(id, frame.timestamp, std::move(features.keypoints),
                 std::move(features.descriptors), cv::Mat(), camera_, pyramid_, angular_velocity);
  }

  std::unique_ptr<MapInitializer> make_map_initializer(
      const TrackerOptions& tracker) const override {
    MonocularInitializerOptions options;
    options.pose_optimizer = tracker.pose_optimizer;
    return make_monocular_map_initializer(options);
  }

  void adapt(LocalMappingOptions& options) const override {
    // ORB-SLAM's monocular rules: a recent point seen by at most 2 keyframes is culled (3 with
    // depth, where an observation with depth counts as two views), and keyframe redundancy
    // counts every point, there being no "close" ones.
    options.min_observations = 2;
    options.redundancy_needs_depth = false;
  }

  // A single camera's map drifts in scale: its loops are similarities (loop/loop_closing.h).
  void adapt(LoopClosingOptions& options) const override { close_loops_with_scale(options); }

 private:
  OrbExtractor extractor_;
  std::shared_ptr<const CameraModel> camera_;
  std::shared_ptr<const ScalePyramid> pyramid_;
};

}  // namespace

SensorLimits apply_sensor_limits(SensorType type, SystemOptions& options) {
  SensorLimits limits;
  limits.requested_mode = options.dynamic.mode;
  if (type != SensorType::monocular) return limits;
  // The geometry stage compares the frame's depth with its reference keyframes' depth images
  // around projected pixels (geometry/multiview_test.h); a single camera has neither. The modes
  // keep their meaning for the part that can run: semantic stays semantic, full and exhaustive
  // run their semantic half, geometry alone runs nothing.
  const DynamicMode mode = options.dynamic.mode;
  if (uses_geometry(mode)) {
    options.dynamic.mode = uses_semantics(mode) ? DynamicMode::semantic : DynamicMode::off;
    limits.dynamic_note = std::string(to_string(mode)) + " runs as " +
                          to_string(options.dynamic.mode) +
                          " (monocular: the geometry stage needs depth images)";
  }
  return limits;
}

std::unique_ptr<FrameBuilder> make_frame_builder(const SystemConfig& config,
                                                 std::shared_ptr<const CameraModel> camera,
                                                 std::shared_ptr<const ScalePyramid> pyramid,
                                                 bool dense_depth) {
  const OrbConfig orb = read_orb_config(config.orb);
  if (config.camera.type == SensorType::stereo) {
    return std::make_unique<StereoFrameBuilder>(orb, std::move(camera), std::move(pyramid),
                                                dense_depth);
  }
  if (config.camera.type == SensorType::monocular) {
    return std::make_unique<MonocularFrameBuilder>(orb, std::move(camera), std::move(pyramid));
  }
  return std::make_unique<RgbdFrameBuilder>(orb, std::move(camera), std::move(pyramid));
}

}  // namespace pspslam
