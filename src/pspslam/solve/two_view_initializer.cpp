#include "pspslam/solve/two_view_initializer.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <future>
#include <numeric>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <random>

#include "pspslam/solve/triangulation.h"

namespace pspslam {

const char* to_string(TwoViewModel model) {
  switch (model) {
    case TwoViewModel::none:
      return "none";
    case TwoViewModel::homography:
      return "homography";
    case TwoViewModel::fundamental:
      return "fundamental";
  }
  return "?";
}

namespace {

using MinimalSet = std::array<int, 8>;
using Matrix34 = Eigen::Matrix<double, 3, 4>;

// χ² thresholds at 95 %: 1 dof (a point to an epipolar line), 2 dof (a point to a point).
constexpr double kChi2OneDof = 3.841;
constexpr double kChi2TwoDof = 5.991;
// cos of the parallax below which a point counts as triangulated well enough (~0.36°).
constexpr double kMaxParallaxCos = 0.99998;

// Hartley's normalisation (ORB-SLAM's variant: mean absolute deviation per axis), so that the
// DLT's equations are well conditioned: x_n = T x.
Eigen::Matrix3d normalise(std::span<const Eigen::Vector2d> points,
                          std::vector<Eigen::Vector2d>& normalised) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Vector2d deviation = Eigen::Vector2d::Zero();
  for (const auto& p : points) deviation += (p - mean).cwiseAbs();
  deviation /= static_cast<double>(points.size());
  const double sx = deviation.x() > 0.0 ? 1.0 / deviation.x() : 1.0;
  const double sy = deviation.y() > 0.0 ? 1.0 / deviation.y() : 1.0;
  normalised.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    normalised[i] = {(points[i].x() - mean.x()) * sx, (points[i].y() - mean.y()) * sy};
  }
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(0, 0) = sx;
  T(1, 1) = sy;
  T(0, 2) = -mean.x() * sx;
  T(1, 2) = -mean.y() * sy;
  return T;
}

// x2 ~ H x1 from the correspondences `set` (8 in RANSAC, all inliers in the final fit; DLT,
// Hartley & Zisserman alg. 4.1).
Eigen::Matrix3d homography_dlt(const std::vector<Eigen::Vector2d>& p1,
                               const std::vector<Eigen::Vector2d>& p2, std::span<const int> set) {
  Eigen::Matrix<double, Eigen::Dynamic, 9> A(2 * set.size(), 9);
  for (size_t k = 0; k < set.size(); ++k) {
    const double u1 = p1[set[k]].x(), v1 = p1[set[k]].y();
    const double u2 = p2[set[k]].x(), v2 = p2[set[k]].y();
    A.row(2 * k) << 0.0, 0.0, 0.0, -u1, -v1, -1.0, v2 * u1, v2 * v1, v2;
    A.row(2 * k + 1) << u1, v1, 1.0, 0.0, 0.0, 0.0, -u2 * u1, -u2 * v1, -u2;
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 9>> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(h.data());
}

// x2ᵀ F x1 = 0 from the correspondences `set`, rank 2 enforced (the normalised 8-point
// algorithm, Hartley & Zisserman alg. 11.1).
Eigen::Matrix3d fundamental_eight_point(const std::vector<Eigen::Vector2d>& p1,
                                        const std::vector<Eigen::Vector2d>& p2,
                                        std::span<const int> set) {
  Eigen::Matrix<double, Eigen::Dynamic, 9> A(set.size(), 9);
  for (size_t k = 0; k < set.size(); ++k) {
    const double u1 = p1[set[k]].x(), v1 = p1[set[k]].y();
    const double u2 = p2[set[k]].x(), v2 = p2[set[k]].y();
    A.row(k) << u2 * u1, u2 * v1, u2, v2 * u1, v2 * v1, v2, u1, v1, 1.0;
  }
  const Eigen::JacobiSVD<Eigen::Matrix<double, Eigen::Dynamic, 9>> svd(A, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> f = svd.matrixV().col(8);
  const Eigen::Matrix3d F =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(f.data());
  Eigen::JacobiSVD<Eigen::Matrix3d> rank2(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d singular = rank2.singularValues();
  singular(2) = 0.0;
  return rank2.matrixU() * singular.asDiagonal() * rank2.matrixV().transpose();
}

struct ModelFit {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();  // H21 or F21 in pixels
  double score = 0.0;
  std::vector<std::uint8_t> inlier;
  int num_inliers = 0;
};

// ORB-SLAM's homography score: symmetric transfer error, each side contributing χ²₂ − e²/σ² when
// below χ²₂; a correspondence failing either side is an outlier and contributes nothing more.
double score_homography(const Eigen::Matrix3d& H21, std::span<const Eigen::Vector2d> p1,
                        std::span<const Eigen::Vector2d> p2, double inv_sigma2,
                        std::vector<std::uint8_t>& inlier) {
  const Eigen::Matrix3d H12 = H21.inverse();
  double score = 0.0;
  inlier.assign(p1.size(), 0);
  for (size_t i = 0; i < p1.size(); ++i) {
    const Eigen::Vector3d to1 = H12 * p2[i].homogeneous();
    const Eigen::Vector3d to2 = H21 * p1[i].homogeneous();
    if (to1.z() == 0.0 || to2.z() == 0.0) continue;
    const double chi1 = (p1[i] - to1.hnormalized()).squaredNorm() * inv_sigma2;
    if (chi1 > kChi2TwoDof) continue;
    const double chi2 = (p2[i] - to2.hnormalized()).squaredNorm() * inv_sigma2;
    if (chi2 > kChi2TwoDof) continue;
    score += (kChi2TwoDof - chi1) + (kChi2TwoDof - chi2);
    inlier[i] = 1;
  }
  return score;
}

// ORB-SLAM's fundamental score: distance of each point to the other's epipolar line (1 dof,
// inlier below χ²₁), scored with the same χ²₂ constant as H so that the two scores compare.
double score_fundamental(const Eigen::Matrix3d& F21, std::span<const Eigen::Vector2d> p1,
                         std::span<const Eigen::Vector2d> p2, double inv_sigma2,
                         std::vector<std::uint8_t>& inlier) {
  double score = 0.0;
  inlier.assign(p1.size(), 0);
  for (size_t i = 0; i < p1.size(); ++i) {
    const Eigen::Vector3d x1 = p1[i].homogeneous();
    const Eigen::Vector3d x2 = p2[i].homogeneous();
    const Eigen::Vector3d line2 = F21 * x1;
    const Eigen::Vector3d line1 = F21.transpose() * x2;
    const double n2 = line2.head<2>().squaredNorm();
    const double n1 = line1.head<2>().squaredNorm();
    if (n1 <= 0.0 || n2 <= 0.0) continue;
    const double d2 = line2.dot(x2);
    const double chi2 = d2 * d2 / n2 * inv_sigma2;
    if (chi2 > kChi2OneDof) continue;
    const double d1 = line1.dot(x1);
    const double chi1 = d1 * d1 / n1 * inv_sigma2;
    if (chi1 > kChi2OneDof) continue;
    score += (kChi2TwoDof - chi1) + (kChi2TwoDof - chi2);
    inlier[i] = 1;
  }
  return score;
}

enum class Kind { homography, fundamental };

ModelFit fit(Kind kind, std::span<const Eigen::Vector2d> p1, std::span<const Eigen::Vector2d> p2,
             const std::vector<MinimalSet>& sets, double inv_sigma2) {
  std::vector<Eigen::Vector2d> n1, n2;
  const Eigen::Matrix3d T1 = normalise(p1, n1);
  const Eigen::Matrix3d T2 = normalise(p2, n2);
  ModelFit best;
  std::vector<std::uint8_t> inlier;
  const auto consider = [&](std::span<const int> set) {
    Eigen::Matrix3d M;
    double score = 0.0;
    if (kind == Kind::homography) {
      M = T2.inverse() * homography_dlt(n1, n2, set) * T1;
      if (!M.allFinite() || std::abs(M.determinant()) < 1e-12) return false;
      score = score_homography(M, p1, p2, inv_sigma2, inlier);
    } else {
      M = T2.transpose() * fundamental_eight_point(n1, n2, set) * T1;
      if (!M.allFinite()) return false;
      score = score_fundamental(M, p1, p2, inv_sigma2, inlier);
    }
    if (score <= best.score) return false;
    best.M = M;
    best.score = score;
    best.inlier = inlier;
    return true;
  };
  for (const MinimalSet& set : sets) consider(set);
  // ORB-SLAM stops at the best minimal model and leaves the rest to bundle adjustment; a least-
  // squares refit on its inliers, kept while it scores higher, is cheap and much closer (a
  // minimal 8-point model's translation direction can be off by degrees).
  for (int round = 0; round < 3; ++round) {
    std::vector<int> inliers;
    for (size_t i = 0; i < best.inlier.size(); ++i) {
      if (best.inlier[i]) inliers.push_back(static_cast<int>(i));
    }
    if (inliers.size() < 8 || !consider(inliers)) break;
  }
  best.num_inliers =
      static_cast<int>(std::count(best.inlier.begin(), best.inlier.end(), std::uint8_t{1}));
  return best;
}

struct Hypothesis {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  int num_good = 0;          // in front of both cameras and reprojecting (ORB-SLAM's CheckRT nGood)
  int num_triangulated = 0;  // of those, with parallax
  double parallax_deg = 0.0;
  std::vector<Eigen::Vector3d> points;
  std::vector<std::uint8_t> triangulated;
};

// ORB-SLAM's CheckRT: triangulates the model's inliers under (R, t) and counts those in front of
// both cameras (unless the rays are parallel) whose reprojection error is below 2σ in both.
void check_motion(Hypothesis& h, const PinholeCamera& camera, std::span<const Eigen::Vector2d> p1,
                  std::span<const Eigen::Vector2d> p2, const std::vector<std::uint8_t>& inlier,
                  double sigma) {
  Eigen::Matrix3d K;
  K << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  Matrix34 P1 = Matrix34::Zero();
  P1.leftCols<3>() = K;
  Matrix34 P2;
  P2.leftCols<3>() = K * h.R;
  P2.col(3) = K * h.t;
  const Eigen::Vector3d center2 = -h.R.transpose() * h.t;
  const double max_error2 = 4.0 * sigma * sigma;
  std::vector<double> parallax_cos;
  h.points.assign(p1.size(), Eigen::Vector3d::Zero());
  h.triangulated.assign(p1.size(), 0);
  h.num_good = 0;
  h.num_triangulated = 0;
  for (size_t i = 0; i < p1.size(); ++i) {
    if (!inlier[i]) continue;
    const Eigen::Vector3d X = triangulate_dlt(p1[i], P1, p2[i], P2);
    if (!X.allFinite()) continue;
    const Eigen::Vector3d ray2 = X - center2;
    const double cos_parallax = X.dot(ray2) / (X.norm() * ray2.norm());
    if (X.z() <= 0.0 && cos_parallax < kMaxParallaxCos) continue;
    const Eigen::Vector3d X2 = h.R * X + h.t;
    if (X2.z() <= 0.0 && cos_parallax < kMaxParallaxCos) continue;
    if ((camera.project(X) - p1[i]).squaredNorm() > max_error2) continue;
    if ((camera.project(X2) - p2[i]).squaredNorm() > max_error2) continue;
    parallax_cos.push_back(cos_parallax);
    ++h.num_good;
    if (cos_parallax < kMaxParallaxCos) {
      h.points[i] = X;
      h.triangulated[i] = 1;
      ++h.num_triangulated;
    }
  }
  h.parallax_deg = 0.0;
  if (!parallax_cos.empty()) {
    // ORB-SLAM's parallax of a hypothesis: the 50th smallest (robust to a few wide rays).
    std::sort(parallax_cos.begin(), parallax_cos.end());
    const size_t index = std::min<size_t>(50, parallax_cos.size() - 1);
    h.parallax_deg = std::acos(std::clamp(parallax_cos[index], -1.0, 1.0)) * 180.0 / M_PI;
  }
}

// E = Kᵀ F K, E = U diag(1,1,0) Vᵀ: R ∈ {U W Vᵀ, U Wᵀ Vᵀ}, t = ±u₃ (Hartley & Zisserman 9.6.2).
std::vector<Hypothesis> fundamental_hypotheses(const Eigen::Matrix3d& F21,
                                               const PinholeCamera& camera) {
  Eigen::Matrix3d K;
  K << camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d E = K.transpose() * F21 * K;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d U = svd.matrixU();
  const Eigen::Matrix3d V = svd.matrixV();
  Eigen::Matrix3d W;
  W << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  Eigen::Matrix3d R1 = U * W * V.transpose();
  Eigen::Matrix3d R2 = U * W.transpose() * V.transpose();
  if (R1.determinant() < 0.0) R1 = -R1;
  if (R2.determinant() < 0.0) R2 = -R2;
  const Eigen::Vector3d t = U.col(2).normalized();
  std::vector<Hypothesis> hypotheses(4);
  hypotheses[0].R = R1, hypotheses[0].t = t;
  hypotheses[1].R = R2, hypotheses[1].t = t;
  hypotheses[2].R = R1, hypotheses[2].t = -t;
  hypotheses[3].R = R2, hypotheses[3].t = -t;
  return hypotheses;
}

// The up to four (R, t/d, n) of H = K (R + t nᵀ / d) K⁻¹ (Malis & Vargas' analytic decomposition,
// cv::decomposeHomographyMat); which of them is physical is left to the triangulation test.
std::vector<Hypothesis> homography_hypotheses(const Eigen::Matrix3d& H21,
                                              const PinholeCamera& camera) {
  cv::Mat H;
  cv::eigen2cv(H21, H);
  std::vector<cv::Mat> rotations, translations, normals;
  cv::decomposeHomographyMat(H, camera.K(), rotations, translations, normals);
  std::vector<Hypothesis> hypotheses;
  for (size_t k = 0; k < rotations.size(); ++k) {
    Hypothesis h;
    cv::cv2eigen(rotations[k], h.R);
    cv::cv2eigen(translations[k], h.t);
    if (h.t.norm() < 1e-12) continue;  // pure rotation: no baseline to triangulate from
    h.t.normalize();
    hypotheses.push_back(std::move(h));
  }
  return hypotheses;
}

// Sampson errors (Hartley & Zisserman eq. 11.9) of E = [t]x R on the normalised points, in pixels.
void sampson_residuals(const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                       const std::vector<Eigen::Vector3d>& x1,
                       const std::vector<Eigen::Vector3d>& x2, double focal,
                       Eigen::VectorXd& residuals) {
  const Eigen::Matrix3d E = skew_symmetric(t) * R;
  residuals.resize(static_cast<Eigen::Index>(x1.size()));
  for (size_t i = 0; i < x1.size(); ++i) {
    const Eigen::Vector3d Ex1 = E * x1[i];
    const Eigen::Vector3d Etx2 = E.transpose() * x2[i];
    const double denominator =
        std::sqrt(Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm());
    residuals(static_cast<Eigen::Index>(i)) =
        denominator > 0.0 ? focal * x2[i].dot(Ex1) / denominator : 0.0;
  }
}

// Refines a motion hypothesis on the points it triangulated by minimising their Sampson errors
// over rotation (3 dof) and translation direction (2 dof), Levenberg-Marquardt with a numeric
// Jacobian. The linear fits are algebraic: the decomposition of a homography in particular turns
// ~0.5 px of noise into 3-4 deg of translation direction on the synthetic plane, this into < 1.
void refine_motion(Hypothesis& h, const PinholeCamera& camera, std::span<const Eigen::Vector2d> p1,
                   std::span<const Eigen::Vector2d> p2) {
  std::vector<Eigen::Vector3d> x1, x2;
  for (size_t i = 0; i < p1.size(); ++i) {
    if (!h.triangulated[i]) continue;
    x1.emplace_back((p1[i].x() - camera.cx) / camera.fx, (p1[i].y() - camera.cy) / camera.fy, 1.0);
    x2.emplace_back((p2[i].x() - camera.cx) / camera.fx, (p2[i].y() - camera.cy) / camera.fy, 1.0);
  }
  if (x1.size() < 8) return;
  const double focal = 0.5 * (camera.fx + camera.fy);
  const auto apply = [](const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                        const Eigen::Matrix<double, 5, 1>& delta, Eigen::Matrix3d& R_out,
                        Eigen::Vector3d& t_out) {
    R_out = Eigen::AngleAxisd(delta.head<3>().norm(),
                              delta.head<3>().norm() > 0.0
                                  ? Eigen::Vector3d(delta.head<3>().normalized())
                                  : Eigen::Vector3d::UnitX())
                .toRotationMatrix() *
            R;
    // Translation moves on the unit sphere, in the plane orthogonal to t.
    const Eigen::Vector3d a =
        std::abs(t.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    const Eigen::Vector3d b1 = t.cross(a).normalized();
    const Eigen::Vector3d b2 = t.cross(b1);
    t_out = (t + delta(3) * b1 + delta(4) * b2).normalized();
  };
  Eigen::Matrix3d R = h.R;
  Eigen::Vector3d t = h.t.normalized();
  Eigen::VectorXd residuals, shifted;
  sampson_residuals(R, t, x1, x2, focal, residuals);
  double cost = residuals.squaredNorm();
  double lambda = 1e-3;
  Eigen::MatrixXd J(residuals.size(), 5);
  for (int iteration = 0; iteration < 20; ++iteration) {
    constexpr double kStep = 1e-7;
    for (int k = 0; k < 5; ++k) {
      Eigen::Matrix<double, 5, 1> delta = Eigen::Matrix<double, 5, 1>::Zero();
      delta(k) = kStep;
      Eigen::Matrix3d R_k;
      Eigen::Vector3d t_k;
      apply(R, t, delta, R_k, t_k);
      sampson_residuals(R_k, t_k, x1, x2, focal, shifted);
      J.col(k) = (shifted - residuals) / kStep;
    }
    Eigen::Matrix<double, 5, 5> H = J.transpose() * J;
    const Eigen::Matrix<double, 5, 1> g = J.transpose() * residuals;
    H.diagonal() *= 1.0 + lambda;
    const Eigen::Matrix<double, 5, 1> delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) break;
    Eigen::Matrix3d R_new;
    Eigen::Vector3d t_new;
    apply(R, t, delta, R_new, t_new);
    sampson_residuals(R_new, t_new, x1, x2, focal, shifted);
    const double new_cost = shifted.squaredNorm();
    if (new_cost < cost) {
      const bool converged = cost - new_cost < 1e-10 * cost;
      R = R_new, t = t_new, residuals = shifted, cost = new_cost;
      lambda *= 0.1;
      if (converged) break;
    } else {
      lambda *= 10.0;
    }
  }
  h.R = R;
  h.t = t;
}

}  // namespace

TwoViewResult initialize_two_view(const PinholeCamera& camera,
                                  std::span<const Eigen::Vector2d> first,
                                  std::span<const Eigen::Vector2d> second,
                                  const TwoViewOptions& options) {
  TwoViewResult result;
  const size_t n = std::min(first.size(), second.size());
  if (first.size() != second.size() || n < 8) {
    result.failure = "fewer than 8 correspondences";
    return result;
  }
  std::mt19937_64 random(options.seed);
  std::vector<int> indices(n);
  std::vector<MinimalSet> sets(static_cast<size_t>(std::max(1, options.iterations)));
  for (MinimalSet& set : sets) {
    std::iota(indices.begin(), indices.end(), 0);
    // A partial Fisher-Yates shuffle draws 8 distinct correspondences.
    for (int k = 0; k < 8; ++k) {
      std::uniform_int_distribution<size_t> pick(static_cast<size_t>(k), n - 1);
      std::swap(indices[static_cast<size_t>(k)], indices[pick(random)]);
      set[static_cast<size_t>(k)] = indices[static_cast<size_t>(k)];
    }
  }
  const double inv_sigma2 = 1.0 / (options.sigma * options.sigma);
  ModelFit homography, fundamental;
  if (options.parallel) {
    auto h = std::async(std::launch::async,
                        [&] { return fit(Kind::homography, first, second, sets, inv_sigma2); });
    fundamental = fit(Kind::fundamental, first, second, sets, inv_sigma2);
    homography = h.get();
  } else {
    homography = fit(Kind::homography, first, second, sets, inv_sigma2);
    fundamental = fit(Kind::fundamental, first, second, sets, inv_sigma2);
  }
  result.score_homography = homography.score;
  result.score_fundamental = fundamental.score;
  const double total = homography.score + fundamental.score;
  if (total <= 0.0) {
    result.failure = "neither model has inliers";
    return result;
  }
  result.homography_ratio = homography.score / total;
  const bool planar = result.homography_ratio > options.homography_ratio;
  result.model = planar ? TwoViewModel::homography : TwoViewModel::fundamental;
  const ModelFit& model = planar ? homography : fundamental;
  std::vector<Hypothesis> hypotheses =
      planar ? homography_hypotheses(model.M, camera) : fundamental_hypotheses(model.M, camera);
  if (hypotheses.empty()) {
    result.failure = "the homography has no motion with a baseline";
    return result;
  }
  for (Hypothesis& h : hypotheses)
    check_motion(h, camera, first, second, model.inlier, options.sigma);
  // Ranked by the points triangulated with parallax, not ORB-SLAM's nGood, which also counts
  // near-parallel rays wherever they land: the wrong decomposition of a plane's homography puts
  // its translation along the optical axis, where many rays are near-parallel (on the synthetic
  // plane it had nGood 214 against 252, ambiguous, but 107 triangulated against 252).
  std::sort(hypotheses.begin(), hypotheses.end(), [](const Hypothesis& a, const Hypothesis& b) {
    return a.num_triangulated > b.num_triangulated;
  });
  Hypothesis& best = hypotheses.front();
  const int second_good = hypotheses.size() > 1 ? hypotheses[1].num_triangulated : 0;
  const double max_second_ratio =
      planar ? options.max_second_ratio_homography : options.max_second_ratio_fundamental;
  const int min_good = std::max(options.min_triangulated,
                                static_cast<int>(options.min_good_ratio * model.num_inliers));
  result.parallax_deg = best.parallax_deg;
  if (best.num_good < min_good) {
    result.failure = "the best motion triangulates " + std::to_string(best.num_good) + " of " +
                     std::to_string(model.num_inliers) + " inliers (needs " +
                     std::to_string(min_good) + ")";
    return result;
  }
  if (second_good >= max_second_ratio * best.num_triangulated) {
    result.failure = "two motions explain the matches alike";
    return result;
  }
  if (best.parallax_deg < options.min_parallax_deg) {
    result.failure = "parallax too small";
    return result;
  }
  // Refined, then triangulated again under the refined motion.
  Hypothesis refined = best;
  refine_motion(refined, camera, first, second);
  check_motion(refined, camera, first, second, model.inlier, options.sigma);
  if (refined.num_triangulated < best.num_triangulated * 0.9) refined = best;  // refit diverged
  result.success = true;
  result.T_second_first.linear() = refined.R;
  result.T_second_first.translation() = refined.t;
  result.points = std::move(refined.points);
  result.triangulated = std::move(refined.triangulated);
  result.num_triangulated = refined.num_triangulated;
  result.parallax_deg = refined.parallax_deg;
  return result;
}

}  // namespace pspslam
