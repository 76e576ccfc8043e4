#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/config/config.h"
#include "pspslam/core/types.h"

namespace pspslam {

// Ground-truth label values of SynthFrame::labels and mask/*.png (fixed convention):
// `label != 0` is exactly the set of pixels showing something that moves.
inline constexpr uint8_t kSynthLabelStatic = 0;
inline constexpr uint8_t kSynthLabelPerson = 15;    // PASCAL VOC id of "person"
inline constexpr uint8_t kSynthLabelCarried = 100;  // a box (static class) carried by a person

// Most walking people a scene holds: keeps 1 + box * 6 + face inside 16-bit surface ids.
inline constexpr int kMaxBodies = 200;

enum class SynthTrajectory { kHandheld, kLoop };

// "handheld" | "loop"; anything else throws pspslam::Error naming the flag.
SynthTrajectory parse_synth_trajectory(const std::string& name);
std::string to_string(SynthTrajectory trajectory);

struct SynthOptions {
  size_t frames = 300;
  int bodies = 3;           // walking people; 0 = the static twin (same room, same camera path)
  int carried_objects = 1;  // people carrying a box; clamped to `bodies`
  uint64_t seed = 1;
  SynthTrajectory trajectory = SynthTrajectory::kHandheld;
  double loop_turns = 1.08;  // turns of the loop trajectory (> 1: the start is revisited)
  // Kinect-like sensor: noise growing with depth squared plus holes (range limits, grazing
  // angles, discontinuity shadows, dropouts). Off: depth_sensor is the exact depth.
  bool depth_noise = true;
  int threads = 0;  // worker threads for rendering / writing; 0 = all hardware threads

  // Throws pspslam::Error naming the offending CLI flag (--frames, --bodies, ...).
  void validate() const;
};

struct SynthFrame {
  size_t index = 0;
  Timestamp timestamp = 0.0;
  Pose T_world_camera = Pose::Identity();  // exact ground truth, camera-to-world
  cv::Mat bgr;                             // CV_8UC3
  cv::Mat depth;         // CV_32F metres, exact z-depth of every pixel (the room is closed)
  cv::Mat depth_sensor;  // CV_32F metres, exactly what depth/<ts>.png holds (0 = no reading)
  cv::Mat labels;        // CV_8U, kSynthLabel* values
  cv::Mat surface_ids;   // CV_16U, 1 + which box face each pixel shows: for visibility tests
};

// A closed, textured room (7 x 6 x 2.8 m, furniture along the walls) with people walking around
// it, seen by a hand-held 640x480 RGB-D camera at 30 Hz. Every frame is a pure function of
// (options, index): frames can be rendered in any order, on any thread, with identical bytes.
class SyntheticScene {
 public:
  explicit SyntheticScene(const SynthOptions& options);
  ~SyntheticScene();
  SyntheticScene(SyntheticScene&&) noexcept;
  SyntheticScene& operator=(SyntheticScene&&) noexcept;

  SynthFrame render(size_t index) const;
  // Same, reusing `frame`'s buffers; `threads` overrides options().threads (1 = this thread).
  void render(size_t index, SynthFrame& frame, int threads) const;

  const PinholeCamera& camera() const;
  const SynthOptions& options() const;
  size_t frame_count() const;
  Timestamp timestamp(size_t index) const;  // 1000000 + index / 30 s
  Pose camera_pose(size_t index) const;     // T_world_camera
  Trajectory ground_truth() const;          // all frames

 private:
  struct Impl;
  std::unique_ptr<const Impl> impl_;
};

// The camera every synthetic sequence uses: "synthetic", fx = fy = 525, cx = 319.5, cy = 239.5,
// no distortion, 30 fps, depth factor 5000, depth threshold 4 m.
CameraConfig synthetic_camera_config();
SystemConfig synthetic_system_config();

}  // namespace pspslam
