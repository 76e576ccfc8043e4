#include "pspslam/eval/rpe.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

// evaluate_rpe.py's find_closest_index: a bisection that remembers the closest value it visited.
// Kept verbatim in behaviour (not std::lower_bound) so ties resolve to the same index.
size_t find_closest_index(const std::vector<double>& sorted, double t) {
  size_t beginning = 0;
  double difference = std::abs(sorted[0] - t);
  size_t best = 0;
  size_t end = sorted.size();
  while (beginning < end) {
    const size_t middle = (end + beginning) / 2;
    if (std::abs(sorted[middle] - t) < difference) {
      difference = std::abs(sorted[middle] - t);
      best = middle;
    }
    if (t == sorted[middle]) return middle;
    if (sorted[middle] > t) {
      end = middle;
    } else {
      beginning = middle + 1;
    }
  }
  return best;
}

Trajectory sorted_by_time(Trajectory trajectory) {
  std::sort(trajectory.begin(), trajectory.end(),
            [](const StampedPose& l, const StampedPose& r) { return l.timestamp < r.timestamp; });
  return trajectory;
}

std::vector<double> timestamps(const Trajectory& trajectory) {
  std::vector<double> stamps;
  stamps.reserve(trajectory.size());
  for (const StampedPose& p : trajectory) stamps.push_back(p.timestamp);
  return stamps;
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t half = values.size() / 2;
  return values.size() % 2 == 1 ? values[half] : 0.5 * (values[half - 1] + values[half]);
}

// Accumulates (estimate axis, ground-truth axis) pairs of relative rotations and solves for the
// rotation that maps one set onto the other (Kabsch on the axes, weighted by the angles).
class BodyFrameRotation {
 public:
  void add(const Eigen::Matrix3d& est_rotation, const Eigen::Matrix3d& gt_rotation) {
    const Eigen::AngleAxisd est(est_rotation), gt(gt_rotation);
    constexpr double kMinTurn = std::numbers::pi / 180.0;  // below 1 degree the axis is noise
    if (est.angle() < kMinTurn || gt.angle() < kMinTurn) return;
    correlation_ += (gt.axis() * gt.angle()) * (est.axis() * est.angle()).transpose();
    ++turning_pairs_;
  }
  double degrees() const {
    if (turning_pairs_ < 10) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation_,
                                                Eigen::ComputeFullU | Eigen::ComputeFullV);
    // Axes about a single direction leave the rotation about it free.
    if (svd.singularValues()(1) < 0.02 * svd.singularValues()(0))
      return std::numeric_limits<double>::quiet_NaN();
    Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
    fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    const Eigen::Matrix3d rotation = svd.matrixU() * fix * svd.matrixV().transpose();
    return Eigen::AngleAxisd(rotation).angle() * 180.0 / std::numbers::pi;
  }

 private:
  Eigen::Matrix3d correlation_ = Eigen::Matrix3d::Zero();
  int turning_pairs_ = 0;
};

}  // namespace

std::string to_string(RpeDeltaUnit unit) { return unit == RpeDeltaUnit::seconds ? "s" : "f"; }

RpeResult compute_rpe(const Trajectory& ground_truth_in, const Trajectory& estimate_in,
                      const RpeOptions& options) {
  if (ground_truth_in.size() < 2 || estimate_in.size() < 2) {
    throw Error("RPE: need at least 2 poses in each trajectory (ground truth has " +
                std::to_string(ground_truth_in.size()) + ", estimate has " +
                std::to_string(estimate_in.size()) + ")");
  }
  if (!(options.delta > 0.0)) throw Error("RPE: delta must be > 0");
  const Trajectory gt = sorted_by_time(ground_truth_in);
  const Trajectory est = sorted_by_time(estimate_in);
  const std::vector<double> gt_stamps = timestamps(gt);
  const std::vector<double> est_stamps = timestamps(est);

  std::vector<double> index_est;
  if (options.unit == RpeDeltaUnit::seconds) {
    index_est = est_stamps;
  } else {
    for (size_t i = 0; i < est.size(); ++i) index_est.push_back(static_cast<double>(i));
  }

  std::vector<double> gt_intervals;
  for (size_t k = 1; k < gt_stamps.size(); ++k)
    gt_intervals.push_back(gt_stamps[k] - gt_stamps[k - 1]);
  const double gt_max_time_difference = 2.0 * median(gt_intervals);

  RpeResult result;
  BodyFrameRotation body_frames;
  std::vector<double> translation, rotation, translation_rate, rotation_rate;
  for (size_t i = 0; i < est.size(); ++i) {
    const size_t j = find_closest_index(index_est, index_est[i] + options.delta);
    if (j == est.size() - 1) continue;  // evaluate_rpe.py drops pairs ending at the last pose
    const double stamp_est_0 = est_stamps[i];
    const double stamp_est_1 = est_stamps[j];
    const size_t g0 = find_closest_index(gt_stamps, stamp_est_0 + options.offset);
    const size_t g1 = find_closest_index(gt_stamps, stamp_est_1 + options.offset);
    if (std::abs(gt_stamps[g0] - (stamp_est_0 + options.offset)) > gt_max_time_difference ||
        std::abs(gt_stamps[g1] - (stamp_est_1 + options.offset)) > gt_max_time_difference) {
      continue;
    }
    const Pose est_motion = est[j].T_world_camera.inverse() * est[i].T_world_camera;
    const Pose gt_motion = gt[g1].T_world_camera.inverse() * gt[g0].T_world_camera;
    const Pose error = est_motion.inverse() * gt_motion;
    body_frames.add(est_motion.linear(), gt_motion.linear());
    RpePair pair;
    pair.est_from = stamp_est_0;
    pair.est_to = stamp_est_1;
    pair.gt_from = gt_stamps[g0];
    pair.gt_to = gt_stamps[g1];
    pair.translation_error = error.translation().norm();
    const double cosine = std::clamp((error.linear().trace() - 1.0) / 2.0, -1.0, 1.0);
    pair.rotation_error = std::acos(cosine) * 180.0 / std::numbers::pi;
    translation.push_back(pair.translation_error);
    rotation.push_back(pair.rotation_error);
    const double seconds = stamp_est_1 - stamp_est_0;
    if (seconds > 0.0) {
      translation_rate.push_back(pair.translation_error / seconds);
      rotation_rate.push_back(pair.rotation_error / seconds);
    }
    result.pairs.push_back(pair);
  }
  if (result.pairs.size() < 2) {
    char delta[32];
    std::snprintf(delta, sizeof(delta), "%g", options.delta);
    throw Error("RPE: only " + std::to_string(result.pairs.size()) + " pose pairs " + delta + " " +
                to_string(options.unit) +
                " apart have ground truth at both ends (need at least 2); is the trajectory "
                "shorter than the delta, or the wrong ground truth?");
  }
  result.body_frame_rotation_deg = body_frames.degrees();
  result.translation = compute_error_stats(std::move(translation));
  result.rotation = compute_error_stats(std::move(rotation));
  result.translation_per_second = compute_error_stats(std::move(translation_rate));
  result.rotation_per_second = compute_error_stats(std::move(rotation_rate));
  return result;
}

}  // namespace pspslam
