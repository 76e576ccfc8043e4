// Timings of the per-frame pose-only optimisation and of one local bundle adjustment on
// synthetic RGB-D data of the size ORB-SLAM2 sees on TUM sequences.
//   build-opt/bench/bench_optimize [--benchmark_filter=...]

#include <benchmark/benchmark.h>

#include <limits>
#include <random>

#include "pspslam/optimize/local_bundle_adjustment.h"
#include "pspslam/optimize/pose_optimizer.h"

namespace pspslam {
namespace {

constexpr double kBaseline = 0.08;

Pose camera_on_track(int index) {
  Pose T_world_camera = Pose::Identity();
  T_world_camera.linear() =
      Eigen::AngleAxisd(0.02 * index, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_world_camera.translation() = Eigen::Vector3d(0.1 * index, 0.0, 0.0);
  return T_world_camera.inverse();
}

Pose perturbed(const Pose& pose, std::mt19937& rng, double angle, double shift) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Pose delta = Pose::Identity();
  delta.linear() =
      Eigen::AngleAxisd(angle, Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized())
          .toRotationMatrix();
  delta.translation() = shift * Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
  return delta * pose;
}

constexpr double kNoDepth = std::numeric_limits<double>::quiet_NaN();

// Noisy (u, v, u_r) of point_world; u_r NaN (no depth) with probability 1 - depth_fraction.
void measure(const PinholeCamera& camera, double bf, const Pose& T_camera_world,
             const Eigen::Vector3d& point_world, double depth_fraction, std::mt19937& rng,
             Eigen::Vector2d& pixel, double& right_u) {
  std::normal_distribution<double> noise(0.0, 1.0);
  std::bernoulli_distribution has_depth(depth_fraction);
  const Eigen::Vector3d p = T_camera_world * point_world;
  const Eigen::Vector2d ideal = camera.project(p);
  pixel = ideal + Eigen::Vector2d(noise(rng), noise(rng));
  right_u = has_depth(rng) ? ideal.x() - bf / p.z() + noise(rng) : kNoDepth;
}

void BM_OptimizePose(benchmark::State& state) {
  const int num_observations = static_cast<int>(state.range(0));
  const PinholeCamera camera;
  const double bf = camera.fx * kBaseline;
  std::mt19937 rng(1);
  const Pose truth = camera_on_track(3);
  std::uniform_real_distribution<double> u(10.0, 630.0), v(10.0, 470.0), z(0.8, 6.0);
  std::bernoulli_distribution is_outlier(0.2);
  std::vector<PoseObservation> observations;
  for (int i = 0; i < num_observations; ++i) {
    const Eigen::Vector3d point = truth.inverse() * camera.unproject({u(rng), v(rng)}, z(rng));
    PoseObservation observation{point, {}, kNoDepth, 1.0};
    measure(camera, bf, truth, point, 0.8, rng, observation.pixel, observation.right_u);
    if (is_outlier(rng)) observation.pixel = {u(rng), v(rng)};
    observations.push_back(observation);
  }
  const Pose initial = perturbed(truth, rng, 0.02, 0.03);  // ≈ a constant-velocity prediction
  int inliers = 0;
  for (auto _ : state) {
    const PoseOptimizationResult result = optimize_pose(camera, bf, initial, observations);
    inliers = result.num_inliers;
    benchmark::DoNotOptimize(result.T_camera_world);
  }
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_OptimizePose)->Arg(200)->Arg(500)->Arg(1000)->Unit(benchmark::kMicrosecond);

// range(0) keyframes (3 of them fixed border keyframes), range(1) points.
void BM_LocalBundleAdjustment(benchmark::State& state) {
  const int num_keyframes = static_cast<int>(state.range(0));
  const int num_points = static_cast<int>(state.range(1));
  const PinholeCamera camera;
  const double bf = camera.fx * kBaseline;
  std::mt19937 rng(2);
  BaProblem truth;
  for (int k = 0; k < num_keyframes; ++k) {
    truth.keyframes.push_back({static_cast<uint64_t>(k), camera_on_track(k), k < 3});
  }
  std::uniform_real_distribution<double> x(-2.0, 0.1 * num_keyframes + 2.0), y(-1.5, 1.5),
      depth(1.0, 6.0);
  for (int p = 0; p < num_points; ++p) {
    truth.points.push_back({static_cast<uint64_t>(p), Eigen::Vector3d(x(rng), y(rng), depth(rng))});
  }
  BaProblem start = truth;
  for (size_t k = 0; k < truth.keyframes.size(); ++k) {
    for (size_t p = 0; p < truth.points.size(); ++p) {
      const Eigen::Vector3d pc = truth.keyframes[k].T_camera_world * truth.points[p].position_world;
      if (pc.z() < 0.5 || !camera.in_image(camera.project(pc), 10.0)) continue;
      BaObservation observation{k, p, {}, kNoDepth, 1.0};
      measure(camera, bf, truth.keyframes[k].T_camera_world, truth.points[p].position_world, 0.8,
              rng, observation.pixel, observation.right_u);
      start.observations.push_back(observation);
    }
  }
  for (BaKeyframe& keyframe : start.keyframes) {
    if (!keyframe.fixed)
      keyframe.T_camera_world = perturbed(keyframe.T_camera_world, rng, 0.005, 0.02);
  }
  std::normal_distribution<double> point_noise(0.0, 0.02);
  for (BaPoint& point : start.points) {
    point.position_world += Eigen::Vector3d(point_noise(rng), point_noise(rng), point_noise(rng));
  }
  BaOptions options;
  options.max_seconds = 10.0;  // measure the full solve, not the budget
  int iterations = 0;
  for (auto _ : state) {
    state.PauseTiming();
    BaProblem problem = start;
    state.ResumeTiming();
    iterations = solve_bundle_adjustment(problem, camera, bf, options).iterations;
  }
  state.counters["observations"] = static_cast<double>(start.observations.size());
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_LocalBundleAdjustment)
    ->Args({10, 1000})
    ->Args({20, 2000})
    ->Args({40, 3000})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pspslam

BENCHMARK_MAIN();
