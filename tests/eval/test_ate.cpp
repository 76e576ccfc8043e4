#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "pspslam/core/error.h"
#include "pspslam/eval/ate.h"
#include "pspslam/io/trajectory_io.h"
#include "support/test_support.h"

namespace pspslam {
namespace {

// Independent reference: Horn (1987) closed-form absolute orientation with unit quaternions.
// The rotation is the eigenvector of the largest eigenvalue of Horn's symmetric 4x4 matrix N
// (no SVD, unlike evaluate_ate.py's align()); translation from the centroids.
struct HornResult {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  double rmse;
};

HornResult horn_align(const std::vector<Eigen::Vector3d>& model,
                      const std::vector<Eigen::Vector3d>& data) {
  const double n = static_cast<double>(model.size());
  Eigen::Vector3d model_mean = Eigen::Vector3d::Zero(), data_mean = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < model.size(); ++i) {
    model_mean += model[i] / n;
    data_mean += data[i] / n;
  }
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();  // M_ab = sum model_a * data_b (centred)
  for (size_t i = 0; i < model.size(); ++i) {
    M += (model[i] - model_mean) * (data[i] - data_mean).transpose();
  }
  const double Sxx = M(0, 0), Sxy = M(0, 1), Sxz = M(0, 2);
  const double Syx = M(1, 0), Syy = M(1, 1), Syz = M(1, 2);
  const double Szx = M(2, 0), Szy = M(2, 1), Szz = M(2, 2);
  Eigen::Matrix4d N;
  N << Sxx + Syy + Szz, Syz - Szy, Szx - Sxz, Sxy - Syx,  //
      Syz - Szy, Sxx - Syy - Szz, Sxy + Syx, Szx + Sxz,   //
      Szx - Sxz, Sxy + Syx, -Sxx + Syy - Szz, Syz + Szy,  //
      Sxy - Syx, Szx + Sxz, Syz + Szy, -Sxx - Syy + Szz;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> solver(N);
  const Eigen::Vector4d q = solver.eigenvectors().col(3);  // eigenvalues ascending
  HornResult result;
  result.rotation = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  result.translation = data_mean - result.rotation * model_mean;
  double sum = 0.0;
  for (size_t i = 0; i < model.size(); ++i) {
    sum += (result.rotation * model[i] + result.translation - data[i]).squaredNorm();
  }
  result.rmse = std::sqrt(sum / n);
  return result;
}

std::vector<Eigen::Vector3d> positions(const Trajectory& trajectory) {
  std::vector<Eigen::Vector3d> points;
  for (const StampedPose& p : trajectory) points.push_back(p.T_world_camera.translation());
  return points;
}

Pose known_transform() {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(1.9, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(3.0, -2.0, 0.5);
  return T;
}

// The estimate of a SLAM run in its own world frame: ground truth moved by T (+ noise).
Trajectory transformed_copy(const Trajectory& gt, const Pose& T, double sigma, unsigned seed,
                            double* noise_rmse) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  Trajectory estimate = gt;
  double sum = 0.0;
  for (StampedPose& p : estimate) {
    const Eigen::Vector3d n(noise(rng), noise(rng), noise(rng));
    sum += n.squaredNorm();
    p.T_world_camera = T * p.T_world_camera;
    p.T_world_camera.translation() += n;
  }
  if (noise_rmse != nullptr) *noise_rmse = std::sqrt(sum / static_cast<double>(gt.size()));
  return estimate;
}

Trajectory bonn_ground_truth(const std::filesystem::path& shared) {
  return read_tum_trajectory(shared / "data" / "bonn_crowd_dev" / "groundtruth.txt");
}

TEST(Ate, IdenticalTrajectoriesHaveZeroError) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const Trajectory gt = bonn_ground_truth(shared);
  const AteResult ate = compute_ate(gt, gt);
  EXPECT_EQ(ate.error.count, 404u);
  EXPECT_LT(ate.error.rmse, 1e-12);
  EXPECT_LT((ate.alignment.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
}

TEST(Ate, RecoversKnownRigidTransformOnBonnGroundTruth) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const Trajectory gt = bonn_ground_truth(shared);
  const Pose T = known_transform();
  const AteResult ate = compute_ate(gt, transformed_copy(gt, T, 0.0, 1, nullptr));
  EXPECT_EQ(ate.error.count, 404u);
  EXPECT_LT(ate.error.rmse, 1e-9);
  // The alignment maps the estimate back: it is T^-1.
  EXPECT_LT((ate.alignment.rotation - T.rotation().transpose()).norm(), 1e-9);
  EXPECT_LT((ate.alignment.translation - T.inverse().translation()).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(ate.alignment.scale, 1.0);
}

// ATE after alignment equals the RMSE of the added noise, within what the alignment can absorb:
// the 6 fitted parameters remove a chi-square(6) share of the noise energy, E = 6 sigma^2 out of
// 3 N sigma^2 (N = 404: 0.5%); its 5-sigma bound (6 + 5 sqrt(12)) sigma^2 = 23.3 sigma^2 gives a
// relative RMSE reduction below 1 - sqrt(1 - 23.3 / 1212) = 1%. The alignment can never increase
// the RMSE above the noise's (the true transform is one of the candidates).
TEST(Ate, PerturbedCopiesAgreeWithHornAndWithTheNoise) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const Trajectory gt = bonn_ground_truth(shared);
  const Pose T = known_transform();
  for (const double sigma : {0.001, 0.01, 0.05}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      double noise_rmse = 0.0;
      const Trajectory estimate = transformed_copy(gt, T, sigma, seed, &noise_rmse);
      const AteResult ate = compute_ate(gt, estimate);
      const HornResult horn = horn_align(positions(estimate), positions(gt));
      EXPECT_NEAR(ate.error.rmse, horn.rmse, 1e-6) << "sigma " << sigma << " seed " << seed;
      EXPECT_NEAR(ate.error.rmse, horn.rmse, 1e-12) << "(far tighter than required)";
      EXPECT_LT((ate.alignment.rotation - horn.rotation).norm(), 1e-9);
      EXPECT_LE(ate.error.rmse, noise_rmse + 1e-12);
      EXPECT_GT(ate.error.rmse, 0.99 * noise_rmse) << "sigma " << sigma << " seed " << seed;
    }
  }
}

TEST(Ate, Sim3RecoversScale) {
  PSPSLAM_SHARED_OR_SKIP(shared);
  const Trajectory gt = bonn_ground_truth(shared);
  Trajectory estimate = transformed_copy(gt, known_transform(), 0.0, 1, nullptr);
  for (StampedPose& p : estimate) p.T_world_camera.translation() *= 0.4;  // monocular scale
  AteOptions options;
  options.sim3 = true;
  const AteResult sim3 = compute_ate(gt, estimate, options);
  EXPECT_NEAR(sim3.alignment.scale, 2.5, 1e-9);
  EXPECT_LT(sim3.error.rmse, 1e-9);
  const AteResult se3 = compute_ate(gt, estimate);
  EXPECT_GT(se3.error.rmse, 0.05);  // without scale the shrunken copy cannot fit
}

TEST(Ate, AssociationWindowAndOffset) {
  Trajectory gt, estimate;
  for (int i = 0; i < 20; ++i) {
    StampedPose p;
    p.timestamp = 100.0 + 0.1 * i;
    p.T_world_camera.translation() = Eigen::Vector3d(i, i * i * 0.1, std::sin(i));
    gt.push_back(p);
    p.timestamp += 0.555;  // estimate clock runs 0.555 s ahead: 0.045 s from any gt stamp
    estimate.push_back(p);
  }
  try {
    compute_ate(gt, estimate);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "ATE: only 0 of the 20 estimated poses have a ground-truth pose within 0.02 s "
                 "(need at least 3); wrong files, or do the timestamps need --offset?");
  }
  AteOptions options;
  options.offset = -0.55;
  const AteResult ate = compute_ate(gt, estimate, options);
  EXPECT_EQ(ate.error.count, 20u);
  EXPECT_LT(ate.error.rmse, 1e-12);
  options.max_difference = 0.004;  // the 0.005 s left after the offset is now too much
  EXPECT_THROW(compute_ate(gt, estimate, options), Error);
}

TEST(Ate, AlignPointsMatchesHornOnRandomClouds) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> uniform(-2.0, 2.0);
  for (int trial = 0; trial < 10; ++trial) {
    std::vector<Eigen::Vector3d> model, data;
    Eigen::Matrix3Xd model_matrix(3, 30), data_matrix(3, 30);
    for (int i = 0; i < 30; ++i) {
      model.emplace_back(uniform(rng), uniform(rng), uniform(rng));
      data.emplace_back(uniform(rng), uniform(rng), uniform(rng));  // unrelated clouds: hard case
      model_matrix.col(i) = model.back();
      data_matrix.col(i) = data.back();
    }
    const Alignment svd = align_points(model_matrix, data_matrix);
    const HornResult horn = horn_align(model, data);
    EXPECT_LT((svd.rotation - horn.rotation).norm(), 1e-9) << trial;
    EXPECT_NEAR(svd.rotation.determinant(), 1.0, 1e-12);
  }
}

}  // namespace
}  // namespace pspslam
