#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/config/config.h"
#include "pspslam/core/types.h"
#include "pspslam/synth/kinect.h"

namespace pspslam {

// Ground-truth label values of SynthFrame::labels and mask/*.png (fixed convention):
// `label != 0` is exactly the set of pixels showing something that moves.
inline constexpr uint8_t kSynthLabelStatic = 0;
inline constexpr uint8_t kSynthLabelPerson = 15;    // PASCAL VOC id of "person"
inline constexpr uint8_t kSynthLabelCarried = 100;  // a box (static class) carried by a person

// Most walking people a scene holds: keeps 1 + box * 6 + face inside 16-bit surface ids.
inline constexpr int kMaxBodies = 200;

enum class SynthTrajectory { kHandheld, kLoop };

// A box of the scene at some instant: the world pose of its centre and its half extents.
struct SynthBox {
  Pose T_world_box = Pose::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

// ideal: a perfect RGB-D camera (registered, synchronised, global shutter, no distortion; depth
// noise per --depth-noise). kinect: a hand-held structured-light camera with the faults of
// SynthOptions::faults (synth/kinect.h).
enum class SynthSensor { kIdeal, kKinect };
SynthSensor parse_synth_sensor(const std::string& name);
std::string to_string(SynthSensor sensor);

// "handheld" | "loop"; anything else throws pspslam::Error naming the flag.
SynthTrajectory parse_synth_trajectory(const std::string& name);
std::string to_string(SynthTrajectory trajectory);

struct SynthOptions {
  size_t frames = 300;
  int bodies = 3;           // walking people; 0 = the static twin (same room, same camera path)
  int carried_objects = 1;  // people carrying a box; clamped to `bodies`
  uint64_t seed = 1;
  // People stand where they start for this long, then walk: points made on a person who stood
  // still must leave the map once she moves.
  double stand_seconds = 0.0;
  SynthTrajectory trajectory = SynthTrajectory::kHandheld;
  double loop_turns = 1.08;  // turns of the loop trajectory (> 1: the start is revisited)
  // Kinect-like sensor: noise growing with depth squared plus holes (range limits, grazing
  // angles, discontinuity shadows, dropouts). Off: depth_sensor is the exact depth.
  bool depth_noise = true;
  SynthSensor sensor = SynthSensor::kIdeal;
  synth::KinectFaults faults;  // used with sensor == kKinect only (depth_noise is then ignored)
  int threads = 0;             // worker threads for rendering / writing; 0 = all hardware threads
  // `--stereo BASELINE_M`: also render a rectified right camera this far along the left
  // camera's x axis (same intrinsics, same instant); 0 = RGB-D only. Ideal sensor only.
  double stereo_baseline = 0.0;
  // `--layout kitti|euroc` (needs stereo): write the KITTI odometry or EuRoC MAV layout
  // instead of TUM's.
  enum class Layout { tum, kitti, euroc };
  Layout layout = Layout::tum;

  // Throws pspslam::Error naming the offending CLI flag (--frames, --bodies, ...).
  void validate() const;
};

struct SynthFrame {
  size_t index = 0;
  Timestamp timestamp = 0.0;
  Pose T_world_camera = Pose::Identity();  // exact ground truth, camera-to-world
  cv::Mat bgr;                             // CV_8UC3
  // CV_32F metres, exact z-depth of every pixel (the room is closed); kinect: at the depth
  // camera's instant (t + depth_time_offset), through the same lens distortion as colour.
  cv::Mat depth;
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
  // The rectified right image of frame `index` (options().stereo_baseline > 0): the scene at the
  // same instant seen from T_world_camera * (baseline, 0, 0), same intrinsics. CV_8UC3.
  void render_right(size_t index, cv::Mat& bgr, int threads) const;
  // Same, reusing `frame`'s buffers; `threads` overrides options().threads (1 = this thread).
  void render(size_t index, SynthFrame& frame, int threads) const;

  const PinholeCamera& camera() const;
  const SynthOptions& options() const;
  size_t frame_count() const;
  Timestamp timestamp(size_t index) const;  // 1000000 + index / 30 s
  Pose camera_pose(size_t index) const;     // T_world_camera
  Trajectory ground_truth() const;          // all frames, camera poses
  // T_world_camera at `seconds` after the first frame (any instant, e.g. between frames).
  Pose camera_pose_at(double seconds) const;
  // Depth capture instant minus colour capture instant of a frame (0 unless kinect sync-offset).
  double depth_time_offset(size_t index) const;
  // The motion-capture body whose pose groundtruth.txt holds: T_body_camera maps camera points
  // into the body frame (identity unless kinect marker); ground_truth_pose = camera * inverse.
  Pose T_body_camera() const;
  Pose ground_truth_pose(size_t index) const;
  // The walking people (synth/people_truth.h): how many; the centre of body `body`'s torso at
  // `seconds` after the first frame (world); which body a SynthFrame::surface_ids value shows
  // (-1: the static scene or a carried box).
  int body_count() const;
  Eigen::Vector3d body_centre_at(int body, double seconds) const;
  int person_of_surface(uint16_t surface_id) const;
  // config.yaml of the sequence: synthetic_system_config() plus the lens distortion when the
  // kinect distortion fault is on; a stereo camera (type stereo, the baseline, depth threshold
  // 40 baselines) with --stereo.
  SystemConfig system_config() const;
  // The RGB-D config of the same sequence (config_rgbd.yaml beside a stereo config.yaml).
  SystemConfig rgbd_system_config() const;
  // The static geometry: the room first (a box seen from inside: its faces are the walls, the
  // floor and the ceiling), then the furniture (solid boxes).
  std::vector<SynthBox> static_boxes() const;
  // Every body part (and carried box) of every walking person at `seconds` after the first frame.
  std::vector<SynthBox> body_boxes_at(double seconds) const;

 private:
  struct Impl;
  std::unique_ptr<const Impl> impl_;
};

// The camera every synthetic sequence uses: "synthetic", fx = fy = 525, cx = 319.5, cy = 239.5,
// no distortion, 30 fps, depth factor 5000, depth threshold 4 m.
CameraConfig synthetic_camera_config();
SystemConfig synthetic_system_config();

}  // namespace pspslam
