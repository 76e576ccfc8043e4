#include "pspslam/synth/motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "pspslam/synth/texture.h"

namespace pspslam::synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

double unit(uint64_t seed, uint64_t what) { return hash_to_unit(mix_hash(seed, what)); }

// Camera axes: x right, y down, z forward (OpenCV), from a world heading with z up.
Eigen::Matrix3d look_rotation(double yaw, double pitch) {
  const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                std::sin(pitch));
  const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  Eigen::Matrix3d R;
  R.col(0) = right;
  R.col(1) = down;
  R.col(2) = forward;
  return R;
}

Eigen::Matrix3d rot_y(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

}  // namespace

CameraPath::CameraPath(bool loop, uint64_t seed, double duration_s, const RoomLayout& room,
                       double loop_turns, MotionProfile profile)
    : loop_(loop),
      loop_turns_(loop_turns),
      profile_(profile),
      duration_s_(std::max(duration_s, 1e-3)),
      centre_(room.floor_centre()) {
  const uint64_t camera_seed = mix_hash(seed, 0xCA3E7Au);
  for (int i = 0; i < 16; ++i) phases_[i] = 2.0 * kPi * unit(camera_seed, static_cast<uint64_t>(i));
  yaw0_ = 2.0 * kPi * unit(camera_seed, 100);
}

Pose CameraPath::T_world_camera(double t) const {
  const double* ph = phases_;
  Eigen::Vector3d position;
  double yaw = 0, pitch = 0, roll = 0;
  if (loop_) {
    const double angle = yaw0_ + 2.0 * kPi * loop_turns_ * t / duration_s_;
    // Everything but the shake is a function of the loop angle, so one turn later the camera
    // is back at the same viewpoint (within the ~3 mm / 0.4 deg shake).
    position << centre_.x() + 1.0 * std::cos(angle), centre_.y() + 0.8 * std::sin(angle),
        1.4 + 0.04 * std::sin(2.0 * angle + ph[0]);
    yaw = angle + 0.15 * std::sin(3.0 * angle + ph[1]);
    pitch = -0.12 + 0.05 * std::sin(2.0 * angle + ph[2]);
    roll = 0.03 * std::sin(angle + ph[3]);
  } else {
    // Slow incommensurate sinusoids: smooth, never exactly repeating, speeds <= 0.35 m/s and
    // yaw rates <= 35 deg/s, like a person filming while walking around slowly.
    // Scaled term by term in the original order: a profile of 1.0 leaves every rounding, so
    // the ideal path keeps its bytes.
    const double p = profile_.translation, r = profile_.rotation;
    position << centre_.x() + p * 0.55 * std::sin(0.45 * t + ph[0]) +
                    p * 0.08 * std::sin(1.3 * t + ph[1]),
        centre_.y() + p * 0.4 * std::sin(0.37 * t + ph[2]),
        1.45 + p * 0.06 * std::sin(0.8 * t + ph[3]);
    yaw = yaw0_ + r * 1.1 * std::sin(0.35 * t + ph[4]) + r * 0.25 * std::sin(0.9 * t + ph[5]);
    pitch = -0.15 + r * 0.08 * std::sin(0.6 * t + ph[6]);
    roll = r * 0.04 * std::sin(0.5 * t + ph[7]);
  }
  // Hand shake: small fast rotations (~0.3 deg) and translations (~2 mm).
  const Eigen::Vector3d shake_rotation_unit(
      0.004 * std::sin(9.1 * t + ph[8]) + 0.002 * std::sin(15.3 * t + ph[9]),
      0.004 * std::sin(8.3 * t + ph[10]) + 0.002 * std::sin(14.1 * t + ph[11]),
      0.003 * std::sin(7.7 * t + ph[12]));
  const Eigen::Vector3d shake_translation_unit(0.002 * std::sin(10.3 * t + ph[13]),
                                               0.002 * std::sin(11.9 * t + ph[14]),
                                               0.002 * std::sin(9.7 * t + ph[15]));
  const Eigen::Vector3d shake_rotation = profile_.shake * shake_rotation_unit;
  const Eigen::Vector3d shake_translation = profile_.shake * shake_translation_unit;
  Pose pose = Pose::Identity();
  const double shake_angle = shake_rotation.norm();
  const Eigen::Matrix3d shake =
      shake_angle > 0
          ? Eigen::AngleAxisd(shake_angle, shake_rotation / shake_angle).toRotationMatrix()
          : Eigen::Matrix3d::Identity();
  pose.linear() = look_rotation(yaw, pitch) *
                  Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ()).toRotationMatrix() * shake;
  pose.translation() = position + shake_translation;
  return pose;
}

WalkingBody::WalkingBody(int index, uint64_t seed, bool carries_box, const RoomLayout& room,
                         std::optional<double> sector_centre_angle, double stand_s)
    : carries_box_(carries_box),
      centre_(room.floor_centre()),
      sector_centre_(sector_centre_angle),
      stand_s_(stand_s) {
  const uint64_t body_seed = mix_hash(seed, 0xB0D1u, static_cast<uint64_t>(index));
  if (sector_centre_) {
    // Spread people over the sector; a person beyond the third reuses a lane, shifted.
    *sector_centre_ += 0.5 * ((index % 3) - 1) + 0.2 * (unit(body_seed, 5) - 0.5);
    radius_ = 2.0 + 0.12 * (index % 3);
    radius_swing_ = 0.35;
  } else {
    // Three rings between the camera area (|x| < 0.7 m, |y| < 0.5 m around the centre) and
    // the furniture along the walls.
    radius_ = 1.8 + 0.3 * (index % 3);
    radius_swing_ = 0.1;
  }
  wobble_phase_ = 2.0 * kPi * unit(body_seed, 1);
  direction_ = (index % 2 == 0) ? 1.0 : -1.0;
  speed_ = 0.6 + 0.7 * unit(body_seed, 3);
  scale_ = 0.95 + 0.1 * unit(body_seed, 4);
  parts_ = {BodyPart::kTorso,    BodyPart::kHead,    BodyPart::kLeftArm,
            BodyPart::kRightArm, BodyPart::kLeftLeg, BodyPart::kRightLeg};
  if (carries_box_) parts_.push_back(BodyPart::kCarriedBox);

  constexpr int kSamples = 2048;
  lap_distance_.resize(kSamples);
  lap_distance_[0] = 0.0;
  for (int i = 1; i < kSamples; ++i) {
    const double tau0 = 2.0 * kPi * (i - 1) / (kSamples - 1), tau1 = 2.0 * kPi * i / (kSamples - 1);
    lap_distance_[static_cast<size_t>(i)] =
        lap_distance_[static_cast<size_t>(i - 1)] + (path_point(tau1) - path_point(tau0)).norm();
  }
  start_m_ = lap_distance_.back() * unit(body_seed, 2);
}

Eigen::Vector2d WalkingBody::path_point(double tau) const {
  double angle = 0.0, radius = 0.0;
  if (sector_centre_) {
    // A lap in polar coordinates: +-115 deg wide, so people also leave the view for a while;
    // far arc at tau = 0, near arc at tau = pi.
    constexpr double kSectorHalfWidth = 2.0;
    angle = *sector_centre_ + kSectorHalfWidth * std::sin(tau);
    radius = radius_ + radius_swing_ * std::cos(tau);
  } else {
    angle = tau;
    radius = radius_ * (1.0 + radius_swing_ * std::sin(2.0 * tau + wobble_phase_));
  }
  // The room is 7 x 6 m: squeeze y so every lap keeps clear of the furniture on all walls.
  return centre_ + Eigen::Vector2d(radius * std::cos(angle), 0.78 * radius * std::sin(angle));
}

double WalkingBody::tau_at_distance(double distance_m) const {
  const double lap = lap_distance_.back();
  distance_m = std::fmod(distance_m, lap);
  if (distance_m < 0) distance_m += lap;
  const auto it = std::upper_bound(lap_distance_.begin(), lap_distance_.end(), distance_m);
  const size_t i = std::clamp<size_t>(static_cast<size_t>(it - lap_distance_.begin()), 1,
                                      lap_distance_.size() - 1);
  const double d0 = lap_distance_[i - 1], d1 = lap_distance_[i];
  const double fraction = d1 > d0 ? (distance_m - d0) / (d1 - d0) : 0.0;
  return 2.0 * kPi * (static_cast<double>(i - 1) + fraction) /
         static_cast<double>(lap_distance_.size() - 1);
}

void WalkingBody::pose_parts(double t, std::vector<BodyPartPose>& out) const {
  const double walked_s = std::max(0.0, t - stand_s_);
  const double distance = start_m_ + direction_ * speed_ * walked_s;
  const Eigen::Vector2d position = path_point(tau_at_distance(distance));
  const Eigen::Vector2d ahead = path_point(tau_at_distance(distance + direction_ * 0.05));
  const double heading = std::atan2(ahead.y() - position.y(), ahead.x() - position.x());
  constexpr double kStrideCycle_m = 1.3;  // one full gait cycle (two steps)
  const double gait = 2.0 * kPi * speed_ * walked_s / kStrideCycle_m;
  const double bob = 0.012 * (1.0 - std::cos(2.0 * gait));

  Pose T_world_body = Pose::Identity();
  T_world_body.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_body.translation() = Eigen::Vector3d(position.x(), position.y(), bob);
  const double s = scale_;

  // A limb hangs from its joint; positive swing moves its lower end forward (+x of the body).
  const auto limb = [&](const Eigen::Vector3d& joint, double half_length, double half_width,
                        double swing) {
    BodyPartPose part;
    Pose T_body_part = Pose::Identity();
    T_body_part.linear() = rot_y(-swing);
    T_body_part.translation() = joint + T_body_part.linear() * Eigen::Vector3d(0, 0, -half_length);
    part.T_world_part = T_world_body * T_body_part;
    part.half_extents = Eigen::Vector3d(half_width, half_width, half_length);
    return part;
  };
  const auto rigid = [&](const Eigen::Vector3d& centre, const Eigen::Vector3d& half) {
    BodyPartPose part;
    part.T_world_part = T_world_body * Eigen::Translation3d(centre);
    part.half_extents = half;
    return part;
  };

  out.clear();
  const double leg_swing = 0.42 * std::sin(gait);
  // Arms swing against the leg on their side; a carrier holds both forward around the box.
  const double left_arm_swing = carries_box_ ? 1.15 : -0.38 * std::sin(gait);
  const double right_arm_swing = carries_box_ ? 1.15 : 0.38 * std::sin(gait);
  for (const BodyPart part : parts_) {
    switch (part) {
      case BodyPart::kTorso:
        out.push_back(
            rigid(Eigen::Vector3d(0, 0, 1.16 * s), Eigen::Vector3d(0.11, 0.19, 0.30) * s));
        break;
      case BodyPart::kHead:
        out.push_back(
            rigid(Eigen::Vector3d(0, 0, 1.60 * s), Eigen::Vector3d(0.10, 0.085, 0.12) * s));
        break;
      case BodyPart::kLeftArm:
        out.push_back(limb(Eigen::Vector3d(0, 0.25, 1.42) * s, 0.33 * s, 0.05 * s, left_arm_swing));
        break;
      case BodyPart::kRightArm:
        out.push_back(
            limb(Eigen::Vector3d(0, -0.25, 1.42) * s, 0.33 * s, 0.05 * s, right_arm_swing));
        break;
      case BodyPart::kLeftLeg:
        out.push_back(limb(Eigen::Vector3d(0, 0.1, 0.86) * s, 0.43 * s, 0.07 * s, leg_swing));
        break;
      case BodyPart::kRightLeg:
        out.push_back(limb(Eigen::Vector3d(0, -0.1, 0.86) * s, 0.43 * s, 0.07 * s, -leg_swing));
        break;
      case BodyPart::kCarriedBox:
        out.push_back(rigid(Eigen::Vector3d(0.45, 0, 1.12) * s, Eigen::Vector3d(0.17, 0.2, 0.14)));
        break;
    }
  }
}

}  // namespace pspslam::synth
