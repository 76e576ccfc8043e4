#include "pspslam/io/euroc_calibration.h"

#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <fstream>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

template <typename T>
T read_key(const YAML::Node& root, const std::string& key, const std::filesystem::path& file) {
  const YAML::Node node = root[key];
  if (!node) throw Error(file.string() + ": missing key '" + key + "'");
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(file.string() + ":" + std::to_string(node.Mark().line + 1) + ": key '" + key +
                "' has an invalid value");
  }
}

template <typename T>
std::vector<T> read_list(const YAML::Node& root, const std::string& key, size_t count,
                         const std::filesystem::path& file) {
  const auto values = read_key<std::vector<T>>(root, key, file);
  if (values.size() != count) {
    throw Error(file.string() + ":" + std::to_string(root[key].Mark().line + 1) + ": key '" + key +
                "' must list " + std::to_string(count) + " values, got " +
                std::to_string(values.size()));
  }
  return values;
}

}  // namespace

EurocCamera read_euroc_camera(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open camera calibration (sensor.yaml)");
  std::stringstream text;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    // OpenCV's "%YAML:1.0" directive is not YAML; keep the line count for error messages.
    text << (first && line.rfind("%YAML", 0) == 0 ? "" : line) << "\n";
    first = false;
  }
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw Error(file.string() + ":" + std::to_string(e.mark.line + 1) + ": invalid YAML: " + e.msg);
  }
  if (!root.IsMap()) throw Error(file.string() + ": expected a mapping of key: value");
  EurocCamera camera;
  const auto model = read_key<std::string>(root, "camera_model", file);
  if (model != "pinhole") {
    throw Error(file.string() + ": camera_model must be pinhole, got '" + model + "'");
  }
  const auto distortion_model = read_key<std::string>(root, "distortion_model", file);
  if (distortion_model != "radial-tangential" && distortion_model != "radtan") {
    throw Error(file.string() + ": distortion_model must be radial-tangential, got '" +
                distortion_model + "'");
  }
  const auto resolution = read_list<int>(root, "resolution", 2, file);
  camera.width = resolution[0];
  camera.height = resolution[1];
  const auto intrinsics = read_list<double>(root, "intrinsics", 4, file);
  camera.K = cv::Matx33d(intrinsics[0], 0, intrinsics[2], 0, intrinsics[1], intrinsics[3], 0, 0, 1);
  const auto distortion = read_list<double>(root, "distortion_coefficients", 4, file);
  camera.distortion = cv::Vec4d(distortion[0], distortion[1], distortion[2], distortion[3]);
  camera.rate_hz = read_key<double>(root, "rate_hz", file);
  const YAML::Node t_bs = root["T_BS"];
  if (!t_bs || !t_bs.IsMap()) throw Error(file.string() + ": missing key 'T_BS'");
  const auto data = read_list<double>(t_bs, "data", 16, file);
  Eigen::Matrix4d m;
  for (int k = 0; k < 16; ++k) m(k / 4, k % 4) = data[static_cast<size_t>(k)];
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  if (!(r * r.transpose()).isApprox(Eigen::Matrix3d::Identity(), 1e-3)) {
    throw Error(file.string() + ": T_BS's rotation is not orthonormal");
  }
  camera.T_body_camera.linear() = Eigen::Quaterniond(r).normalized().toRotationMatrix();
  camera.T_body_camera.translation() = m.topRightCorner<3, 1>();
  if (camera.width <= 0 || camera.height <= 0 || intrinsics[0] <= 0 || intrinsics[1] <= 0 ||
      camera.rate_hz <= 0) {
    throw Error(file.string() + ": resolution, focal lengths and rate_hz must be > 0");
  }
  return camera;
}

StereoRectification StereoRectification::compute(const EurocCamera& left, const EurocCamera& right,
                                                 const std::string& what) {
  if (left.width != right.width || left.height != right.height) {
    throw Error(what + ": the two cameras differ in resolution");
  }
  // T_right_left maps left-camera points into the right camera: what stereoRectify wants.
  const Pose T_right_left = right.T_body_camera.inverse() * left.T_body_camera;
  cv::Matx33d R;
  cv::Vec3d t;
  for (int i = 0; i < 3; ++i) {
    t[i] = T_right_left.translation()[i];
    for (int j = 0; j < 3; ++j) R(i, j) = T_right_left.linear()(i, j);
  }
  // stereoRectify asserts on a zero baseline (found by fuzz/fuzz_stereo_layouts).
  if (T_right_left.translation().norm() < 1e-6) {
    throw Error(what + ": the two cameras are at the same place (T_BS): no stereo baseline");
  }
  const cv::Size size(left.width, left.height);
  cv::Mat R1, R2, P1, P2, Q;
  try {
    // alpha 0: only valid pixels in the rectified images (no black borders to extract from).
    cv::stereoRectify(left.K, left.distortion, right.K, right.distortion, size, R, t, R1, R2, P1,
                      P2, Q, cv::CALIB_ZERO_DISPARITY, 0.0, size);
  } catch (const cv::Exception& e) {
    throw Error(what + ": cv::stereoRectify failed: " + e.err);
  }
  if (std::abs(P2.at<double>(1, 3)) > std::abs(P2.at<double>(0, 3))) {
    throw Error(what +
                ": the right camera is above or below the left one (a vertical pair); "
                "rows cannot be matched");
  }
  StereoRectification rect;
  rect.size = size;
  rect.fx = P1.at<double>(0, 0);
  rect.fy = P1.at<double>(1, 1);
  rect.cx = P1.at<double>(0, 2);
  rect.cy = P1.at<double>(1, 2);
  rect.baseline = -P2.at<double>(0, 3) / P2.at<double>(0, 0);
  if (!(rect.baseline > 0.0)) {
    throw Error(what + ": the second camera is left of the first; swap cam0 and cam1");
  }
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) rect.R_rect_left(i, j) = R1.at<double>(i, j);
  cv::initUndistortRectifyMap(left.K, left.distortion, R1, P1, size, CV_32FC1, rect.left_map_x,
                              rect.left_map_y);
  cv::initUndistortRectifyMap(right.K, right.distortion, R2, P2, size, CV_32FC1, rect.right_map_x,
                              rect.right_map_y);
  return rect;
}

void StereoRectification::rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_out,
                                  cv::Mat& right_out) const {
  cv::remap(left, left_out, left_map_x, left_map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(right, right_out, right_map_x, right_map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
}

Undistortion Undistortion::compute(const EurocCamera& camera) {
  Undistortion result;
  result.size = cv::Size(camera.width, camera.height);
  if (camera.distortion == cv::Vec4d::all(0.0)) {
    // Nothing to undo: the camera stays as it is and its images are used as stored.
    result.fx = camera.K(0, 0);
    result.fy = camera.K(1, 1);
    result.cx = camera.K(0, 2);
    result.cy = camera.K(1, 2);
    return result;
  }
  const cv::Matx33d K =
      cv::getOptimalNewCameraMatrix(camera.K, camera.distortion, result.size, 0.0, result.size);
  result.fx = K(0, 0);
  result.fy = K(1, 1);
  result.cx = K(0, 2);
  result.cy = K(1, 2);
  cv::initUndistortRectifyMap(camera.K, camera.distortion, cv::Matx33d::eye(), K, result.size,
                              CV_32FC1, result.map_x, result.map_y);
  return result;
}

void Undistortion::undistort(const cv::Mat& image, cv::Mat& out) const {
  if (map_x.empty()) {
    out = image;
    return;
  }
  cv::remap(image, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
}

}  // namespace pspslam
