#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "pspslam/core/types.h"

namespace pspslam::synth {

// The room: an axis-aligned box [0, size] in world coordinates, z up (floor at z = 0).
struct RoomLayout {
  Eigen::Vector3d size{7.0, 6.0, 2.8};
  Eigen::Vector2d floor_centre() const { return size.head<2>() / 2.0; }
};

// Hand-held camera motion as a smooth function of time, so ground truth is exact at any t.
// Handheld: wanders around the middle of the room looking at the walls (yaw sweeps +-80 deg).
// Loop: walks an ellipse (~5.7 m long) looking outwards and ends `loop_turns` turns after its
// start (default 1.08: 8% of a turn past it), so the last frames revisit the first viewpoint
// (for loop-closure tests; more turns = a longer revisit, e.g. for covisibility consistency).
// Scales of the hand-held path's slow rotation, slow translation and hand shake (1, 1, 1: the
// ideal sensor's path).
struct MotionProfile {
  double rotation = 1.0;
  double translation = 1.0;
  double shake = 1.0;
};

class CameraPath {
 public:
  CameraPath(bool loop, uint64_t seed, double duration_s, const RoomLayout& room,
             double loop_turns = 1.08, MotionProfile profile = {});
  Pose T_world_camera(double t) const;
  // Mean viewing direction (world yaw) of the hand-held camera: where people should walk.
  double mean_heading() const { return yaw0_; }

 private:
  bool loop_;
  double loop_turns_;
  MotionProfile profile_;
  double duration_s_;
  Eigen::Vector2d centre_;
  double phases_[16];
  double yaw0_;
};

// One rigid part of an animated body: a box with its pose and size at some instant.
struct BodyPartPose {
  Pose T_world_part = Pose::Identity();
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();
};

enum class BodyPart { kTorso, kHead, kLeftArm, kRightArm, kLeftLeg, kRightLeg, kCarriedBox };

// A person walking at constant speed along a smooth closed path, limbs swinging with the gait;
// a carrier holds a box in front of the chest with both arms.
// Without a sector the path is a wobbly ellipse around the whole room (between the camera area
// and the furniture). With a sector (the direction, seen from the room centre, that a hand-held
// camera mostly looks at) the person walks a long lap inside that sector: out along a far arc,
// back along a near one, passing about 1 m from the camera, as people do in front of a camera.
class WalkingBody {
 public:
  // `stand_s`: the person stands at the path's start for this long, then walks.
  WalkingBody(int index, uint64_t seed, bool carries_box, const RoomLayout& room,
              std::optional<double> sector_centre_angle = std::nullopt, double stand_s = 0.0);

  bool carries_box() const { return carries_box_; }
  const std::vector<BodyPart>& parts() const { return parts_; }
  // Part poses at time t, in the order of parts().
  void pose_parts(double t, std::vector<BodyPartPose>& out) const;
  double speed() const { return speed_; }  // m/s along the path

 private:
  Eigen::Vector2d path_point(double tau) const;  // tau in [0, 2 pi): one lap
  double tau_at_distance(double distance_m) const;

  bool carries_box_;
  std::vector<BodyPart> parts_;
  Eigen::Vector2d centre_;
  std::optional<double> sector_centre_;
  double radius_, radius_swing_, wobble_phase_;
  double direction_;  // +1 or -1: which way round the lap
  double start_m_;    // where on the lap the person is at t = 0
  double stand_s_;    // seconds stood still before walking
  double speed_;
  double scale_;                      // body height / 1.72 m
  std::vector<double> lap_distance_;  // arc length at tau = 2 pi k / (n - 1), for constant speed
};

}  // namespace pspslam::synth
