#pragma once
// The rotation rate of a rolling-shutter frame, measured from the frame's own matches.
//
// A frame's keypoints were moved to its instant with a predicted rate w0
// (camera/rolling_shutter.h). Where the true rate is w0 + rho, a keypoint on a row read dt after
// the frame's instant still sits where the camera, turned by rho dt, saw the point: the map point p
// (camera coordinates at the frame's instant) appears at pi(Exp(-dt [rho]x) p). Across the rows
// that is a shear and a stretch of the image no rigid pose reproduces, so rho is measured by the
// image itself, together with the pose, with a Gaussian prior rho ~ N(0, sigma^2) for frames with
// few matches.
//
// Why not difference the last two poses instead: each pose jitters by a few tenths of a degree on
// real data, and over one frame interval that is a rate error of several degrees per second, a
// third of the hand-held rate being corrected; fed back into the next frame's correction it makes
// the synthetic Kinect runs worse (docs/decisions/rolling-shutter.md).

#include <vector>

#include "pspslam/camera/pinhole_camera.h"
#include "pspslam/core/types.h"
#include "pspslam/optimize/depth_noise_model.h"
#include "pspslam/optimize/pose_optimizer.h"

namespace pspslam {

struct RollingShutterPose {
  Pose T_camera_world = Pose::Identity();
  Eigen::Vector3d rate_correction = Eigen::Vector3d::Zero();  // rho, rad/s, camera frame
  // The pose's information with rho marginalised out (Schur complement of the last iteration's
  // normal equations): what the image says about the pose once the rate is free too. Zero when
  // the refinement gave up.
  PoseInformation pose_information = PoseInformation::Zero();
};

// Gauss-Newton on the pose (6) and rho (3) over `observations` (inliers of the pose-only
// optimisation), plain least squares as the optimiser's last rounds are. `row_times[i]`: seconds
// from the frame's instant to the reading of observation i's row. `sigma_rate`: the prior's
// standard deviation (rad/s, > 0). Returns the start and zero when a point falls behind the camera
// or the system is singular.
RollingShutterPose refine_pose_and_rotation_rate(const PinholeCamera& camera, double bf,
                                                 const DepthNoiseModel& depth_noise,
                                                 const Pose& initial_T_camera_world,
                                                 const std::vector<PoseObservation>& observations,
                                                 const std::vector<double>& row_times,
                                                 double sigma_rate, int iterations = 5);

}  // namespace pspslam
