#include "pspslam/geometry/compensated_homography.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"

namespace pspslam {
namespace {

using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix8d = Eigen::Matrix<double, 8, 8>;

// Hartley normalisation: centroid to the origin, mean distance sqrt(2). Without it the DLT and
// the LM normal equations mix pixel coordinates (~600) with ones and lose ~6 digits.
Eigen::Matrix3d normalising_transform(std::span<const Eigen::Vector2d> points,
                                      std::span<const std::uint8_t> use) {
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  int count = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use.empty() && !use[i]) continue;
    centroid += points[i];
    ++count;
  }
  if (count == 0) return Eigen::Matrix3d::Identity();
  centroid /= count;
  double mean_distance = 0.0;
  for (size_t i = 0; i < points.size(); ++i) {
    if (!use.empty() && !use[i]) continue;
    mean_distance += (points[i] - centroid).norm();
  }
  mean_distance /= count;
  const double scale = mean_distance > 1e-12 ? std::sqrt(2.0) / mean_distance : 1.0;
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
  T(0, 0) = T(1, 1) = scale;
  T(0, 2) = -scale * centroid.x();
  T(1, 2) = -scale * centroid.y();
  return T;
}

Eigen::Vector2d apply(const Eigen::Matrix3d& T, const Eigen::Vector2d& p) {
  return (T * p.homogeneous()).hnormalized();
}

// Twice the signed area of a triangle; near zero means three of the four sample points are
// collinear, for which the 4-point homography is undefined.
double triangle_area2(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                      const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Minimal DLT with h33 = 1: two rows of the 8x8 system per correspondence.
bool solve_minimal(const std::array<Eigen::Vector2d, 4>& x, const std::array<Eigen::Vector2d, 4>& y,
                   Eigen::Matrix3d& H) {
  Matrix8d A;
  Vector8d b;
  for (int i = 0; i < 4; ++i) {
    const double u = y[i].x(), v = y[i].y(), px = x[i].x(), py = x[i].y();
    A.row(2 * i) << px, py, 1, 0, 0, 0, -u * px, -u * py;
    A.row(2 * i + 1) << 0, 0, 0, px, py, 1, -v * px, -v * py;
    b(2 * i) = u;
    b(2 * i + 1) = v;
  }
  Eigen::FullPivLU<Matrix8d> lu(A);
  if (lu.rank() < 8) return false;
  const Vector8d h = lu.solve(b);
  if (!h.allFinite()) return false;
  H << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  return true;
}

double squared_transfer_error(const Eigen::Matrix3d& H, const Eigen::Vector2d& x,
                              const Eigen::Vector2d& y) {
  const Eigen::Vector3d p = H * x.homogeneous();
  if (std::abs(p.z()) < 1e-12) return std::numeric_limits<double>::infinity();
  return (y - p.hnormalized()).squaredNorm();
}

double rms_over(const Eigen::Matrix3d& H, std::span<const Eigen::Vector2d> x,
                std::span<const Eigen::Vector2d> y, std::span<const std::uint8_t> use) {
  double sum = 0.0;
  int count = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    if (!use[i]) continue;
    sum += squared_transfer_error(H, x[i], y[i]);
    ++count;
  }
  return count > 0 ? std::sqrt(sum / count) : 0.0;
}

// Levenberg-Marquardt on eq. 11 in normalised coordinates. The previous points are normalised by
// Tx and the current ones by Ty (a similarity), so the normalised residual is the pixel residual
// times one constant: the minimiser is the same as for pixel errors, with a well-scaled system.
int refine_levenberg_marquardt(std::span<const Eigen::Vector2d> x,
                               std::span<const Eigen::Vector2d> y,
                               std::span<const std::uint8_t> use, int max_iterations,
                               Eigen::Matrix3d& H) {
  const Eigen::Matrix3d Tx = normalising_transform(x, use);
  const Eigen::Matrix3d Ty = normalising_transform(y, use);
  Eigen::Matrix3d Hn = Ty * H * Tx.inverse();
  if (std::abs(Hn(2, 2)) < 1e-9) return 0;  // h33 = 1 cannot represent it; keep RANSAC's H
  Hn /= Hn(2, 2);
  Vector8d h;
  h << Hn(0, 0), Hn(0, 1), Hn(0, 2), Hn(1, 0), Hn(1, 1), Hn(1, 2), Hn(2, 0), Hn(2, 1);

  // Normalised points are computed on the fly (no per-point buffers).
  const auto cost_of = [&](const Vector8d& p) {
    double cost = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d a = apply(Tx, x[i]);
      const Eigen::Vector2d b = apply(Ty, y[i]);
      const double w = p(6) * a.x() + p(7) * a.y() + 1.0;
      const double u = (p(0) * a.x() + p(1) * a.y() + p(2)) / w;
      const double v = (p(3) * a.x() + p(4) * a.y() + p(5)) / w;
      cost += (b.x() - u) * (b.x() - u) + (b.y() - v) * (b.y() - v);
    }
    return cost;
  };

  double cost = cost_of(h);
  double lambda = 1e-3;
  int iteration = 0;
  bool converged = false;
  for (; iteration < max_iterations && !converged; ++iteration) {
    Matrix8d JtJ = Matrix8d::Zero();
    Vector8d Jtr = Vector8d::Zero();
    for (size_t i = 0; i < x.size(); ++i) {
      if (!use[i]) continue;
      const Eigen::Vector2d a = apply(Tx, x[i]);
      const Eigen::Vector2d b = apply(Ty, y[i]);
      const double w = h(6) * a.x() + h(7) * a.y() + 1.0;
      const double inv_w = 1.0 / w;
      const double u = (h(0) * a.x() + h(1) * a.y() + h(2)) * inv_w;
      const double v = (h(3) * a.x() + h(4) * a.y() + h(5)) * inv_w;
      // Jacobians of the predicted point pi(H a) with respect to h1..h8.
      Vector8d ju, jv;
      ju << a.x() * inv_w, a.y() * inv_w, inv_w, 0, 0, 0, -u * a.x() * inv_w, -u * a.y() * inv_w;
      jv << 0, 0, 0, a.x() * inv_w, a.y() * inv_w, inv_w, -v * a.x() * inv_w, -v * a.y() * inv_w;
      JtJ.noalias() += ju * ju.transpose() + jv * jv.transpose();
      Jtr.noalias() += ju * (b.x() - u) + jv * (b.y() - v);
    }
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Matrix8d damped = JtJ;
      for (int k = 0; k < 8; ++k) damped(k, k) += lambda * std::max(JtJ(k, k), 1e-12);
      const Vector8d step = damped.ldlt().solve(Jtr);
      if (!step.allFinite()) {
        lambda *= 10.0;
        continue;
      }
      const Vector8d candidate = h + step;
      const double candidate_cost = cost_of(candidate);
      if (candidate_cost < cost) {
        const double relative_decrease = (cost - candidate_cost) / std::max(cost, 1e-300);
        h = candidate;
        cost = candidate_cost;
        lambda = std::max(lambda / 10.0, 1e-12);
        improved = true;
        converged = relative_decrease < 1e-12;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;  // at a minimum within numerical precision
  }
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0;
  Eigen::Matrix3d refined = Ty.inverse() * Hn * Tx;
  if (std::abs(refined(2, 2)) > 1e-12) refined /= refined(2, 2);
  if (refined.allFinite()) H = refined;
  return iteration;
}

// Three of the four points (in either image) on a line: no homography through them.
bool degenerate_sample(const std::array<Eigen::Vector2d, 4>& sample_x,
                       const std::array<Eigen::Vector2d, 4>& sample_y) {
  bool degenerate = false;
  for (int a = 0; a < 4 && !degenerate; ++a) {
    const int b = (a + 1) % 4, c = (a + 2) % 4;
    degenerate = std::abs(triangle_area2(sample_x[a], sample_x[b], sample_x[c])) < 1e-3 ||
                 std::abs(triangle_area2(sample_y[a], sample_y[b], sample_y[c])) < 1e-3;
  }
  return degenerate;
}

// MSAC score of H (sum of squared transfer errors truncated at threshold2) and its inliers;
// stops adding once the score reaches `give_up_at` (it cannot be the best then).
double msac_score(const Eigen::Matrix3d& H, std::span<const Eigen::Vector2d> previous,
                  std::span<const Eigen::Vector2d> current, double threshold2, double give_up_at,
                  int& inliers) {
  double score = 0.0;
  inliers = 0;
  for (size_t i = 0; i < previous.size() && score < give_up_at; ++i) {
    const double e2 = squared_transfer_error(H, previous[i], current[i]);
    if (e2 < threshold2) {
      score += e2;
      ++inliers;
    } else {
      score += threshold2;
    }
  }
  return score;
}

// The RANSAC iterations that reach the confidence with the new best model's inlier ratio.
int iterations_needed(int inliers, size_t n, int iteration, int needed_iterations,
                      const HomographyParams& params) {
  const double inlier_ratio = static_cast<double>(inliers) / static_cast<double>(n);
  const double all_inlier_sample = std::pow(inlier_ratio, 4);
  if (all_inlier_sample > 1.0 - 1e-12) return iteration + 1;
  if (all_inlier_sample > 0.0) {
    const double k = std::log(1.0 - params.ransac_confidence) / std::log(1.0 - all_inlier_sample);
    return std::min(params.max_ransac_iterations, static_cast<int>(std::ceil(k)));
  }
  return needed_iterations;
}

}  // namespace

HomographyParams HomographyParams::from_yaml(YamlSection& section) {
  HomographyParams p;
  p.inlier_threshold_px = section.optional("inlier_threshold_px", p.inlier_threshold_px);
  section.require(p.inlier_threshold_px > 0.0, "inlier_threshold_px", "must be > 0");
  p.max_ransac_iterations = section.optional("max_ransac_iterations", p.max_ransac_iterations);
  section.require(p.max_ransac_iterations >= 1, "max_ransac_iterations", "must be >= 1");
  p.ransac_confidence = section.optional("ransac_confidence", p.ransac_confidence);
  section.require(p.ransac_confidence > 0.0 && p.ransac_confidence < 1.0, "ransac_confidence",
                  "must be in (0, 1)");
  p.lm_max_iterations = section.optional("lm_max_iterations", p.lm_max_iterations);
  section.require(p.lm_max_iterations >= 0, "lm_max_iterations", "must be >= 0");
  p.random_seed = section.optional<std::uint64_t>("random_seed", p.random_seed);
  section.finish();
  return p;
}

CompensatedHomography estimate_compensated_homography(std::span<const Eigen::Vector2d> previous,
                                                      std::span<const Eigen::Vector2d> current,
                                                      const HomographyParams& params) {
  if (previous.size() != current.size()) {
    throw Error("estimate_compensated_homography: " + std::to_string(previous.size()) +
                " previous points but " + std::to_string(current.size()) + " current points");
  }
  CompensatedHomography result;
  const size_t n = previous.size();
  result.inliers.assign(n, 0);
  if (n < 4) return result;

  // RANSAC with MSAC scoring (truncated quadratic): ties in inlier count are broken by how well
  // the inliers fit, which gives LM a better start than plain inlier counting.
  const double threshold2 = params.inlier_threshold_px * params.inlier_threshold_px;
  std::mt19937_64 rng(params.random_seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  double best_score = std::numeric_limits<double>::infinity();
  int best_inliers = 0;
  int needed_iterations = params.max_ransac_iterations;
  int iteration = 0;
  std::array<Eigen::Vector2d, 4> sample_x, sample_y;
  for (; iteration < needed_iterations; ++iteration) {
    std::array<size_t, 4> index{};
    for (int k = 0; k < 4; ++k) {
      bool duplicate = true;
      while (duplicate) {
        index[k] = pick(rng);
        duplicate = std::find(index.begin(), index.begin() + k, index[k]) != index.begin() + k;
      }
      sample_x[k] = previous[index[k]];
      sample_y[k] = current[index[k]];
    }
    if (degenerate_sample(sample_x, sample_y)) continue;
    Eigen::Matrix3d H;
    if (!solve_minimal(sample_x, sample_y, H)) continue;
    int inliers = 0;
    const double score = msac_score(H, previous, current, threshold2, best_score, inliers);
    if (score < best_score) {
      best_score = score;
      best_inliers = inliers;
      result.H_ransac = H;
      needed_iterations = iterations_needed(inliers, n, iteration, needed_iterations, params);
    }
  }
  result.ransac_iterations = iteration;
  if (best_inliers < 4) return result;

  std::vector<std::uint8_t> ransac_inliers(n, 0);
  for (size_t i = 0; i < n; ++i) {
    ransac_inliers[i] =
        squared_transfer_error(result.H_ransac, previous[i], current[i]) < threshold2;
  }
  result.ransac_inlier_count = best_inliers;

  // Eq. 11: minimise the sum of squared transfer errors over the RANSAC inliers.
  result.H = result.H_ransac;
  result.lm_iterations = refine_levenberg_marquardt(previous, current, ransac_inliers,
                                                    params.lm_max_iterations, result.H);
  result.rms_before_px = rms_over(result.H_ransac, previous, current, ransac_inliers);
  result.rms_after_px = rms_over(result.H, previous, current, ransac_inliers);
  for (size_t i = 0; i < n; ++i) {
    result.inliers[i] = squared_transfer_error(result.H, previous[i], current[i]) < threshold2;
    result.inlier_count += result.inliers[i];
  }
  result.valid = true;
  return result;
}

CompensatedHomography estimate_compensated_homography(std::span<const cv::Point2f> previous,
                                                      std::span<const cv::Point2f> current,
                                                      const HomographyParams& params) {
  std::vector<Eigen::Vector2d> x(previous.size()), y(current.size());
  for (size_t i = 0; i < previous.size(); ++i) x[i] = {previous[i].x, previous[i].y};
  for (size_t i = 0; i < current.size(); ++i) y[i] = {current[i].x, current[i].y};
  return estimate_compensated_homography(std::span<const Eigen::Vector2d>(x),
                                         std::span<const Eigen::Vector2d>(y), params);
}

void transfer_points(const Eigen::Matrix3d& H, std::span<const Eigen::Vector2d> previous,
                     std::vector<Eigen::Vector2d>& projected) {
  projected.resize(previous.size());
  for (size_t i = 0; i < previous.size(); ++i) projected[i] = transfer_point(H, previous[i]);
}

cv::Mat warp_to_current(const cv::Mat& previous_image, const Eigen::Matrix3d& H,
                        cv::Size current_size, bool is_label_map) {
  cv::Mat H_cv;
  cv::eigen2cv(H, H_cv);
  cv::Mat warped;
  cv::warpPerspective(previous_image, warped, H_cv, current_size,
                      is_label_map ? cv::INTER_NEAREST : cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar::all(0));
  return warped;
}

}  // namespace pspslam
