#include "pspslam/tracking/frame_pose_optimization.h"

#include "pspslam/camera/rolling_shutter.h"
#include "pspslam/map/frame.h"
#include "pspslam/map/map_point.h"
#include "pspslam/optimize/rolling_shutter_pose.h"
#include "pspslam/solve/pnp_ransac.h"

namespace pspslam {
namespace {

// The frame's matches (or only those not flagged as outliers) as pose observations.
void gather_observations(const Frame& frame, bool inliers_only, FramePoseBuffers& buffers) {
  buffers.observations.clear();
  buffers.keypoint_of_observation.clear();
  const ScalePyramid& pyramid = frame.pyramid();
  for (int i = 0; i < frame.size(); ++i) {
    const auto& point = frame.map_points[i];
    if (!point || (inliers_only && frame.outlier[i])) continue;
    const cv::KeyPoint& kp = frame.keypoints()[i];
    buffers.observations.push_back({point->position(), Eigen::Vector2d(kp.pt.x, kp.pt.y),
                                    static_cast<double>(frame.right_u(i)),
                                    pyramid.inv_sigma2[kp.octave]});
    buffers.keypoint_of_observation.push_back(i);
  }
}

}  // namespace

Pose orthonormalized(const Pose& pose) {
  Pose out = pose;
  out.linear() = Eigen::Quaterniond(pose.rotation()).normalized().toRotationMatrix();
  return out;
}

namespace {

// optimize_frame_pose on observations already gathered into `buffers`.
PoseOptimizationResult solve_gathered(Frame& frame, const PoseOptimizerOptions& options,
                                      const FramePoseBuffers& buffers, const PosePrior* prior) {
  PoseOptimizationResult optimized =
      optimize_pose(frame.camera().pinhole, frame.camera().bf, frame.T_camera_world(),
                    buffers.observations, options, prior);
  frame.set_pose(orthonormalized(optimized.T_camera_world));
  return optimized;
}

}  // namespace

PoseOptimizationResult optimize_frame_pose(Frame& frame, const PoseOptimizerOptions& options,
                                           FramePoseBuffers& buffers, const PosePrior* prior) {
  gather_observations(frame, /*inliers_only=*/false, buffers);
  return solve_gathered(frame, options, buffers, prior);
}

PoseOptimizationResult optimize_frame_pose_judged_first(
    Frame& frame, const PoseOptimizerOptions& options, FramePoseBuffers& buffers,
    const PosePrior* prior, const JudgedPoints& judged, int& set_aside) {
  set_aside = 0;
  gather_observations(frame, /*inliers_only=*/false, buffers);
  const std::vector<PoseObservation>& all = buffers.observations;
  std::vector<uint8_t>& use = buffers.use;
  use.assign(all.size(), 0);
  int judged_matches = 0;
  for (size_t k = 0; k < all.size(); ++k) {
    const std::uint64_t made =
        frame.map_points[buffers.keypoint_of_observation[k]]->first_frame_id();
    use[k] = made <= judged.judged_through_frame || made > frame.id();
    judged_matches += use[k];
  }
  if (judged_matches < judged.min_points || judged_matches == static_cast<int>(all.size()))
    return solve_gathered(frame, options, buffers, prior);

  const PinholeCamera& pinhole = frame.camera().pinhole;
  const double bf = frame.camera().bf;
  auto solve_on = [&](const Pose& start) {
    buffers.subset.clear();
    buffers.subset_of_observation.clear();
    for (size_t k = 0; k < all.size(); ++k) {
      if (!use[k]) continue;
      buffers.subset.push_back(all[k]);
      buffers.subset_of_observation.push_back(k);
    }
    return optimize_pose(pinhole, bf, start, buffers.subset, options, prior);
  };
  const PoseOptimizationResult on_judged = solve_on(frame.T_camera_world());
  classify_observations(pinhole, bf, on_judged.T_camera_world, all, options, buffers.agrees);
  for (size_t k = 0; k < all.size(); ++k) {
    if (use[k]) continue;
    use[k] = buffers.agrees[k];
    set_aside += !buffers.agrees[k];
  }
  const PoseOptimizationResult final_solve = solve_on(on_judged.T_camera_world);

  PoseOptimizationResult result;
  result.T_camera_world = final_solve.T_camera_world;
  result.inlier.assign(all.size(), 0);
  for (size_t j = 0; j < buffers.subset_of_observation.size(); ++j)
    result.inlier[buffers.subset_of_observation[j]] = final_solve.inlier[j];
  result.num_inliers = final_solve.num_inliers;
  frame.set_pose(orthonormalized(result.T_camera_world));
  return result;
}

RollingShutterPose refine_frame_rotation_rate(Frame& frame, const PoseOptimizerOptions& options,
                                              double sigma_rate, FramePoseBuffers& buffers) {
  const CameraModel& camera = frame.camera();
  if (camera.rolling_shutter_readout_s == 0.0) return {frame.T_camera_world()};
  gather_observations(frame, /*inliers_only=*/true, buffers);
  buffers.row_times.clear();
  for (const PoseObservation& observation : buffers.observations) {
    buffers.row_times.push_back(rolling_shutter_row_time(
        camera.rolling_shutter_readout_s, camera.pinhole.height, observation.pixel.y()));
  }
  const RollingShutterPose refined = refine_pose_and_rotation_rate(
      camera.pinhole, camera.bf, options.depth_noise, frame.T_camera_world(), buffers.observations,
      buffers.row_times, sigma_rate);
  frame.set_pose(orthonormalized(refined.T_camera_world));
  frame.correct_rotation_rate(refined.rate_correction);
  return refined;
}

PoseInformation frame_pose_information(const Frame& frame, const PoseOptimizerOptions& options,
                                       FramePoseBuffers& buffers, const PosePrior* prior) {
  gather_observations(frame, /*inliers_only=*/true, buffers);
  return pose_information(frame.camera().pinhole, frame.camera().bf, options.depth_noise,
                          frame.T_camera_world(), buffers.observations, prior);
}

bool pose_from_matches(Frame& frame) {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<int> keypoint;
  for (int i = 0; i < frame.size(); ++i) {
    if (!frame.map_points[i]) continue;
    points.push_back(frame.map_points[i]->position());
    pixels.emplace_back(frame.keypoints()[i].pt.x, frame.keypoints()[i].pt.y);
    keypoint.push_back(i);
  }
  const PnpRansacResult pnp = solve_pnp_ransac(frame.camera().pinhole, points, pixels);
  if (!pnp.success) return false;
  for (size_t k = 0; k < keypoint.size(); ++k) {
    if (!pnp.inlier[k]) frame.map_points[keypoint[k]] = nullptr;
  }
  frame.set_pose(pnp.T_camera_world);
  return true;
}

}  // namespace pspslam
